// The tubular reactor (spec 04): the model problem of the whole Hopf -> centre-manifold
// pipeline. Usage: tubular_reactor [out_dir] [--inflow 1|2|3] [--cells N] [--quick]
//
// Writes under out_dir (default out/tubular_reactor):
//   hopf_convergence.csv   Hopf point by the augmented system for 8..256 cells, Newton
//                          iterations from an inverse-power start and from the previous grid
//   branch.csv, bifurcations.csv   equilibrium branch (pseudo-arclength through the folds)
//   coefficients.csv       centre-manifold coefficients: FD in double/dd/qd over h, and taylor
//   damping.csv            damping model below mu* vs the exact critical eigenvalue
//   reduced_vs_full.csv    LCO amplitude of Theta(x=1): reduced model vs time marching
//   lco_branch.csv         the LCO branch by harmonic balance (1, 2, 3, 5, 8 harmonics), with
//                          Floquet stability, for mu* - 2e-3 <= mu <= mu* + 2e-3
//   lco_compare.csv        harmonic balance, reduced model and time marching at the marched points
//   history_*.csv          time histories (full and reduced) at mu* + 7e-5 and mu* + 7.5e-4
// plot.py in this folder turns them into PNGs.
#include <aerohopf/bifurcation.hpp>
#include <aerohopf/io/csv.hpp>
#include <aerohopf/models/tubular_reactor.hpp>
#include <aerohopf/periodic.hpp>
#include <aerohopf/reduction.hpp>
#include <aerohopf/scalar/qd.hpp>
#include <aerohopf/time.hpp>

#include <chrono>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <string>

using namespace aerohopf;
using clk = std::chrono::steady_clock;

namespace {

double seconds_since(clk::time_point t0) { return std::chrono::duration<double>(clk::now() - t0).count(); }

/// Linear interpolation of interleaved cell-centred fields (stride 2) from N to M cells.
template <class V>
V prolong(const V& coarse, int n, int m) {
  V fine(2 * m);
  for (int j = 0; j < m; ++j) {
    const double x = (j + 0.5) * n / double(m) - 0.5;  // position in coarse cell-index units
    const int i0 = std::clamp(int(std::floor(x)), 0, n - 2);
    const double t = std::clamp(x - i0, 0.0, 1.0);
    for (int v = 0; v < 2; ++v) fine[2 * j + v] = (1 - t) * coarse[2 * i0 + v] + t * coarse[2 * (i0 + 1) + v];
  }
  return fine;
}

/// Equilibrium at mu by natural continuation from the rest state (mu = 0), below the first fold.
vec<double> equilibrium_below_fold(const tubular_reactor& r, double mu) {
  vec<double> w = r.rest_state();
  const int steps = 8;
  for (int k = 1; k <= steps; ++k) w = newton(r, w, mu * k / steps).x;
  return w;
}

/// First Hopf point from an inverse-power start at mu0 (no information from other grids).
hopf_result hopf_from_inverse_power(const tubular_reactor& r, double mu0, double omega0) {
  const vec<double> w0 = equilibrium_below_fold(r, mu0);
  hopf_options ho;
  ho.label = "hopf N=" + std::to_string(r.cells());
  return solve_hopf(r, hopf_start(r, w0, mu0, omega0), ho);
}

struct full_run {
  std::vector<double> t, theta;
  cycle_measure cycle;
  double seconds = 0;
};

/// BDF2 time marching of the full system at mu from w_start, recording Theta(x=1).
full_run march(const tubular_reactor& r, double mu, const vec<double>& w_start, double t_end, double dt) {
  full_run run;
  bdf2_options bo;
  bo.dt = dt;
  bo.inner_tolerance = 1e-11;
  const auto t0 = clk::now();
  integrate_bdf2(r, mu, w_start, 0.0, t_end, bo, [&](const bdf2_step_info& s, const vec<double>& w) {
    run.t.push_back(s.t);
    run.theta.push_back(r.outlet_theta(w));
  });
  run.seconds = seconds_since(t0);
  run.cycle = last_cycles(run.t, run.theta, 3);
  return run;
}

}  // namespace

int main(int argc, char** argv) {
  std::filesystem::path out = "out/tubular_reactor";
  reactor_inflow inflow = reactor_inflow::second_order;
  bool quick = false;
  int cells = 32;  // grid of the branch, coefficient table and LCO comparison
  for (int i = 1; i < argc; ++i) {
    if (!std::strcmp(argv[i], "--inflow") && i + 1 < argc) inflow = reactor_inflow(std::atoi(argv[++i]));
    else if (!std::strcmp(argv[i], "--quick")) quick = true;
    else if (!std::strcmp(argv[i], "--cells") && i + 1 < argc) cells = std::atoi(argv[++i]);
    else if (!std::strcmp(argv[i], "--help")) {
      std::cout << "usage: tubular_reactor [out_dir] [--inflow 1|2|3] [--cells N] [--quick]\n";
      return 0;
    } else out = argv[i];
  }
  try {
    std::filesystem::create_directories(out);
    std::cout << std::setprecision(12);
    const auto t_all = clk::now();

    // ---------------------------------------------------------------- Hopf point vs grid
    std::cout << "== Hopf point by the augmented system (inflow closure " << int(inflow) << ")\n";
    csv_writer hc(out / "hopf_convergence.csv", "cells,mu,omega,newton_iterations,newton_iterations_sequenced,seconds");
    std::printf("%6s %18s %18s %8s %10s %10s %12s\n", "cells", "mu", "omega", "newton", "sequenced", "seconds",
                "hopf/steady");
    hopf_point previous;
    int previous_cells = 0;
    for (int cells : {8, 16, 32, 64, 128, 256}) {
      const tubular_reactor r(cells, inflow);
      const auto t0 = clk::now();
      const hopf_result h = hopf_from_inverse_power(r, 0.16, 0.4);
      const double secs = seconds_since(t0);
      // cost unit: one steady solve at mu* from the rest state (natural continuation)
      const auto ts = clk::now();
      equilibrium_below_fold(r, 0.16);
      const double steady = seconds_since(ts);
      int sequenced = 0;
      if (previous_cells) {
        hopf_point g{prolong(previous.w, previous_cells, cells), previous.mu, previous.omega,
                     prolong(previous.p, previous_cells, cells)};
        hopf_options ho;
        ho.label = "hopf sequenced N=" + std::to_string(cells);
        const hopf_result hs = solve_hopf(r, g, ho);
        sequenced = hs.report.iterations;
        if (std::abs(hs.point.mu - h.point.mu) > 1e-9)
          throw error("grid sequencing converged to a different Hopf point at " + std::to_string(cells) + " cells");
      }
      std::printf("%6d %18.12f %18.12f %8d %10d %10.4f %12.2f\n", cells, h.point.mu, h.point.omega,
                  h.report.iterations, sequenced, secs, secs / steady);
      hc.row({(long long)cells, h.point.mu, h.point.omega, (long long)h.report.iterations, (long long)sequenced, secs});
      previous = h.point;
      previous_cells = cells;
    }

    // ---------------------------------------------------------------- branch (32 cells)
    const tubular_reactor r(cells, inflow);
    std::cout << "\n== Equilibrium branch by pseudo-arclength continuation (" << cells << " cells)\n";
    continuation_options co;
    co.ds = 0.01;
    co.ds_max = 0.02;
    co.mu_max = 0.3;
    co.max_steps = 600;
    co.verbose = false;
    const auto branch = pseudo_arclength_continuation(r, r.rest_state(), 0.0, co);
    {
      csv_writer bc(out / "branch.csv", "mu,max_theta,outlet_theta,gamma,max_real,stable");
      for (const auto& p : branch.points) {
        double mt = -1e300;
        for (int i = 0; i < cells; ++i) mt = std::max(mt, p.w[2 * i + 1]);
        bc.row({p.mu, mt, r.outlet_theta(p.w), p.gamma, p.max_real, (long long)(p.max_real < 0)});
      }
      csv_writer bf(out / "bifurcations.csv", "kind,mu,omega,max_theta");
      for (const auto& b : branch.bifurcations) {
        double mt = -1e300;
        for (int i = 0; i < cells; ++i) mt = std::max(mt, b.w[2 * i + 1]);
        const std::string kind = b.kind == bifurcation_kind::fold ? "fold" : "hopf";
        bf.row({kind, b.mu, b.omega, mt});
        std::cout << "  " << kind << " at mu = " << b.mu << (b.kind == bifurcation_kind::hopf ? "  omega = " : "")
                  << (b.kind == bifurcation_kind::hopf ? std::to_string(b.omega) : "") << "\n";
      }
      std::cout << "  " << branch.points.size() << " points, stop: " << branch.stop_reason << "\n";
    }

    // ---------------------------------------------------------------- centre manifold (32 cells)
    const hopf_result hr = hopf_from_inverse_power(r, 0.16, 0.4);
    const hopf_point& hp = hr.point;
    std::cout << "\n== Centre-manifold coefficients at mu* = " << hp.mu << ", omega = " << hp.omega << "\n";
    csv_writer cc(out / "coefficients.csv", "precision,h,g20_re,g20_im,g11_re,g11_im,g02_re,g02_im,g21_re,g21_im,l1");
    auto put = [&](const std::string& prec, const std::string& h, const centre_manifold_coefficients& c) {
      cc.row({prec, h, c.G20.real(), c.G20.imag(), c.G11.real(), c.G11.imag(), c.G02.real(), c.G02.imag(),
              c.G21.real(), c.G21.imag(), c.l1});
      std::printf("  %-7s h=%-6s G20 %+.10e %+.10ei  G21 %+.10e %+.10ei  l1 %+.10e\n", prec.c_str(), h.c_str(),
                  c.G20.real(), c.G20.imag(), c.G21.real(), c.G21.imag(), c.l1);
    };
    const centre_manifold_coefficients exact = reduce_to_centre_manifold(r, hp, taylor_products<double>{});
    put("taylor", "", exact);
    for (int e = 2; e <= 18; ++e) {
      const double h = std::pow(10.0, -e);
      const std::string hs = "1e-" + std::to_string(e);
      put("double", hs, reduce_to_centre_manifold(r, hp, fd_products<double>{h}));
      put("dd", hs, reduce_to_centre_manifold(r, hp, fd_products<dd_real>{h}));
      put("qd", hs, reduce_to_centre_manifold(r, hp, fd_products<qd_real>{h}));
    }
    const centre_manifold_model model(exact, parameter_dependence::moving_equilibrium);
    std::cout << "  c1 = " << exact.c1 << "  l1 = " << exact.l1 << (exact.l1 < 0 ? " (supercritical)" : " (subcritical)")
              << "  d lambda/d mu = " << exact.lambda_mu << "\n";

    // ---------------------------------------------------------------- damping below mu*
    {
      // model_*: the 2x2 damping model z' = (i omega + a dmu) z + b dmu conj(z); linear_*: its
      // normal-form part i omega + a dmu; exact_*: inverse power on the full Jacobian.
      csv_writer dc(out / "damping.csv", "dmu,model_re,model_im,linear_re,linear_im,exact_re,exact_im");
      vec<double> w = hp.w;
      std::complex<double> shift(0, hp.omega);
      for (double dmu : {-4e-3, -2e-3, -1e-3, -5e-4, -2e-4, -1e-4, 0.0, 1e-4, 2e-4}) {
        w = newton(r, w, hp.mu + dmu).x;
        const eigen_pair ep = inverse_power(r.jacobian(w, hp.mu + dmu), shift);
        const auto lm = model.eigenvalue(dmu);
        const auto ll = std::complex<double>(0, hp.omega) + model.z_mu_coefficient() * dmu;
        dc.row({dmu, lm.real(), lm.imag(), ll.real(), ll.imag(), ep.lambda.real(), std::abs(ep.lambda.imag())});
        shift = ep.lambda;
      }
    }

    // ---------------------------------------------------------------- LCO: reduced vs full
    std::cout << "\n== LCO amplitude of Theta(x=1): reduced model vs BDF2 time marching (" << cells << " cells)\n";
    const Eigen::Index outlet = 2 * cells - 1;
    const double period = 2 * std::numbers::pi / hp.omega;
    const double dt = period / 120;
    csv_writer rc(out / "reduced_vs_full.csv",
                  "dmu,reduced_amplitude,full_amplitude,relative_difference,reduced_period,full_period,full_seconds");
    struct marched_point {
      double dmu, reduced_amplitude, reduced_period, full_amplitude, full_period, full_seconds;
      bool compared = false;
    };
    std::vector<marched_point> marched;
    std::vector<double> sweep = {1e-5, 3e-5, 7e-5, 1.5e-4, 3e-4, 5e-4, 7.5e-4, 1e-3};
    if (quick) sweep = {7e-5, 7.5e-4};
    std::printf("  %10s %14s %14s %10s %12s %12s %8s\n", "dmu", "reduced", "full", "rel.diff", "T reduced",
                "T full", "seconds");
    for (double dmu : sweep) {
      const lco_prediction l = model.lco(dmu);
      const auto [amp, mean] = model.component_amplitude(outlet, dmu);
      (void)mean;
      // start ON the predicted cycle; march until the transient (rate 2 sigma) has decayed
      const double sigma = std::max(1e-6, model.z_mu_coefficient().real() * dmu);
      const double t_end = std::min(std::max(30 * period, 8.0 / (2 * sigma)), 4000 * period);
      const full_run run = march(r, hp.mu + dmu, model.reconstruct(std::polar(l.amplitude, 0.0), dmu), t_end, dt);
      const double rel = (amp - run.cycle.amplitude) / run.cycle.amplitude;
      const double rp = 2 * std::numbers::pi / l.frequency;
      std::printf("  %10.2e %14.6e %14.6e %+10.4f %12.6f %12.6f %8.2f\n", dmu, amp, run.cycle.amplitude, rel, rp,
                  run.cycle.period, run.seconds);
      rc.row({dmu, amp, run.cycle.amplitude, rel, rp, run.cycle.period, run.seconds});
      marched.push_back({dmu, amp, rp, run.cycle.amplitude, run.cycle.period, run.seconds, false});
    }

    // ---------------------------------------------------------------- LCO branch: harmonic balance
    std::cout << "\n== LCO branch by harmonic balance, continued in amplitude from the Hopf point (" << cells
              << " cells)\n";
    {
      const vec<double> probe = vec<double>::Unit(r.size(), outlet);
      // cost unit: one steady solve at mu* from the rest state (as in the Hopf table)
      const auto ts = clk::now();
      equilibrium_below_fold(r, hp.mu);
      const double steady = seconds_since(ts);
      csv_writer lc(out / "lco_branch.csv", "harmonics,mu,period,theta_amplitude,stable,newton_iterations,seconds");
      csv_writer cc2(out / "lco_compare.csv",
                     "mu,dmu,hb_amplitude,hb_period,reduced_amplitude,reduced_period,full_amplitude,full_period,"
                     "hb_vs_full,hb_seconds,full_seconds");
      std::vector<double> targets;
      for (const auto& m : marched) targets.push_back(hp.mu + m.dmu);
      for (int h : {1, 2, 3, 5, 8}) {
        // first cycle: amplitude 1e-3 of Theta(x=1) on the critical eigenvector, mu from the reduced model
        const double a0 = 1e-3;
        const double dmu0 = std::pow(a0 / std::max(1e-300, model.component_amplitude(outlet, 1e-4).first), 2) * 1e-4;
        const lco_solution start =
            solve_lco(r, lco_guess_from_hopf(hp, probe, a0, h, hp.mu + dmu0), probe, lco_fix::amplitude);
        lco_branch_options bo;
        bo.mu_scale = 1e-3;
        bo.amplitude_scale = 1e-2;
        bo.step = 0.05;
        bo.max_step = 0.5;
        bo.mu_targets = targets;
        bo.mu_min = hp.mu - 2e-3;  // H = 1 turns back (subcritical) towards a = 0
        bo.mu_max = hp.mu + 2e-3;
        bo.amplitude_max = 0.06;
        bo.max_points = 200;
        int points = 0, stable = 0;
        double seconds = 0;
        const auto tb = clk::now();
        const lco_branch b = trace_lco_branch(r, start, probe, bo, [&](const lco_branch_point& p) {
          const bool st = p.floquet && p.floquet->stable;
          lc.row({(long long)h, p.cycle.mu, p.cycle.period(), p.probe_amplitude, (long long)st,
                  (long long)p.cycle.newton_iterations, p.seconds});
          ++points;
          stable += st;
          seconds += p.seconds;
          if (h == 5 && p.landed)
            for (auto& m : marched)
              if (!m.compared && std::abs(hp.mu + m.dmu - p.cycle.mu) < 1e-12) {
                m.compared = true;  // the first landing: the branch folds back over mu later
                const double rel = p.probe_amplitude / m.full_amplitude - 1;
                cc2.row({p.cycle.mu, m.dmu, p.probe_amplitude, p.cycle.period(), m.reduced_amplitude, m.reduced_period,
                         m.full_amplitude, m.full_period, rel, p.seconds, m.full_seconds});
                std::printf("  dmu %9.2e  HB %.6e (T %.6f)  reduced %.6e  BDF2 %.6e (T %.6f)  HB/BDF2 - 1 %+.2e"
                            "  HB solve %.3f s = %.1f steady solves (+ Hill %.3f s; BDF2 %.2f s)\n",
                            m.dmu, p.probe_amplitude, p.cycle.period(), m.reduced_amplitude, m.full_amplitude,
                            m.full_period, rel, p.cycle.seconds, p.cycle.seconds / steady, p.seconds - p.cycle.seconds,
                            m.full_seconds);
              }
          return false;
        });
        std::printf("  H = %d: %d points (%d stable) up to mu* + %.3g, Theta(1) amplitude %.4f; %.2f s (%s)\n", h,
                    points, stable, b.points.back().cycle.mu - hp.mu, b.points.back().probe_amplitude,
                    seconds_since(tb), b.stop_reason.c_str());
      }
      std::printf("  one steady solve: %.4f s\n", steady);
    }

    // ---------------------------------------------------------------- time histories
    std::cout << "\n== Time histories from initial deflections of Theta(x=1)\n";
    for (double dmu : {7e-5, 7.5e-4}) {
      const vec<double> w_eq = newton(r, hp.w, hp.mu + dmu).x;
      for (double defl : {0.01, 0.001}) {
        char name[96];
        std::snprintf(name, sizeof name, "history_dmu%.1e_defl%.0e.csv", dmu, defl);
        // full system: equilibrium with Theta(x=1) deflected
        vec<double> w0 = w_eq;
        w0[outlet] += defl;
        const double t_end = quick ? 60 * period : 400 * period;
        const full_run run = march(r, hp.mu + dmu, w0, t_end, dt);
        // reduced model: z0 = <q, w0 - w_eq> (projection of the same deflection)
        const std::complex<double> z0 = exact.q.dot((w0 - w_eq).cast<std::complex<double>>());
        const reduced_history rh = model.integrate(z0, dmu, t_end, dt);
        csv_writer th(out / name, "t,theta_full,theta_reduced");
        for (size_t k = 0; k < run.t.size(); k += 4) {
          const size_t kr = std::min(k, rh.z.size() - 1);
          th.row({run.t[k], run.theta[k], model.reconstruct(rh.z[kr], dmu)[outlet]});
        }
        std::printf("  dmu %.1e deflection %.0e: full amplitude %.6e (last cycles), %.1f s\n", dmu, defl,
                    run.cycle.amplitude, run.seconds);
      }
    }
    std::cout << "\nwrote results to " << out.string() << " in " << seconds_since(t_all) << " s\n";
  } catch (const std::exception& e) {
    std::cerr << "tubular_reactor: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
