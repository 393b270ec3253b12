#!/usr/bin/env bash
# The coarse-grid increment predictor of aerofoil_flutter's natural continuation
# (--coarse-predictor, --coarse-guided-restart) changes the starts only, never the points: the
# light boundary on the coarse grid (started from the very coarse one), M = 0.75 .. 0.95, with the
# predictor and without it must list the same Mach numbers with the same Ubar* and omega* to
# within the Newton tolerance (relative 1e-4; measured 3e-7), and the run with it must have used
# it. Usage: aerofoil_coarse_predictor.sh <aerofoil_flutter> <work dir>
set -euo pipefail
exe=$1
work=$2
rm -rf "$work"
mkdir -p "$work"
common=(--case light --grids very_coarse,coarse --mach-min 0.75 --mach-max 0.95 --skip-spectra --skip-verify
        --skip-reduced --skip-jump-check --skip-vg --verbose)
"$exe" "$work/with" "${common[@]}" --coarse-predictor auto --coarse-guided-restart on > "$work/with.log"
"$exe" "$work/without" "${common[@]}" --coarse-predictor off --coarse-guided-restart off > "$work/without.log"
used=$(grep -c "predictor ||F||" "$work/with.log" || true)
if [ "$used" -lt 10 ]; then
  echo "FAIL: the predictor was used at $used points (expected one per continued coarse point)"
  exit 1
fi
if grep -q "predictor ||F||" "$work/without.log"; then
  echo "FAIL: --coarse-predictor off still used the predictor"
  exit 1
fi
a=$work/with/boundary_light_coarse.csv
b=$work/without/boundary_light_coarse.csv
head -1 "$a" | grep -qx "mach,ubar,omega,newton_iterations,linear_iterations,hopf_seconds,steady_seconds" ||
  { echo "FAIL: unexpected header in $a"; exit 1; }
# the 17 listed Mach numbers (0.75, 0.80, 0.81 .. 0.95): every one in both files, equal to 1e-4
awk -F, '
  FNR == 1 { next }
  { key = sprintf("%.5f", $1); c = key * 100; listed = (key == "0.75000" || key == "0.80000" || (key + 0 > 0.805 && (c - int(c + 0.5)) ^ 2 < 1e-12)) }
  !listed { next }
  FNR == NR { ub[key] = $2; om[key] = $3; next }
  {
    if (!(key in ub)) { printf "FAIL: M = %s only without the predictor\n", key; bad = 1; next }
    du = ($2 - ub[key]) / $2; if (du < 0) du = -du
    dw = ($3 - om[key]) / $3; if (dw < 0) dw = -dw
    if (du > m) m = du
    if (dw > m) m = dw
    seen[key] = 1; n++
  }
  END {
    for (k in ub) if (!(k in seen)) { printf "FAIL: M = %s only with the predictor\n", k; bad = 1 }
    printf "%d listed Mach numbers, largest relative difference in Ubar* or omega* %.3g\n", n, m
    if (n != 17 || m > 1e-4) bad = 1
    exit bad
  }' "$a" "$b"
echo "PASS"
