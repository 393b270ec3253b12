#pragma once
// An aeroelastic system on MPI ranks in the bordered form: the flow grid partitioned as in
// mpi_euler.hpp, the n_s structural unknowns on one rank, the root. The common part of the
// distributed pitch-plunge aerofoil (mpi_aerofoil.hpp) and the distributed modal wing
// (mpi_wing.hpp), and the solvers written once against it.
//
// Local vectors: this rank's flow values (distributed_euler's order), then n_s structural
// values, which are significant on the root only: on input the root's are broadcast (the
// others' are not read), on output the other ranks hold zeros there. A sum over the ranks of
// local inner products therefore counts the structure once, so these vectors serve the
// distributed Krylov methods as they are.
//
// Jacobian rows (bordered_rows): A_ff in this rank's rows (distributed_euler's numbering), A_fs
// (its rows x n_s), A_sf (n_s x its flow values: its wall cells' columns) and A_ss (the same on
// every rank). multiply() applies them with the structural part broadcast from the root and the
// structural rows summed onto it.
//
// Solvers (each collective, each the serial algorithm with sums over the ranks):
//  - basic_distributed_bordered_preconditioner: block-Jacobi BILU(k) of the flow rows, the
//    border eliminated exactly (n_s x n_s Schur complement);
//  - inverse_power: the eigenpair nearest a shift (the root locus' and the Hopf start's);
//  - solve_equilibrium: the static aeroelastic equilibrium by Newton-GMRES;
//  - root_locus: the eigenvalue of one mode along the parameter.
// A model D derived from distributed_bordered<Dim> supplies residual(local, mu),
// jacobian(local, mu, kind, rows) and jacobians(local, mu, exact rows, preconditioning rows), and
// for the Hopf solve (mpi_hopf.hpp) set_parameter(rows, mu) (the rows moved to another mu
// without re-assembly), residual_d_parameter(local, mu) = f_mu and parameter_column(rows, x) =
// A_mu x. Tests: tests/distributed/test_mpi_aerofoil.cpp and test_mpi_wing.cpp (the two models).

#include <mpi.h>

#include <aerohopf/bifurcation/root_locus.hpp>
#include <aerohopf/distributed/mpi_eigen.hpp>
#include <aerohopf/distributed/mpi_euler.hpp>
#include <aerohopf/linalg/block_ilu.hpp>
#include <aerohopf/linalg/krylov.hpp>

#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <complex>
#include <functional>
#include <string>
#include <type_traits>
#include <vector>

namespace aerohopf::distributed {

/// The bordered Jacobian in one rank's rows (file comment).
template <int Dim>
struct bordered_rows {
  static constexpr int nv = Dim + 2;
  block_sparse_matrix<double, nv> flow;  ///< A_ff: this rank's cells' rows, distributed_euler's numbering
  Eigen::MatrixXd flow_structure;        ///< A_fs: this rank's flow rows x n_s
  Eigen::MatrixXd structure_flow;        ///< A_sf: n_s x this rank's flow values (its wall cells' columns)
  Eigen::MatrixXd structure;             ///< A_ss (the same on every rank)
  double mu = NAN;                       ///< the parameter the rows were assembled (or moved) at
  /// d/dmu of A_sf and A_ss where the model's border is affine in mu (the wing: mu scales the
  /// generalised forces); empty where it is not (the aerofoil: the stiffness in Ubar).
  Eigen::MatrixXd structure_flow_d_mu, structure_d_mu;
};

template <int Dim>
class distributed_bordered {
 public:
  static constexpr int nv = Dim + 2;
  static constexpr int root = 0;
  using jacobian_rows = bordered_rows<Dim>;

  int rank() const { return dist_->rank(); }
  distributed_euler<Dim>& flow() { return *dist_; }
  const distributed_euler<Dim>& flow() const { return *dist_; }
  Eigen::Index flow_size() const { return dist_->local_size(); }
  Eigen::Index structure_size() const { return ns_; }
  Eigen::Index local_size() const { return dist_->local_size() + ns_; }
  /// Unknowns of the whole (serial) system.
  Eigen::Index global_size() const { return dist_->model().size() + ns_; }
  /// The parameter's name in messages ("Ubar", "mu").
  const char* parameter_name() const { return parameter_; }

  /// This rank's part of a whole state or vector (global_size() values): its flow values, then
  /// the structure on the root and zeros elsewhere.
  vec<double> local_part(const vec<double>& global) const {
    require_size(global.size(), global_size(), "distributed local_part", "global vector");
    vec<double> local(local_size());
    local.head(flow_size()) = dist_->local_part(global.head(dist_->model().size()));
    local.tail(ns_) = rank() == root ? vec<double>(global.tail(ns_)) : vec<double>::Zero(ns_);
    return local;
  }

  /// The whole vector from every rank's part, on every rank (collective; output and tests).
  vec<double> all_gather(const vec<double>& local) {
    check_local(local, "distributed all_gather");
    vec<double> global(global_size());
    global.head(dist_->model().size()) = dist_->all_gather(local.head(flow_size()));
    global.tail(ns_) = structure_of(local);
    return global;
  }

  /// The same for a complex vector (an eigenvector), by its real and imaginary parts.
  vec<std::complex<double>> local_part(const vec<std::complex<double>>& global) const {
    return join(local_part(vec<double>(global.real())), local_part(vec<double>(global.imag())));
  }
  vec<std::complex<double>> all_gather(const vec<std::complex<double>>& local) {
    return join(all_gather(vec<double>(local.real())), all_gather(vec<double>(local.imag())));
  }

  /// y = J x in this rank's part, real or complex vectors (collective: the flow's halo, the
  /// structure's broadcast and the structural rows' sum).
  template <class S = double>
  vec<S> multiply(const jacobian_rows& j, const vec<S>& x) {
    static_assert(std::is_same_v<S, double> || std::is_same_v<S, std::complex<double>>,
                  "distributed multiply: double or std::complex<double> vectors");
    check_local(x, "distributed multiply");
    const vec<S> xs = structure_of(x);
    const vec<S> xf = x.head(flow_size());
    vec<S> y(local_size());
    y.head(flow_size()) = dist_->multiply(j.flow, xf);
    y.head(flow_size()).noalias() += j.flow_structure * xs;
    vec<S> part = j.structure_flow * xf;
    sum(part.data(), static_cast<int>(ns_));
    if (rank() == root) {
      part.noalias() += j.structure * xs;
      y.tail(ns_) = part;
    } else {
      y.tail(ns_).setZero();
    }
    return y;
  }

  /// The root's structural values of a local vector, on every rank (collective).
  template <class S>
  vec<S> structure_of(const vec<S>& local) const {
    vec<S> s = local.tail(ns_);
    internal::check_mpi(MPI_Bcast(s.data(), static_cast<int>(ns_) * static_cast<int>(sizeof(S) / sizeof(double)),
                                  MPI_DOUBLE, root, comm_),
                        "MPI_Bcast");
    return s;
  }

  /// Throws input_error on every rank unless every rank's `local` has local_size() finite
  /// entries and the parameter mu is finite (collective).
  void check_state(const vec<double>& local, double mu, const char* who) const {
    internal::collective(comm_, who, [&] {
      require(std::isfinite(mu), who, ": ", parameter_, " ", mu, " is not finite");
      require_size(local.size(), local_size(), who, "state (this rank's flow values and the structural ones)");
      require_finite(local, who, "state (this rank's part)");
    });
  }

  /// In-place sum over the ranks (collective).
  void sum(double* p, int n) const { internal::sum_over_ranks(comm_, p, n); }
  void sum(std::complex<double>* p, int n) const { internal::sum_over_ranks(comm_, p, n); }
  MPI_Comm communicator() const { return comm_; }

 protected:
  distributed_bordered(Eigen::Index ns, MPI_Comm comm, const char* parameter)
      : ns_(ns), comm_(comm), parameter_(parameter) {}
  distributed_bordered(const distributed_bordered&) = delete;
  distributed_bordered& operator=(const distributed_bordered&) = delete;
  /// The derived model's distributed flow (constructed after this base).
  void attach(distributed_euler<Dim>& d) { dist_ = &d; }

  template <class S>
  void check_local(const vec<S>& local, const char* who) const {
    internal::collective(comm_, who, [&] {
      require_size(local.size(), local_size(), who, "local vector (this rank's flow values and the structural ones)");
    });
  }

  /// A_sf and A_ss of rows `j` from jet derivatives: fills j.flow_structure (this rank's rows)
  /// and j.structure from a residual pass whose structural unknowns j0 .. j0 + width - 1 carried
  /// the jet directions 0 .. width - 1 (rj: the whole-grid flow residual, this rank's cells
  /// written; rs: the structural rows, summed over the ranks already).
  template <class Jet>
  void store_coupling_columns(const vec<Jet>& rj, const vec<Jet>& rs, Eigen::Index j0, Eigen::Index width,
                              jacobian_rows& j) const {
    const auto& num = dist_->numbering();
    for (const auto& [first, last] : dist_->plan().owned)
      for (std::size_t c = first; c < last; ++c)
        for (int v = 0; v < nv; ++v)
          for (Eigen::Index k = 0; k < width; ++k)
            j.flow_structure(num.local[c] * nv + v, j0 + k) =
                rj[static_cast<Eigen::Index>(c * nv + v)].derivative(static_cast<int>(k));
    for (Eigen::Index i = 0; i < ns_; ++i)
      for (Eigen::Index k = 0; k < width; ++k) j.structure(i, j0 + k) = rs[i].derivative(static_cast<int>(k));
  }

  static vec<std::complex<double>> join(const vec<double>& re, const vec<double>& im) {
    vec<std::complex<double>> z(re.size());
    z.real() = re;
    z.imag() = im;
    return z;
  }

  distributed_euler<Dim>* dist_ = nullptr;
  Eigen::Index ns_;
  MPI_Comm comm_;
  const char* parameter_;
};

/// J - sigma I of bordered Jacobian rows as a distributed linear operator on complex local
/// vectors (inner products summed over the ranks: the structure counts once). `d` and `j` must
/// outlive it.
template <int Dim>
class distributed_shifted_operator {
 public:
  distributed_shifted_operator(distributed_bordered<Dim>& d, const bordered_rows<Dim>& j, std::complex<double> sigma)
      : d_(&d), j_(&j), sigma_(sigma) {}
  Eigen::Index rows() const { return d_->local_size(); }
  Eigen::Index cols() const { return d_->local_size(); }
  void apply(const vec<std::complex<double>>& x, vec<std::complex<double>>& y) const {
    y = d_->multiply(*j_, x);
    if (d_->rank() == distributed_bordered<Dim>::root) y -= sigma_ * x;
    else y.head(d_->flow_size()) -= sigma_ * x.head(d_->flow_size());
  }
  void global_sum(double* p, int n) const { d_->sum(p, n); }
  void global_sum(std::complex<double>* p, int n) const { d_->sum(p, n); }

 private:
  distributed_bordered<Dim>* d_;
  const bordered_rows<Dim>* j_;
  std::complex<double> sigma_;
};

/// J on real vectors of the ranks (the static equilibrium's and the full Hopf flow update's
/// operator), J the Jacobian rows j.
template <int Dim>
class real_bordered_operator {
 public:
  real_bordered_operator(distributed_bordered<Dim>& d, const bordered_rows<Dim>& j) : d_(&d), j_(&j) {}
  Eigen::Index rows() const { return d_->local_size(); }
  Eigen::Index cols() const { return d_->local_size(); }
  void apply(const vec<double>& x, vec<double>& y) const { y = d_->multiply(*j_, x); }
  void global_sum(double* p, int n) const { d_->sum(p, n); }

 private:
  distributed_bordered<Dim>* d_;
  const bordered_rows<Dim>* j_;
};

/// Block-Jacobi preconditioner of P - sigma I for bordered rows P (the preconditioning matrix,
/// the modified-order rows): BILU(k) M of each rank's own part of A_ff - sigma I, and the border
/// eliminated exactly around it. With Y = M^{-1} A_fs (this rank's rows) and the Schur complement
/// S = (A_ss - sigma I) - sum over ranks A_sf Y (n_s x n_s, the same LU on every rank),
/// z = P^{-1} r is y_f = M^{-1} r_f, z_s = S^{-1} (r_s - sum A_sf y_f), z_f = y_f - Y z_s: one
/// BILU solve and two small reductions per apply. S = std::complex<double> (any shift) or double
/// (sigma = 0: the real solves with the Jacobian itself, e.g. Newton on the equilibrium).
template <int Dim, class S>
class basic_distributed_bordered_preconditioner {
 public:
  using C = S;
  static constexpr int nv = Dim + 2;
  explicit basic_distributed_bordered_preconditioner(block_ilu_options o = {}) : ilu_(std::move(o)) {}

  /// Collective; singular_matrix_error (every rank) if a BILU pivot or the Schur complement is
  /// singular.
  void compute(distributed_bordered<Dim>& d, const bordered_rows<Dim>& p, C sigma) {
    d_ = &d;
    const Eigen::Index ns = d.structure_size();
    internal::collective(d.communicator(), "distributed bordered preconditioner", [&] {
      require(p.flow_structure.rows() == d.flow_size() && p.flow_structure.cols() == ns &&
                  p.structure_flow.rows() == ns && p.structure_flow.cols() == d.flow_size() &&
                  p.structure.rows() == ns && p.structure.cols() == ns,
              "distributed bordered preconditioner: the rows' border does not match the system (", ns,
              " structural unknowns, ", d.flow_size(), " flow values on this rank)");
      if constexpr (std::is_same_v<S, double>) {
        require(sigma == 0.0, "distributed bordered preconditioner: a real preconditioner has shift 0 (got ", sigma, ")");
        ilu_.compute(owned_part(p.flow));
      } else {
        ilu_.compute(shifted(owned_part(p.flow), sigma));
      }
      y_.resize(d.flow_size(), ns);
      vec<C> col(d.flow_size()), out(d.flow_size());
      for (Eigen::Index k = 0; k < ns; ++k) {
        col = p.flow_structure.col(k).template cast<C>();
        ilu_.apply(col, out);
        y_.col(k) = out;
      }
      sf_ = p.structure_flow.template cast<C>();
    });
    mat t = sf_ * y_;
    d.sum(t.data(), static_cast<int>(t.size()));
    mat schur = p.structure.template cast<C>();
    schur -= t;
    schur.diagonal().array() -= sigma;
    lu_.compute(schur);
    const double det = std::abs(lu_.determinant());
    if (!(det > 0) || !std::isfinite(det))
      throw singular_matrix_error(aerohopf::internal::concat("distributed bordered preconditioner: the ", ns, " x ", ns,
                                                             " Schur complement of the structure is singular"));
  }

  Eigen::Index rows() const { return d_ ? d_->local_size() : 0; }

  void apply(const vec<C>& r, vec<C>& z) const {
    const Eigen::Index nf = d_->flow_size(), ns = d_->structure_size();
    z.resize(r.size());
    vec<C> yf(nf);
    ilu_.apply(vec<C>(r.head(nf)), yf);
    vec<C> t = sf_ * yf;
    d_->sum(t.data(), static_cast<int>(ns));
    const vec<C> rs = d_->structure_of(r);
    const vec<C> rhs = rs - t;
    const vec<C> zs = lu_.solve(rhs);
    z.head(nf) = yf - y_ * zs;
    if (d_->rank() == distributed_bordered<Dim>::root) z.tail(ns) = zs;
    else z.tail(ns).setZero();
  }

 private:
  using mat = Eigen::Matrix<C, Eigen::Dynamic, Eigen::Dynamic>;
  distributed_bordered<Dim>* d_ = nullptr;
  block_ilu<C, nv> ilu_;
  mat y_, sf_;
  Eigen::PartialPivLU<mat> lu_;
};

/// The eigenpair of the aeroelastic Jacobian J (rows `a`) nearest `shift` on the ranks: the one
/// inverse-power iteration (bifurcation/inverse_power.hpp) with sums over the ranks, each solve
/// complex GMRES on J - sigma I preconditioned by the complex bordered preconditioner of `pre`
/// (the modified-order rows; nullptr: `a`). `start`: this rank's part (nullptr: the part of the
/// serial default start). The vector of the result is this rank's part (structure on the
/// root). Collective; errors as distributed::inverse_power (mpi_eigen.hpp).
template <int Dim>
eigen_pair inverse_power(distributed_bordered<Dim>& d, const bordered_rows<Dim>& a, const bordered_rows<Dim>* pre,
                         std::complex<double> shift, const distributed_inverse_power_options& opt = {},
                         const vec<std::complex<double>>* start = nullptr) {
  using C = std::complex<double>;
  constexpr int nv = Dim + 2;
  const char* who = "distributed inverse power (aeroelastic)";
  const MPI_Comm comm = d.communicator();
  const Eigen::Index ns = d.structure_size();
  vec<double> row_sums;
  internal::collective(comm, who, [&] {
    require(std::isfinite(shift.real()) && std::isfinite(shift.imag()), who, ": shift ", shift, " is not finite");
    require(opt.power.max_iterations >= 1 && std::isfinite(opt.power.tolerance) && opt.power.tolerance > 0, who,
            ": need max_iterations >= 1 and a finite tolerance > 0");
    if (start) {
      require_size(start->size(), d.local_size(), who, "start vector (this rank's part)");
      require_finite(*start, who, "start vector");
    }
    const auto& fv = a.flow.values();
    require(std::all_of(fv.begin(), fv.end(), [](double v) { return std::isfinite(v); }) &&
                a.flow_structure.allFinite() && a.structure_flow.allFinite() && a.structure.allFinite(),
            who, ": a Jacobian entry is not finite");
    row_sums = vec<double>::Zero(d.flow_size());
    for (Eigen::Index i = 0; i < a.flow.block_rows(); ++i)
      for (auto p = a.flow.row_ptr()[i]; p < a.flow.row_ptr()[i + 1]; ++p)
        row_sums.segment(i * nv, nv) += a.flow.block_at(p).cwiseAbs().rowwise().sum();
    row_sums += a.flow_structure.cwiseAbs().rowwise().sum();
  });
  double a_norm = row_sums.size() ? row_sums.maxCoeff() : 0.0;
  vec<double> border = a.structure_flow.cwiseAbs().rowwise().sum();
  d.sum(border.data(), static_cast<int>(ns));
  a_norm = internal::max_over_ranks(comm, a_norm);
  border += a.structure.cwiseAbs().rowwise().sum();
  a_norm = std::max(a_norm, border.maxCoeff());

  block_ilu_options io;
  io.fill_level = opt.fill_level;
  io.single_precision_factors = opt.single_precision_factors;
  io.context = "distributed inverse power (aeroelastic): block-Jacobi BILU of P - sigma I";
  basic_distributed_bordered_preconditioner<Dim, C> pc(io);
  pc.compute(d, pre ? *pre : a, shift);
  const distributed_shifted_operator<Dim> op(d, a, shift);
  return internal::run_inverse_power(
      comm, start, d.global_size(), [&d](const vec<double>& g) { return d.local_part(g); },
      [&](const vec<C>& v) { return d.multiply(a, v); }, op, pc, shift, a_norm, opt, who);
}

struct distributed_equilibrium_options {
  int fill_level = 2;           ///< k of the real block-Jacobi BILU(k) of the modified-order rows
  double tolerance = 1e-10;     ///< ||f(w, mu)||_2 over the ranks
  int max_iterations = 25;      ///< full Newton steps
  double eta_max = 1e-2;        ///< GMRES forcing eta_k = min(eta_max, max(||f_k||, 0.1 tolerance / ||f_k||))
  krylov_options krylov = newton_correction_krylov_options();
};

struct distributed_equilibrium_result {
  vec<double> w;            ///< this rank's part of the last iterate (the equilibrium if converged)
  bool converged = false;
  int iterations = 0;
  long linear_iterations = 0;
  double residual = NAN;    ///< ||f|| of w
  std::string reason;       ///< why not converged (the same text on every rank)
};

/// The static aeroelastic equilibrium f(w, mu) = 0 on the ranks (as solve_equilibrium_krylov
/// for the serial system with full steps): Newton from w0 (this rank's part), each step by GMRES
/// on the exact Jacobian rows preconditioned by the real block-Jacobi BILU(k) of the
/// modified-order rows with the structure eliminated exactly, the inexact forcing of the
/// options. Converged when ||f||_2 <= tolerance; a non-finite residual, a GMRES failure, a
/// breakdown or the iteration limit is a result with converged = false and the reason, the
/// same on every rank (the last finite iterate in w). Collective. D: a model derived from
/// distributed_bordered (distributed_aerofoil, distributed_wing).
template <class D>
distributed_equilibrium_result solve_equilibrium(D& d, vec<double> w0, double mu,
                                                 const distributed_equilibrium_options& opt = {}) {
  constexpr int dim = D::nv - 2;
  const char* who = "distributed solve_equilibrium (aeroelastic)";
  internal::collective(d.communicator(), who, [&] {
    validate_krylov_options(opt.krylov, who);
    require(opt.fill_level >= 0 && opt.fill_level <= 8, who, ": fill_level must lie in [0, 8] (got ", opt.fill_level,
            ")");
    require(opt.tolerance > 0 && std::isfinite(opt.tolerance), who, ": tolerance must be finite and > 0");
    require(opt.max_iterations >= 1, who, ": max_iterations must be >= 1");
    require(opt.eta_max > 0 && opt.eta_max < 1, who, ": eta_max must lie in (0, 1)");
  });
  d.check_state(w0, mu, who);
  const char* param = d.parameter_name();
  distributed_equilibrium_result r;
  r.w = std::move(w0);
  auto norm = [&d](const vec<double>& f) {
    double q = f.allFinite() ? f.squaredNorm() : NAN;
    d.sum(&q, 1);
    return std::sqrt(q);
  };
  block_ilu_options io;
  io.fill_level = opt.fill_level;
  io.context = aerohopf::internal::concat(who, ": block-Jacobi BILU(", opt.fill_level, ") of L");
  basic_distributed_bordered_preconditioner<dim, double> pc(io);
  bordered_rows<dim> a, l;
  vec<double> f = d.residual(r.w, mu);
  r.residual = norm(f);
  for (int k = 0;; ++k) {
    if (!std::isfinite(r.residual)) {
      r.reason = aerohopf::internal::concat(who, ": the residual is not finite at iterate ", k, " (", param, " = ", mu, ")");
      return r;
    }
    if (r.residual <= opt.tolerance) {
      r.converged = true;
      return r;
    }
    if (k >= opt.max_iterations) {
      r.reason = aerohopf::internal::concat(who, ": no convergence in ", opt.max_iterations,
                                            " Newton iterations (||f|| = ", r.residual, ", ", param, " = ", mu, ")");
      return r;
    }
    try {
      d.jacobians(r.w, mu, a, l);
      pc.compute(d, l, 0.0);
      const real_bordered_operator<dim> op(d, a);
      krylov_options ko = opt.krylov;
      ko.relative_tolerance = std::min(opt.eta_max, std::max(r.residual, 0.1 * opt.tolerance / r.residual));
      ko.throw_on_failure = true;
      ko.context = aerohopf::internal::concat(who, ": GMRES, Newton step ", k + 1);
      vec<double> dw = vec<double>::Zero(r.w.size());
      r.linear_iterations += gmres<double>(op, pc, vec<double>(-f), dw, ko).iterations;
      vec<double> w = r.w + dw;
      const vec<double> fw = d.residual(w, mu);
      const double fn = norm(fw);
      r.iterations = k + 1;
      if (!std::isfinite(fn)) {
        r.reason = aerohopf::internal::concat(who, ": the residual is not finite after Newton step ", k + 1, " (", param,
                                              " = ", mu, ")");
        return r;
      }
      r.w = std::move(w);
      f = fw;
      r.residual = fn;
    } catch (const input_error&) {
      throw;
    } catch (const error& e) {
      r.reason = aerohopf::internal::concat(who, ": Newton step ", k + 1, ": ", e.what());
      return r;
    }
  }
}

/// The root locus (bifurcation/root_locus.hpp, the same loop) on the ranks: equilibrium(mu)
/// returns this rank's part of w0(mu) (e.g. the distributed steady solve's, or local_part of a
/// known state); each point's eigenpair by inverse_power above, from the previous point's
/// eigenvalue (shift) and eigenvector part (start). Collective; errors as root_locus. D as for
/// solve_equilibrium.
template <class D>
std::vector<root_locus_point> root_locus(D& d, const std::function<vec<double>(double)>& equilibrium,
                                         const std::vector<double>& mus, std::complex<double> shift0,
                                         const distributed_inverse_power_options& opt = {}) {
  typename D::jacobian_rows a, p;
  return aerohopf::internal::root_locus_loop(
      equilibrium, [&d](const vec<double>& w, double mu) { d.check_state(w, mu, "distributed root_locus"); },
      [&](double mu, const vec<double>& w, std::complex<double> shift, const vec<std::complex<double>>* start) {
        d.jacobians(w, mu, a, p);
        return inverse_power(d, a, &p, shift, opt, start);
      },
      mus, shift0, opt.power, "distributed root_locus");
}

}  // namespace aerohopf::distributed
