#pragma once
// V-g / V-f diagram: the damping and frequency of every structural mode against the parameter
// (the flutter engineer's picture of spec 01, step 2; the root locus of several modes at once).
//
// Each mode k is one eigenvalue lambda_k(mu) of A(w0(mu), mu), traced over the listed
// parameters by shift-invert inverse power (inverse_power.hpp), every step shifted at the
// mode's previous eigenvalue and started from its previous eigenvector. Reported per point:
//     damping   g = 2 Re(lambda) / |Im(lambda)|       (= -2 zeta / sqrt(1 - zeta^2) for damping
//                                                      ratio zeta: g < 0 stable, as in the V-g method)
//     frequency |Im(lambda)|, in the model's time unit (the aerofoil's is c / U_inf, so
//               omega c / U_inf = 2 k with k the reduced frequency; omega / omega_alpha =
//               frequency * Ubar / 2)
// MODE TRACKING BY THE EIGENVECTOR, not by frequency: where two modes' frequencies cross (the
// usual picture below coalescence flutter), sorting by frequency swaps their identities, and
// even the eigenvalue nearest the previous one may be the other mode when the parameter step is
// large against their distance in the complex plane. At every parameter the inverse power is run
// from every mode's PREDICTED eigenvalue (the secant through its last two, scaled to the step and
// at most twice the last one; the previous eigenvalue at the first step): from the previous one,
// a neighbouring aerodynamic eigenvalue can be nearer than the mode's own (NACA 0012 medium,
// alpha_0 = 1 deg, M = 0.65, Ubar 0.55 -> 0.60 Ubar*: 0.043 against 0.061 away; from the secant
// 0.058 against 0.017), and its structural part overlaps 0.98. Where the step is long for the
// mode's curvature the secant can overshoot onto a neighbour too (there, at 0.05 Ubar* steps
// where the frequency levels off): the steps must be short against the eigenvalue spacing. The
// distinct eigenpairs found are the candidates, and
// each mode takes the candidate whose TRACKED PART (the structural unknowns of an aeroelastic
// system: vg_options::tracked_offset / tracked_size) has the largest normalised overlap
//     |s_prev^H s| / (||s_prev|| ||s||)
// with its previous one (greedy, largest overlap first); for an aeroelastic_system
// (nonlinear/aeroelastic_system.hpp) the tracked part is by default its structure_part(v), so
// any such model is tracked by its structural unknowns. A mode left without a candidate, or
// whose overlap is below vg_options::min_overlap, gets one more inverse power from its previous
// eigenvalue and the assignment is redone.
// Eigenpairs with (almost) no tracked part are no candidates (vg_options::min_tracked_share).
// Where a mode is still without one, or its overlap is below vg_options::min_overlap, the step
// is halved (the intermediate parameters are solved, equilibrium(mu) included, but not
// reported) up to vg_options::max_subdivisions times; then convergence_error.
//
// Start: one vg_mode_start per mode: the shift of the first inverse power (e.g. the in-vacuo
// structural eigenvalue at the first parameter) and optionally the mode's tracked-part vector
// (the in-vacuo mode shape, embedded with zeros elsewhere as the start vector); with the vectors,
// the first parameter's candidates are assigned by overlap with them too, without the
// min_overlap test (the aerodynamic coupling changes the shape).
//
// Flutter points: where a mode's g crosses zero from below between two listed parameters
// (g(mu_j) < 0 <= g(mu_{j+1})), the crossing is the root in [mu_j, mu_{j+1}] of the cubic
// through the mode's g at mu_{j-1} .. mu_{j+2} (fewer at the ends of the list; it matches g at
// mu_j and mu_{j+1}, so the bracket holds): error O(dmu^4) instead of O(dmu^2) for the chord.
// Its frequency is the cubic through the frequencies at that root.
//
// The equilibrium is supplied per parameter (as for root_locus): the symmetric aerofoil returns
// the same flow for every Ubar, an asymmetric case a static aeroelastic solve. Linear algebra:
// sparse or dense LU of A - sigma I by default; a solver of the compute/solve interface for
// A - sigma I (e.g. krylov_solver, complex BILU(k) + GMRES, for CFD sizes), or a factory
// make_solver(w, mu, sigma) returning a fresh one per inverse power (to precondition with the
// modified-order L - sigma I: krylov_solver::precondition_with) may be passed instead.
#include <Eigen/Core>
#include <Eigen/Eigenvalues>

#include <algorithm>
#include <cmath>
#include <complex>
#include <concepts>
#include <iostream>
#include <limits>
#include <memory>
#include <optional>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "../error.hpp"
#include "../nonlinear/aeroelastic_system.hpp"
#include "../nonlinear/block_system.hpp"
#include "../nonlinear/system.hpp"
#include "../linalg/direct.hpp"
#include "../linalg/krylov_solver.hpp"
#include "inverse_power.hpp"

namespace aerohopf {

struct vg_mode_start {
  std::complex<double> shift;          ///< first inverse power's shift (Im > 0 for the upper eigenvalue)
  vec<std::complex<double>> tracked;   ///< optional: the mode's tracked part (size tracked_size), e.g. in-vacuo
};

struct vg_options {
  inverse_power_options inverse_power{};
  /// The part of the eigenvector that identifies a mode: entries [tracked_offset, tracked_offset +
  /// tracked_size). Both 0 (the default): the structural part (structure_part) of an
  /// aeroelastic_system, the whole vector of any other system. tracked_size 0 with an offset:
  /// through the last entry.
  Eigen::Index tracked_offset = 0;
  Eigen::Index tracked_size = 0;
  double min_overlap = 0.9;         ///< a step whose best overlap is below this is halved
  int max_subdivisions = 4;         ///< halvings of one listed step (down to 1/16 of it)
  /// An eigenpair whose tracked part is below this share of the (unit) eigenvector is no
  /// candidate: it does not involve the tracked unknowns, and the direction of its round-off
  /// tracked part is noise that can overlap with anything. (The symmetric aerofoil has such
  /// eigenpairs: flow modes that put no lift or moment on the section, Ubar-independent.)
  double min_tracked_share = 1e-6;
  /// Where the tracking is lost even after max_subdivisions halvings, or the equilibrium callable
  /// throws convergence_error (e.g. a static equilibrium lost past divergence): false, the error
  /// propagates; true, the diagram ends at the last parameter reached (vg_result::complete false,
  /// its stop_reason the error's text), e.g. for a scan that needs only the lowest crossing.
  bool partial_on_lost_tracking = false;
  /// Stop one listed parameter after the first rising zero of g of any mode (the crossing's
  /// cubic then has three of its four points): a scan for the lowest flutter point.
  bool stop_after_flutter = false;
  bool verbose = false;
  std::ostream* log = &std::cout;
};

struct vg_point {
  int mode = 0;
  double mu = 0;
  std::complex<double> lambda;
  double damping = 0;    ///< g = 2 Re(lambda) / |Im(lambda)| (+-infinity for a real eigenvalue)
  double frequency = 0;  ///< |Im(lambda)|, model time unit
  double overlap = 0;    ///< with the mode's previous tracked part (NaN at the first parameter without vg_mode_start::tracked)
  int iterations = 0;    ///< inverse-power iterations of the accepted eigenpair
  double residual = 0;   ///< ||A x - lambda x||_2, ||x||_2 = 1
};

struct vg_flutter_point {
  int mode = 0;
  double mu = 0;         ///< g = 0, g rising with mu
  double frequency = 0;  ///< there, model time unit
};

struct vg_result {
  std::vector<vg_point> points;           ///< mode-major: mode 0 over every mu, then mode 1, ...
  std::vector<vg_flutter_point> flutter;  ///< in mode order, then mu order
  int modes = 0;
  int subdivisions = 0;         ///< halved steps over the whole diagram
  int inverse_powers = 0;       ///< inverse-power solves (each one factorisation of A - sigma I)
  long linear_iterations = 0;   ///< Krylov iterations over all solves (0 with a direct solver)
  bool complete = true;         ///< every listed parameter reached (see vg_options::partial_on_lost_tracking, stop_after_flutter)
  std::string stop_reason;      ///< why not

  /// The points of one mode, in mu order.
  std::vector<vg_point> mode(int k) const {
    std::vector<vg_point> r;
    for (const auto& p : points)
      if (p.mode == k) r.push_back(p);
    return r;
  }
};

/// g = 2 Re(lambda) / |Im(lambda)|.
inline double vg_damping(std::complex<double> lambda) {
  if (lambda.imag() == 0) return lambda.real() == 0 ? 0.0 : std::copysign(std::numeric_limits<double>::infinity(), lambda.real());
  return 2 * lambda.real() / std::abs(lambda.imag());
}

/// One start per oscillatory mode of a structural state matrix (e.g. the in-vacuo -M^{-1} K of
/// the structural unknowns, in the order of the tracked part): its eigenvalues with Im > 0, in
/// increasing frequency, each with its eigenvector as the tracked vector. Real eigenvalues
/// (rigid-body or overdamped modes) are left out.
inline std::vector<vg_mode_start> vg_mode_starts(const Eigen::MatrixXd& structural) {
  require(structural.rows() == structural.cols() && structural.rows() > 0, "vg_mode_starts: matrix is ",
          structural.rows(), "x", structural.cols(), ", not square");
  require_finite(structural.reshaped(), "vg_mode_starts", "structural matrix");
  Eigen::EigenSolver<Eigen::MatrixXd> es(structural);
  require(es.info() == Eigen::Success, "vg_mode_starts: eigen-decomposition failed");
  std::vector<vg_mode_start> r;
  const double scale = std::max(1.0, structural.cwiseAbs().maxCoeff());
  for (Eigen::Index i = 0; i < structural.rows(); ++i) {
    const std::complex<double> l = es.eigenvalues()[i];
    if (l.imag() > 1e-12 * scale) r.push_back({l, es.eigenvectors().col(i)});
  }
  std::sort(r.begin(), r.end(), [](const vg_mode_start& a, const vg_mode_start& b) { return a.shift.imag() < b.shift.imag(); });
  return r;
}

namespace internal {

/// The cubic (or lower) through (x_i, y_i), evaluated at t (Lagrange form; a few points).
inline double lagrange_at(const std::vector<double>& x, const std::vector<double>& y, double t) {
  double s = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    double l = 1;
    for (std::size_t j = 0; j < x.size(); ++j)
      if (j != i) l *= (t - x[j]) / (x[i] - x[j]);
    s += l * y[i];
  }
  return s;
}

/// Zero crossings of g from below along mu for one mode's points (mu increasing), see the file comment.
inline void vg_locate_flutter(const std::vector<vg_point>& m, std::vector<vg_flutter_point>& out) {
  const std::size_t n = m.size();
  for (std::size_t j = 0; j + 1 < n; ++j) {
    if (!(m[j].damping < 0 && m[j + 1].damping >= 0)) continue;
    if (!std::isfinite(m[j].damping) || !std::isfinite(m[j + 1].damping)) continue;
    const std::size_t lo = j > 0 ? j - 1 : j, hi = std::min(n - 1, j + 2);
    std::vector<double> x, g, f;
    for (std::size_t i = lo; i <= hi; ++i) {
      if (!std::isfinite(m[i].damping)) continue;  // a real eigenvalue: leave it out of the fit
      x.push_back(m[i].mu);
      g.push_back(m[i].damping);
      f.push_back(m[i].frequency);
    }
    double a = m[j].mu, b = m[j + 1].mu;
    double ga = m[j].damping;
    if (m[j + 1].damping == 0) {
      out.push_back({m[j].mode, b, m[j + 1].frequency});
      continue;
    }
    for (int it = 0; it < 200 && b - a > 4 * std::numeric_limits<double>::epsilon() * std::max(1.0, std::abs(b)); ++it) {
      const double c = 0.5 * (a + b), gc = lagrange_at(x, g, c);
      if ((gc < 0) == (ga < 0)) {
        a = c;
        ga = gc;
      } else {
        b = c;
      }
    }
    const double r = 0.5 * (a + b);
    out.push_back({m[j].mode, r, lagrange_at(x, f, r)});
  }
}

struct vg_mode_state {
  std::complex<double> lambda;
  vec<std::complex<double>> vector;   // full eigenvector (start of the next inverse power)
  vec<std::complex<double>> tracked;  // its tracked part (the overlap reference)
  std::optional<std::complex<double>> lambda_before;  // the eigenvalue before (secant predictor)
  double mu = 0, mu_before = 0;                       // the parameters of lambda and lambda_before

  /// The secant prediction of the eigenvalue at `to` through the last two, its step at most
  /// twice the last one's (a step after a halved one); the last eigenvalue where there is one.
  std::complex<double> predicted(double to) const {
    if (!lambda_before || mu == mu_before) return lambda;
    const double r = std::min((to - mu) / (mu - mu_before), 2.0);
    return lambda + r * (lambda - *lambda_before);
  }
};

/// The tracer's at(w, mu) of the inverse powers by a factorisation of J: the Jacobian.
template <dynamical_system S>
auto vg_jacobian_at(const S& sys) {
  return [&sys](const vec<double>& w, double mu) { return sys.jacobian(w, mu); };
}

/// The tracer; at(w, mu) makes what the inverse powers at one parameter share (the Jacobian,
/// once per parameter), eig(a, w, mu, shift, start) returns an eigen_pair or throws.
template <dynamical_system S, class Equilibrium, class At, class Eig>
vg_result vg_trace(const S& sys, const Equilibrium& equilibrium, const std::vector<double>& mus,
                   const std::vector<vg_mode_start>& starts, const vg_options& opt, At&& at, Eig&& eig) {
  using C = std::complex<double>;
  constexpr const char* who = "vg_diagram";
  const Eigen::Index n = sys.size();
  require(!mus.empty(), who, ": no parameter values");
  require_finite(mus, who, "parameter list");
  for (std::size_t j = 1; j < mus.size(); ++j)
    require(mus[j] > mus[j - 1], who, ": parameters must increase strictly (mu[", j - 1, "] = ", mus[j - 1], ", mu[", j,
            "] = ", mus[j], ")");
  require(!starts.empty(), who, ": no modes to trace (starts is empty)");
  require(opt.tracked_offset >= 0 && opt.tracked_offset < n, who, ": tracked_offset ", opt.tracked_offset,
          " outside the state of ", n, " entries");
  [[maybe_unused]] bool structural = false;  // the tracked part is sys.structure_part(v)
  if constexpr (aeroelastic_system<S>) {
    if (opt.tracked_offset == 0 && opt.tracked_size == 0) {
      check_aeroelastic_layout(sys, who);
      structural = true;
    }
  }
  Eigen::Index offset = opt.tracked_offset, ts = opt.tracked_size > 0 ? opt.tracked_size : n - opt.tracked_offset;
  if constexpr (aeroelastic_system<S>) {
    if (structural) {
      offset = sys.flow_size();
      ts = sys.structure_size();
    }
  }
  require(offset + ts <= n, who, ": tracked part [", offset, ", ", offset + ts, ") outside the state of ", n,
          " entries");
  require(opt.min_overlap >= 0 && opt.min_overlap <= 1, who, ": min_overlap = ", opt.min_overlap, " outside [0, 1]");
  require(opt.min_tracked_share >= 0 && opt.min_tracked_share < 1, who, ": min_tracked_share = ", opt.min_tracked_share,
          " outside [0, 1)");
  require(opt.max_subdivisions >= 0, who, ": max_subdivisions = ", opt.max_subdivisions, " < 0");
  const bool have_reference = starts.front().tracked.size() > 0;
  for (std::size_t k = 0; k < starts.size(); ++k) {
    require(internal::is_finite_value(starts[k].shift), who, ": start shift of mode ", k, " is not finite");
    require(starts[k].tracked.size() == 0 || starts[k].tracked.size() == ts, who, ": tracked vector of mode ", k, " has ",
            starts[k].tracked.size(), " entries, expected ", ts, " (or none)");
    require((starts[k].tracked.size() > 0) == have_reference, who,
            ": give the tracked vector for every mode or for none (mode ", k, ")");
    if (starts[k].tracked.size()) {
      require_finite(starts[k].tracked, who, "tracked vector of mode " + std::to_string(k));
      require(starts[k].tracked.norm() > 0, who, ": tracked vector of mode ", k, " is zero");
    }
  }
  const int m = static_cast<int>(starts.size());
  vg_result res;
  res.modes = m;
  std::vector<std::vector<vg_point>> by_mode(m);
  auto part = [&](const vec<C>& v) {
    if constexpr (aeroelastic_system<S>) {
      if (structural) return vec<C>(sys.structure_part(v));
    }
    return vec<C>(v.segment(offset, ts));
  };

  struct candidate {
    eigen_pair ep;
    vec<C> tracked;
  };
  // one inverse power; a failed one (no convergence, singular shift) is no candidate
  auto solve = [&](const auto& a, const vec<double>& w, double mu, C shift, const vec<C>* start,
                   std::vector<candidate>& cand) {
    try {
      eigen_pair ep = eig(a, w, mu, shift, start);
      ++res.inverse_powers;
      res.linear_iterations += ep.linear_iterations;
      const double scale = std::max(1.0, std::abs(ep.lambda));
      for (const auto& c : cand)  // the same eigenpair found from another shift
        if (std::abs(c.ep.lambda - ep.lambda) <= 1e-8 * scale && structural_cosine(c.ep.vector, ep.vector) > 1 - 1e-6)
          return;
      vec<C> t = part(ep.vector);
      if (t.norm() < opt.min_tracked_share * ep.vector.norm()) {  // decoupled from the tracked unknowns
        if (opt.verbose && opt.log)
          *opt.log << who << ": mu = " << mu << ", shift " << shift << ": eigenvalue " << ep.lambda
                   << " has no tracked part (" << t.norm() << "): not a mode of the diagram\n";
        return;
      }
      cand.push_back({std::move(ep), std::move(t)});
    } catch (const convergence_error& e) {
      ++res.inverse_powers;
      if (opt.verbose && opt.log) *opt.log << who << ": mu = " << mu << ", shift " << shift << ": " << e.what() << "\n";
    } catch (const singular_matrix_error& e) {
      ++res.inverse_powers;
      if (opt.verbose && opt.log) *opt.log << who << ": mu = " << mu << ", shift " << shift << ": " << e.what() << "\n";
    }
  };
  // greedy assignment by largest overlap; -1 for a mode left without a candidate
  auto assign = [&](const std::vector<vec<C>>& refs, const std::vector<candidate>& cand, std::vector<int>& pick,
                    std::vector<double>& ov) {
    pick.assign(m, -1);
    ov.assign(m, 0.0);
    std::vector<char> used(cand.size(), 0);
    for (int round = 0; round < m; ++round) {
      int bk = -1, bc = -1;
      double best = -1;
      for (int k = 0; k < m; ++k) {
        if (pick[k] >= 0) continue;
        for (std::size_t c = 0; c < cand.size(); ++c) {
          if (used[c]) continue;
          const double o = structural_cosine(refs[k], cand[c].tracked);
          if (o > best) {
            best = o;
            bk = k;
            bc = static_cast<int>(c);
          }
        }
      }
      if (bk < 0) break;
      pick[bk] = bc;
      ov[bk] = best;
      used[bc] = 1;
    }
  };
  auto equilibrium_at = [&](double mu) {
    vec<double> w = equilibrium(mu);
    require_size(w.size(), n, who, internal::concat("equilibrium(mu = ", mu, ")"));
    require_finite(w, who, internal::concat("equilibrium(mu = ", mu, ")"));
    return w;
  };

  // First parameter.
  std::vector<vg_mode_state> state(m);
  {
    const double mu = mus.front();
    const vec<double> w = equilibrium_at(mu);
    const auto a = at(w, mu);
    std::vector<candidate> cand;
    for (int k = 0; k < m; ++k) {
      vec<C> start;
      if (have_reference) {
        start = vec<C>::Zero(n);
        start.segment(offset, ts) = starts[k].tracked;  // the structural part is the last ts entries
      }
      solve(a, w, mu, starts[k].shift, have_reference ? &start : nullptr, cand);
    }
    std::vector<int> pick(m, -1);
    std::vector<double> ov(m, NAN);
    if (have_reference) {
      std::vector<vec<C>> refs(m);
      for (int k = 0; k < m; ++k) refs[k] = starts[k].tracked;
      assign(refs, cand, pick, ov);
    } else {
      // no reference shapes: the start shifts decide; m distinct eigenpairs are needed
      require(static_cast<int>(cand.size()) == m, who, ": at mu = ", mu, " the ", m, " start shifts found ", cand.size(),
              " distinct eigenpairs (two starts converged to one eigenvalue, or an inverse power failed): "
              "give shifts nearer the modes or their tracked vectors");
      for (int k = 0; k < m; ++k) pick[k] = k;
    }
    for (int k = 0; k < m; ++k) {
      if (pick[k] < 0)
        throw convergence_error(internal::concat(who, ": mode ", k, " (start shift ", starts[k].shift,
                                                 ") found no eigenpair of its own at mu = ", mu));
      const auto& c = cand[pick[k]];
      state[k] = {c.ep.lambda, c.ep.vector, c.tracked, std::nullopt, mu, mu};
      by_mode[k].push_back({k, mu, c.ep.lambda, vg_damping(c.ep.lambda), std::abs(c.ep.lambda.imag()), ov[k],
                            c.ep.iterations, c.ep.residual});
    }
  }

  // One step from the current states to mu (the states are replaced); false if a mode was lost.
  std::vector<double> last_overlap(m, NAN);
  std::vector<int> last_iterations(m, 0);
  std::vector<double> last_residual(m, 0.0);
  auto step_to = [&](double mu) -> bool {
    const vec<double> w = equilibrium_at(mu);
    const auto a = at(w, mu);
    std::vector<candidate> cand;
    for (int k = 0; k < m; ++k) solve(a, w, mu, state[k].predicted(mu), &state[k].vector, cand);
    std::vector<vec<C>> refs(m);
    for (int k = 0; k < m; ++k) refs[k] = state[k].tracked;
    std::vector<int> pick;
    std::vector<double> ov;
    assign(refs, cand, pick, ov);
    bool retry = false;
    for (int k = 0; k < m; ++k)
      if ((pick[k] < 0 || ov[k] < opt.min_overlap) && state[k].lambda_before) {
        solve(a, w, mu, state[k].lambda, &state[k].vector, cand);
        retry = true;
      }
    if (retry) assign(refs, cand, pick, ov);
    for (int k = 0; k < m; ++k)
      if (pick[k] < 0 || ov[k] < opt.min_overlap) {
        if (opt.verbose && opt.log)
          *opt.log << who << ": mu = " << mu << ": mode " << k
                   << (pick[k] < 0 ? " found no eigenpair" : internal::concat(" overlap ", ov[k], " < min_overlap")) << "\n";
        return false;
      }
    for (int k = 0; k < m; ++k) {
      const auto& c = cand[pick[k]];
      state[k].lambda_before = state[k].lambda;
      state[k].mu_before = state[k].mu;
      state[k].lambda = c.ep.lambda;
      state[k].mu = mu;
      state[k].vector = c.ep.vector;
      state[k].tracked = c.tracked;
      last_overlap[k] = ov[k];
      last_iterations[k] = c.ep.iterations;
      last_residual[k] = c.ep.residual;
    }
    return true;
  };
  // Step to mu_to, halving the step where it fails; the reported overlap is the smallest over the substeps.
  auto advance = [&](auto&& self, double mu_from, double mu_to, int depth, std::vector<double>& min_ov) -> void {
    if (step_to(mu_to)) {  // (a failed step leaves the states as they were)
      for (int k = 0; k < m; ++k) min_ov[k] = std::min(min_ov[k], last_overlap[k]);
      return;
    }
    if (depth >= opt.max_subdivisions) {
      std::ostringstream os;
      os << who << ": mode tracking lost between mu = " << mu_from << " and " << mu_to << " after " << depth
         << " halvings of the step (a mode found no eigenpair with tracked-part overlap >= " << opt.min_overlap
         << "; last eigenvalues";
      for (int k = 0; k < m; ++k) os << " " << state[k].lambda;
      os << "): refine the parameter list or lower vg_options::min_overlap";
      throw convergence_error(os.str());
    }
    ++res.subdivisions;
    const double mid = 0.5 * (mu_from + mu_to);
    self(self, mu_from, mid, depth + 1, min_ov);
    self(self, mid, mu_to, depth + 1, min_ov);
  };
  std::size_t rose_at = 0;  // the parameter where some mode's g first crossed zero from below (0: none yet)
  for (std::size_t j = 1; j < mus.size(); ++j) {
    if (rose_at > 0 && j > rose_at + 1) {
      res.complete = false;
      res.stop_reason = internal::concat("stopped one parameter after the first rising zero of g (stop_after_flutter), at mu = ",
                                         mus[j - 1]);
      break;
    }
    std::vector<double> min_ov(m, 1.0);
    try {
      advance(advance, mus[j - 1], mus[j], 0, min_ov);
    } catch (const convergence_error& e) {
      if (!opt.partial_on_lost_tracking) throw;
      res.complete = false;
      res.stop_reason = e.what();
      break;
    }
    for (int k = 0; k < m; ++k) {
      if (opt.stop_after_flutter && rose_at == 0 && by_mode[k].back().damping < 0 && vg_damping(state[k].lambda) >= 0)
        rose_at = j;
      by_mode[k].push_back({k, mus[j], state[k].lambda, vg_damping(state[k].lambda), std::abs(state[k].lambda.imag()),
                            min_ov[k], last_iterations[k], last_residual[k]});
      if (opt.verbose && opt.log)
        *opt.log << who << ": mu = " << mus[j] << "  mode " << k << "  lambda " << state[k].lambda << "  g "
                 << by_mode[k].back().damping << "  overlap " << min_ov[k] << "\n";
    }
  }
  for (int k = 0; k < m; ++k) {
    res.points.insert(res.points.end(), by_mode[k].begin(), by_mode[k].end());
    vg_locate_flutter(by_mode[k], res.flutter);
  }
  return res;
}

}  // namespace internal

/// V-g / V-f diagram of the modes started by `starts` over the increasing parameters `mus`;
/// equilibrium(mu) returns w0(mu). Sparse or dense LU of A - sigma I.
template <dynamical_system S, class Equilibrium>
  requires std::invocable<const Equilibrium&, double>
vg_result vg_diagram(const S& sys, const Equilibrium& equilibrium, const std::vector<double>& mus,
                     const std::vector<vg_mode_start>& starts, const vg_options& opt = {}) {
  return internal::vg_trace(sys, equilibrium, mus, starts, opt, internal::vg_jacobian_at(sys),
                            [&](const jacobian_t<S>& a, const vec<double>&, double, std::complex<double> shift,
                                const vec<std::complex<double>>* start) {
                              return inverse_power(a, shift, opt.inverse_power, start);
                            });
}

/// The same with the linear algebra of A - sigma I given: either a solver of the compute/solve
/// interface (inverse_power.hpp; compute(A - sigma I) is called for every inverse power), or a
/// factory make_solver(w, mu, sigma) returning such a solver for that one inverse power, e.g.
///   [&](const vec<double>& w, double mu, std::complex<double> sigma) {
///     krylov_solver<Eigen::SparseMatrix<std::complex<double>>, 4> s(ko, "V-g inverse power");
///     s.precondition_with(shifted(sys.approximate_jacobian(w, mu), sigma));
///     return s;
///   }
template <dynamical_system S, class Equilibrium, class SolverOrFactory>
  requires std::invocable<const Equilibrium&, double>
vg_result vg_diagram(const S& sys, const Equilibrium& equilibrium, const std::vector<double>& mus,
                     const std::vector<vg_mode_start>& starts, const vg_options& opt, SolverOrFactory&& solver) {
  using C = std::complex<double>;
  return internal::vg_trace(sys, equilibrium, mus, starts, opt, internal::vg_jacobian_at(sys),
                            [&](const jacobian_t<S>& a, const vec<double>& w, double mu, C shift, const vec<C>* start) {
                              if constexpr (std::invocable<SolverOrFactory&, const vec<double>&, double, C>) {
                                auto s = solver(w, mu, shift);
                                return inverse_power(a, shift, opt.inverse_power, start, s);
                              } else {
                                return inverse_power(a, shift, opt.inverse_power, start, solver);
                              }
                            });
}

/// Options of vg_krylov_solvers.
struct vg_krylov_options {
  int fill_level = 2;  ///< k of the complex BILU(k) of L - sigma I
  /// GMRES of each shift-invert solve: tighter than vg_options::inverse_power.tolerance (inexact
  /// inverse iteration with a fixed tolerance stagnates near it, inverse_power.hpp).
  krylov_options krylov = [] {
    krylov_options o;
    o.relative_tolerance = 1e-10;
    o.max_iterations = 2000;
    o.restart = 50;  // as the inverse-power start of the boundary driver
    o.record_history = false;
    return o;
  }();
};

/// The solver factory of vg_diagram for CFD sizes, where a sparse LU of A - sigma I per inverse
/// power is too dear: each solve (A - sigma I) y = x by complex GMRES on the exact A - sigma I in
/// the bordered form (flow blocks of B + the structural border, krylov_border_size),
/// right-preconditioned by the complex BILU(k) of the flow part of L - sigma I with the border
/// eliminated exactly (bordered_krylov_solver), L = lhs_jacobian (the model's preconditioning
/// Jacobian, e.g. the aerofoil's modified-order one), assembled once per parameter value (the
/// equilibrium is a function of it) and shifted per inverse power. Use it with
/// vg_options::inverse_power.tolerance above krylov.relative_tolerance (1e-9 with the default
/// 1e-10). The factory keeps a reference to sys.
template <int B, dynamical_system S>
  requires is_sparse_matrix_v<jacobian_t<S>>
auto vg_krylov_solvers(const S& sys, const vg_krylov_options& o = {}) {
  constexpr const char* who = "vg_krylov_solvers";
  require(o.fill_level >= 0, who, ": fill_level must be >= 0 (got ", o.fill_level, ")");
  validate_krylov_options(o.krylov, who);
  struct lhs_cache {
    double mu = NAN;
    bordered_block_matrix<double, B> l;
  };
  const Eigen::Index border = krylov_border_size<B>(sys);
  return [&sys, o, border, cache = std::make_shared<lhs_cache>()](const vec<double>& w, double mu,
                                                                 std::complex<double> sigma) {
    if (!(mu == cache->mu)) {
      cache->l = bordered_from_sparse<B>(lhs_jacobian(sys, w, mu), border, "vg_krylov_solvers");
      cache->mu = mu;
    }
    krylov_solver_options ko;
    ko.fill_level = o.fill_level;
    ko.krylov = o.krylov;
    bordered_krylov_solver<Eigen::SparseMatrix<std::complex<double>>, B> solver(
        border, ko, "V-g inverse power, bordered complex BILU-GMRES");
    solver.precondition_with(cache->l, sigma);
    return solver;
  };
}

}  // namespace aerohopf
