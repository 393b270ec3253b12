#pragma once
// The pitch-plunge aerofoil (models/aerofoil.hpp) on MPI ranks: the flow grid partitioned as in
// mpi_euler.hpp, the four structural unknowns (h, h', alpha, alpha') on one rank, the root.
//
// Local vectors: this rank's flow values (distributed_euler's order), then 4 structural values,
// which are significant on the root only: on input the root's are broadcast (the others' are
// not read), on output the other ranks hold zeros there. A sum over the ranks of local inner
// products therefore counts the structure once, so these vectors serve the distributed Krylov
// methods as they are.
//
// Evaluations, each collective and each equal to the serial system's (tests on 2 and 3 ranks):
//  - residual: the flow rows of the rank's cells on the grid moved to the structural state
//    (aerofoil_system::moved_metrics and the rest model's residual_of_blocks, bitwise the serial
//    rows) and the structural rates from the
//    loads, whose parts (the wall faces of each rank's blocks) are summed over the ranks;
//  - jacobian: the bordered form in the rank's rows: A_ff (distributed_euler's numbering, on the
//    moved grid as the serial assembly), A_fs (its rows) and A_ss from one jet<double, 4> pass of
//    the rank's residual and loads (the loads' derivatives summed over the ranks), A_sf (its
//    wall cells' columns); multiply() applies it with the structural part broadcast from the root
//    and the structural rows summed onto it.
// Eigenpairs: inverse_power(d, J rows, P rows, shift) below, GMRES on J - sigma I with
// distributed_aerofoil_preconditioner (block-Jacobi BILU of the flow, the border eliminated
// exactly): the root locus' and the Hopf start's eigen-solve on the ranks.
// Memory: as distributed_euler (the grid replicated), plus a moved copy of the flow model and,
// during the jet pass, a whole-grid jet state (five doubles per value).

#include <mpi.h>

#include <aerohopf/bifurcation/root_locus.hpp>
#include <aerohopf/distributed/mpi_eigen.hpp>
#include <aerohopf/distributed/mpi_euler.hpp>
#include <aerohopf/linalg/block_ilu.hpp>
#include <aerohopf/linalg/krylov.hpp>
#include <aerohopf/models/aerofoil.hpp>
#include <aerohopf/scalar/jet.hpp>

#include <Eigen/LU>

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <functional>
#include <type_traits>
#include <string>
#include <vector>

namespace aerohopf::distributed {

class distributed_aerofoil {
 public:
  static constexpr int nv = 4;
  static constexpr int ns = models::aerofoil_system::n_structure;
  static constexpr int root = 0;

  /// The Jacobian in this rank's rows, bordered (file comment).
  struct jacobian_rows {
    block_sparse_matrix<double, nv> flow;  ///< A_ff: this rank's cells' rows, distributed_euler's numbering
    Eigen::MatrixXd flow_structure;        ///< A_fs: this rank's flow rows x 4
    Eigen::MatrixXd structure_flow;        ///< A_sf: 4 x this rank's flow values (its wall cells' columns)
    Eigen::Matrix4d structure;             ///< A_ss (the same on every rank)
    double ubar = NAN;                     ///< the Ubar of A_ss (set_ubar moves it)
  };

  /// `sys` (the same on every rank) must outlive this object; `part` assigns its flow grid's
  /// blocks to the ranks of `comm`. Collective.
  distributed_aerofoil(const models::aerofoil_system& sys, const block_partition& part, MPI_Comm comm)
      : sys_(sys), moved_(sys.flow()), d_(moved_, part, comm), comm_(comm) {}

  int rank() const { return d_.rank(); }
  distributed_euler<2>& flow() { return d_; }
  Eigen::Index flow_size() const { return d_.local_size(); }
  Eigen::Index local_size() const { return d_.local_size() + ns; }

  /// This rank's part of a whole state or vector (sys.size() values): its flow values, then the
  /// structure on the root and zeros elsewhere.
  vec<double> local_part(const vec<double>& global) const {
    require_size(global.size(), sys_.size(), "distributed_aerofoil::local_part", "global vector");
    vec<double> local(local_size());
    local.head(flow_size()) = d_.local_part(global.head(sys_.flow_size()));
    local.tail(ns) = d_.rank() == root ? vec<double>(global.tail(ns)) : vec<double>::Zero(ns);
    return local;
  }

  /// The whole vector from every rank's part, on every rank (collective; output and tests).
  vec<double> all_gather(const vec<double>& local) {
    check_local(local, "distributed_aerofoil::all_gather");
    vec<double> global(sys_.size());
    global.head(sys_.flow_size()) = d_.all_gather(local.head(flow_size()));
    global.tail(ns) = structure_of(local);
    return global;
  }

  /// The same for a complex vector (an eigenvector), by its real and imaginary parts.
  vec<std::complex<double>> local_part(const vec<std::complex<double>>& global) const {
    return join(local_part(vec<double>(global.real())), local_part(vec<double>(global.imag())));
  }
  vec<std::complex<double>> all_gather(const vec<std::complex<double>>& local) {
    return join(all_gather(vec<double>(local.real())), all_gather(vec<double>(local.imag())));
  }

  /// f(w, Ubar) in this rank's part (collective).
  vec<double> residual(const vec<double>& local, double ubar) {
    check_state(local, ubar, "distributed_aerofoil::residual");
    const Eigen::Vector4d ws = structure_of(local);
    const coupling::rigid_pose<double> q{ws[0], ws[1], ws[2], ws[3]};
    const auto m = sys_.moved_metrics<double>(q);
    vec<double> r(local_size());
    const vec<double>& full = d_.state_with_halo(local.head(flow_size()));
    residual_.resize(full.size());
    internal::collective(comm_, "distributed_aerofoil::residual", [&] {
      sys_.flow().residual_of_blocks<double>(m, full.data(), residual_.data(), d_.owned_blocks());
    });
    r.head(flow_size()) = d_.local_part(residual_);
    auto [cl, cm] = sys_.loads_of_blocks<double>(m, coupling::rigid_rotation<double>(ws[2]), full.data(),
                                                 &d_.owned_blocks());
    std::array<double, 2> loads{cl, cm};
    sum(loads.data(), 2);
    const auto rs = sys_.structure().rate<double>(ws, loads[0], loads[1], ubar);
    // element by element: GCC 12 with AVX-512 warns falsely on a fixed-to-dynamic copy
    for (int i = 0; i < ns; ++i) r[flow_size() + i] = d_.rank() == root ? rs[i] : 0.0;
    return r;
  }

  /// The exact (kind exact) or modified-order Jacobian in this rank's rows at (w, Ubar)
  /// (collective). The border is the same for both kinds.
  void jacobian(const vec<double>& local, double ubar, flow::jacobian_kind kind, jacobian_rows& j) {
    check_state(local, ubar, "distributed_aerofoil::jacobian");
    const Eigen::Vector4d ws = structure_of(local);
    const vec<double> wf = local.head(flow_size());
    // A_ff on the grid moved to ws, as the serial assembly (the rest model when ws = 0)
    if (ws.isZero(0.0)) {
      if (moved_is_moved_) {
        moved_ = sys_.flow();  // the rest model itself (its metrics as constructed); d_ keeps its address
        moved_is_moved_ = false;
      }
    } else {
      flow::multiblock_points<double, 2> pts, spd;
      coupling::rigid_grid_motion<double>(sys_.flow().grid().points,
                                          coupling::rigid_pose<double>{ws[0], ws[1], ws[2], ws[3]},
                                          {sys_.structure().parameters().x_ea, sys_.structure().parameters().y_ea}, pts,
                                          &spd);
      moved_.set_grid_motion(pts, &spd);
      moved_is_moved_ = true;
    }
    d_.jacobian(wf, kind, j.flow);

    // [A_fs; A_ss]: one jet pass (direction k = structural unknown k) of this rank's residual
    // and of its part of the loads
    using sjet = jet<double, ns>;
    const vec<double>& full = d_.state_with_halo(wf);
    vec<sjet> wj = full.cast<sjet>();
    coupling::rigid_pose<sjet> qj{sjet::variable(ws[0], 0), sjet::variable(ws[1], 1), sjet::variable(ws[2], 2),
                                  sjet::variable(ws[3], 3)};
    const auto mj = sys_.moved_metrics<sjet>(qj);
    vec<sjet> rj(full.size());
    const auto& model = sys_.flow();
    internal::collective(comm_, "distributed_aerofoil::jacobian", [&] {
      model.residual_of_blocks<sjet>(mj, wj.data(), rj.data(), d_.owned_blocks());
    });
    const auto& num = d_.numbering();
    j.flow_structure.resize(flow_size(), ns);
    for (const auto& [first, last] : d_.plan().owned)
      for (std::size_t c = first; c < last; ++c)
        for (int v = 0; v < nv; ++v)
          for (int k = 0; k < ns; ++k)
            j.flow_structure(num.local[c] * nv + v, k) = rj[static_cast<Eigen::Index>(c * nv + v)].derivative(k);
    const auto [clj, cmj] = sys_.loads_of_blocks<sjet>(mj, coupling::rigid_rotation<sjet>(qj.alpha), wj.data(),
                                                       &d_.owned_blocks());
    std::array<double, 2 * (ns + 1)> parts{};
    parts[0] = clj.value();
    parts[ns + 1] = cmj.value();
    for (int k = 0; k < ns; ++k) {
      parts[1 + k] = clj.derivative(k);
      parts[ns + 2 + k] = cmj.derivative(k);
    }
    sum(parts.data(), static_cast<int>(parts.size()));
    sjet cl(parts[0]), cm(parts[ns + 1]);
    for (int k = 0; k < ns; ++k) {
      cl.derivative(k) = parts[1 + k];
      cm.derivative(k) = parts[ns + 2 + k];
    }
    Eigen::Matrix<sjet, 4, 1> wsj;
    for (int k = 0; k < ns; ++k) wsj[k] = sjet::variable(ws[k], k);
    const auto rs = sys_.structure().rate<sjet>(wsj, cl, cm, sjet(ubar));
    for (int i = 0; i < ns; ++i)
      for (int k = 0; k < ns; ++k) j.structure(i, k) = rs[i].derivative(k);
    j.ubar = ubar;

    // A_sf: this rank's wall cells
    j.structure_flow.setZero(ns, flow_size());
    const auto m = sys_.moved_metrics<double>(coupling::rigid_pose<double>{ws[0], ws[1], ws[2], ws[3]});
    sys_.structure_flow_entries(m, coupling::rigid_rotation<double>(ws[2]), full.data(), &d_.owned_blocks(),
                                [&](int i, Eigen::Index cell, int v, double x) {
                                  j.structure_flow(i, num.local[static_cast<std::size_t>(cell)] * nv + v) += x;
                                });
  }

  /// The exact and the modified-order Jacobian rows at (w, Ubar) together: the border (one jet
  /// pass) and the moved grid computed once, as aerofoil_system::bordered_jacobians (collective).
  void jacobians(const vec<double>& local, double ubar, jacobian_rows& exact, jacobian_rows& preconditioning) {
    jacobian(local, ubar, flow::jacobian_kind::exact, exact);
    // moved_ is at w's pose now
    d_.jacobian(local.head(flow_size()), flow::jacobian_kind::modified_order, preconditioning.flow);
    preconditioning.flow_structure = exact.flow_structure;
    preconditioning.structure_flow = exact.structure_flow;
    preconditioning.structure = exact.structure;
    preconditioning.ubar = exact.ubar;
  }

  /// Moves Jacobian rows to another Ubar without re-assembly: Ubar enters only the stiffness,
  /// so only A_ss changes, by the in-vacuo part -M^{-1} (K(Ubar) - K(j.ubar)).
  void set_ubar(jacobian_rows& j, double ubar) const {
    require(std::isfinite(ubar) && ubar != 0 && std::isfinite(j.ubar), "distributed_aerofoil::set_ubar: Ubar ", ubar,
            " (rows assembled at ", j.ubar, ") must be finite and non-zero");
    if (ubar == j.ubar) return;
    const auto& st = sys_.structure();
    j.structure += st.in_vacuo_matrix(ubar) - st.in_vacuo_matrix(j.ubar);
    j.ubar = ubar;
  }

  /// dA/dUbar: zero but for the structural block, -M^{-1} dK/dUbar (4 x 4, every rank).
  Eigen::Matrix4d structure_d_ubar(double ubar) const {
    const auto& st = sys_.structure();
    return -st.mass_inverse() * st.stiffness_d_ubar(ubar);
  }

  /// df/dUbar in this rank's part: the structural rows -M^{-1} dK/dUbar w_s on the root, zeros
  /// elsewhere (collective: the root's structure broadcast).
  vec<double> residual_d_ubar(const vec<double>& local, double ubar) const {
    const vec<double> ws = structure_of(local);
    const Eigen::MatrixXd b = structure_d_ubar(ubar);
    vec<double> r = vec<double>::Zero(local_size());
    if (d_.rank() == root) r.tail(ns) = b * ws;
    return r;
  }

  /// y = J x in this rank's part, real or complex vectors (collective: the flow's halo, the
  /// structure's broadcast and the structural rows' sum).
  template <class S = double>
  vec<S> multiply(const jacobian_rows& j, const vec<S>& x) {
    static_assert(std::is_same_v<S, double> || std::is_same_v<S, std::complex<double>>,
                  "distributed_aerofoil::multiply: double or std::complex<double> vectors");
    check_local(x, "distributed_aerofoil::multiply");
    // dynamic-size operands throughout: GCC 12 with AVX-512 warns falsely (-Warray-bounds) on
    // products of a fixed 4-vector with dynamic matrices
    const vec<S> xs = structure_of(x);
    const vec<S> xf = x.head(flow_size());
    vec<S> y(local_size());
    y.head(flow_size()) = d_.multiply(j.flow, xf);
    y.head(flow_size()).noalias() += j.flow_structure * xs;
    vec<S> part = j.structure_flow * xf;
    sum(part.data(), ns);
    if (d_.rank() == root) {
      const Eigen::MatrixXd ss = j.structure;
      part.noalias() += ss * xs;
      y.tail(ns) = part;
    } else {
      y.tail(ns).setZero();
    }
    return y;
  }

  /// The root's structural values of a local vector, on every rank (collective).
  template <class S>
  vec<S> structure_of(const vec<S>& local) const {
    vec<S> s = local.tail(ns);
    internal::check_mpi(MPI_Bcast(s.data(), ns * static_cast<int>(sizeof(S) / sizeof(double)), MPI_DOUBLE, root, comm_),
                        "MPI_Bcast");
    return s;
  }

  /// Throws input_error on every rank unless every rank's `local` has local_size() finite
  /// entries and ubar is finite (collective).
  void check_state(const vec<double>& local, double ubar, const char* who) const {
    internal::collective(comm_, who, [&] {
      require(std::isfinite(ubar), who, ": Ubar ", ubar, " is not finite");
      require_size(local.size(), local_size(), who, "state (this rank's flow values and 4 structural)");
      require_finite(local, who, "state (this rank's part)");
    });
  }

  /// In-place sum over the ranks (collective).
  void sum(double* p, int n) const { internal::sum_over_ranks(comm_, p, n); }
  void sum(std::complex<double>* p, int n) const { internal::sum_over_ranks(comm_, p, n); }
  MPI_Comm communicator() const { return comm_; }

 private:
  template <class S>
  void check_local(const vec<S>& local, const char* who) const {
    internal::collective(comm_, who, [&] {
      require_size(local.size(), local_size(), who, "local vector (this rank's flow values and 4 structural)");
    });
  }

  static vec<std::complex<double>> join(const vec<double>& re, const vec<double>& im) {
    vec<std::complex<double>> z(re.size());
    z.real() = re;
    z.imag() = im;
    return z;
  }

  const models::aerofoil_system& sys_;
  flow::euler_model<2> moved_;  // the flow model on the grid moved to the last Jacobian's pose
  distributed_euler<2> d_;      // evaluates on moved_ (its metrics: the rest ones or moved)
  MPI_Comm comm_;
  vec<double> residual_;  // whole-grid residual buffer (this rank's cells written)
  bool moved_is_moved_ = false;
};

/// J - sigma I of a distributed_aerofoil's Jacobian rows as a distributed linear operator on
/// complex local vectors (inner products summed over the ranks: the structure counts once).
/// `d` and `j` must outlive it.
class distributed_aerofoil_operator {
 public:
  distributed_aerofoil_operator(distributed_aerofoil& d, const distributed_aerofoil::jacobian_rows& j,
                                std::complex<double> sigma)
      : d_(&d), j_(&j), sigma_(sigma) {}
  Eigen::Index rows() const { return d_->local_size(); }
  Eigen::Index cols() const { return d_->local_size(); }
  void apply(const vec<std::complex<double>>& x, vec<std::complex<double>>& y) const {
    y = d_->multiply(*j_, x);
    if (d_->rank() == distributed_aerofoil::root) y -= sigma_ * x;
    else y.head(d_->flow_size()) -= sigma_ * x.head(d_->flow_size());
  }
  void global_sum(double* p, int n) const { d_->sum(p, n); }
  void global_sum(std::complex<double>* p, int n) const { d_->sum(p, n); }

 private:
  distributed_aerofoil* d_;
  const distributed_aerofoil::jacobian_rows* j_;
  std::complex<double> sigma_;
};

/// J on real vectors of the ranks (the static equilibrium's and the full Hopf flow update's
/// operator), J the Jacobian rows j.
class real_aerofoil_operator {
 public:
  real_aerofoil_operator(distributed_aerofoil& d, const distributed_aerofoil::jacobian_rows& j) : d_(&d), j_(&j) {}
  Eigen::Index rows() const { return d_->local_size(); }
  Eigen::Index cols() const { return d_->local_size(); }
  void apply(const vec<double>& x, vec<double>& y) const { y = d_->multiply(*j_, x); }
  void global_sum(double* p, int n) const { d_->sum(p, n); }

 private:
  distributed_aerofoil* d_;
  const distributed_aerofoil::jacobian_rows* j_;
};

/// Block-Jacobi preconditioner of P - sigma I for a distributed_aerofoil (P: the Jacobian rows
/// of the preconditioning matrix, the modified-order one): complex BILU(k) M of each rank's own
/// part of A_ff - sigma I, and the border eliminated exactly around it. With Y = M^{-1} A_fs
/// (this rank's rows) and the Schur complement S = (A_ss - sigma I) - sum over ranks A_sf Y
/// (4 x 4, the same LU on every rank), z = P^{-1} r is y_f = M^{-1} r_f, z_s = S^{-1} (r_s -
/// sum A_sf y_f), z_f = y_f - Y z_s: one BILU solve and two small reductions per apply.
/// S = std::complex<double> (any shift; distributed_aerofoil_preconditioner) or double (sigma
/// = 0: the real solves with the Jacobian itself, e.g. the flow update of the full Hopf system).
template <class S>
class basic_distributed_aerofoil_preconditioner {
 public:
  using C = S;
  explicit basic_distributed_aerofoil_preconditioner(block_ilu_options o = {}) : ilu_(std::move(o)) {}

  /// Collective; singular_matrix_error (every rank) if a BILU pivot or the Schur complement is
  /// singular.
  void compute(distributed_aerofoil& d, const distributed_aerofoil::jacobian_rows& p, C sigma) {
    d_ = &d;
    internal::collective(d.communicator(), "distributed_aerofoil_preconditioner", [&] {
      if constexpr (std::is_same_v<S, double>) {
        require(sigma == 0.0, "distributed_aerofoil_preconditioner: a real preconditioner has shift 0 (got ", sigma, ")");
        ilu_.compute(owned_part(p.flow));
      } else {
        ilu_.compute(shifted(owned_part(p.flow), sigma));
      }
      y_.resize(d.flow_size(), distributed_aerofoil::ns);
      vec<C> col(d.flow_size()), out(d.flow_size());
      for (int k = 0; k < distributed_aerofoil::ns; ++k) {
        col = p.flow_structure.col(k).cast<C>();
        ilu_.apply(col, out);
        y_.col(k) = out;
      }
      sf_ = p.structure_flow.cast<C>();
    });
    mat t = sf_ * y_;
    d.sum(t.data(), 16);
    Eigen::Matrix<C, 4, 4> schur = p.structure.cast<C>();
    schur -= t;
    schur.diagonal().array() -= sigma;
    lu_.compute(schur);
    if (!(std::abs(lu_.determinant()) > 0) || !std::isfinite(std::abs(lu_.determinant())))
      throw singular_matrix_error("distributed_aerofoil_preconditioner: the 4 x 4 Schur complement is singular");
  }

  Eigen::Index rows() const { return d_ ? d_->local_size() : 0; }

  void apply(const vec<C>& r, vec<C>& z) const {
    const Eigen::Index nf = d_->flow_size();
    z.resize(r.size());
    vec<C> yf(nf);
    ilu_.apply(vec<C>(r.head(nf)), yf);
    vec<C> t = sf_ * yf;
    d_->sum(t.data(), distributed_aerofoil::ns);
    const vec<C> rs = d_->structure_of(r);
    const vec<C> rhs = rs - t;
    const vec<C> zs = lu_.solve(rhs);
    z.head(nf) = yf - y_ * zs;
    if (d_->rank() == distributed_aerofoil::root) z.tail(distributed_aerofoil::ns) = zs;
    else z.tail(distributed_aerofoil::ns).setZero();
  }

 private:
  distributed_aerofoil* d_ = nullptr;
  block_ilu<C, distributed_aerofoil::nv> ilu_;
  using mat = Eigen::Matrix<C, Eigen::Dynamic, Eigen::Dynamic>;
  mat y_, sf_;
  Eigen::PartialPivLU<Eigen::Matrix<C, 4, 4>> lu_;
};

using distributed_aerofoil_preconditioner = basic_distributed_aerofoil_preconditioner<std::complex<double>>;

/// The eigenpair of the aeroelastic Jacobian J (rows `a`) nearest `shift` on the ranks: the one
/// inverse-power iteration (bifurcation/inverse_power.hpp) with sums over the ranks, each solve
/// complex GMRES on J - sigma I preconditioned by distributed_aerofoil_preconditioner of `pre`
/// (the modified-order rows; nullptr: `a`). `start`: this rank's part (nullptr: the part of the
/// serial default start). The vector of the result is this rank's part (structure on the
/// root). Collective; errors as distributed::inverse_power (mpi_eigen.hpp).
inline eigen_pair inverse_power(distributed_aerofoil& d, const distributed_aerofoil::jacobian_rows& a,
                                const distributed_aerofoil::jacobian_rows* pre, std::complex<double> shift,
                                const distributed_inverse_power_options& opt = {},
                                const vec<std::complex<double>>* start = nullptr) {
  using C = std::complex<double>;
  constexpr int nv = distributed_aerofoil::nv;
  const char* who = "distributed inverse power (aeroelastic)";
  const MPI_Comm comm = d.communicator();
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
  Eigen::Vector4d border = a.structure_flow.cwiseAbs().rowwise().sum();
  d.sum(border.data(), 4);
  a_norm = internal::max_over_ranks(comm, a_norm);
  a_norm = std::max(a_norm, (border + a.structure.cwiseAbs().rowwise().sum()).maxCoeff());

  block_ilu_options io;
  io.fill_level = opt.fill_level;
  io.context = "distributed inverse power (aeroelastic): block-Jacobi BILU of P - sigma I";
  distributed_aerofoil_preconditioner pc(io);
  pc.compute(d, pre ? *pre : a, shift);
  const distributed_aerofoil_operator op(d, a, shift);
  return internal::run_inverse_power(
      comm, start, d.flow().model().size() + distributed_aerofoil::ns,
      [&d](const vec<double>& g) { return d.local_part(g); }, [&](const vec<C>& v) { return d.multiply(a, v); }, op,
      pc, shift, a_norm, opt, who);
}

struct distributed_equilibrium_options {
  int fill_level = 2;           ///< k of the real block-Jacobi BILU(k) of the modified-order rows
  double tolerance = 1e-10;     ///< ||f(w, Ubar)||_2 over the ranks
  int max_iterations = 25;      ///< full Newton steps
  double eta_max = 1e-2;        ///< GMRES forcing eta_k = min(eta_max, max(||f_k||, 0.1 tolerance / ||f_k||))
  krylov_options krylov = [] {
    krylov_options o;
    o.max_iterations = 2000;
    o.restart = 80;
    o.record_history = false;
    return o;
  }();
};

struct distributed_equilibrium_result {
  vec<double> w;            ///< this rank's part of the last iterate (the equilibrium if converged)
  bool converged = false;
  int iterations = 0;
  long linear_iterations = 0;
  double residual = NAN;    ///< ||f|| of w
  std::string reason;       ///< why not converged (the same text on every rank)
};

/// The static aeroelastic equilibrium f(w, Ubar) = 0 on the ranks (as solve_equilibrium_krylov
/// for the serial system with full steps): Newton from w0 (this rank's part), each step by GMRES
/// on the exact Jacobian rows preconditioned by the real block-Jacobi BILU(k) of the
/// modified-order rows with the structure eliminated exactly, the inexact forcing of the
/// options. Converged when ||f||_2 <= tolerance; a non-finite residual, a GMRES failure, a
/// breakdown or the iteration limit is a result with converged = false and the reason, the
/// same on every rank (the last finite iterate in w). Collective.
inline distributed_equilibrium_result solve_equilibrium(distributed_aerofoil& d, vec<double> w0, double ubar,
                                                        const distributed_equilibrium_options& opt = {}) {
  const char* who = "distributed solve_equilibrium (aeroelastic)";
  internal::collective(d.communicator(), who, [&] {
    validate_krylov_options(opt.krylov, who);
    require(opt.fill_level >= 0 && opt.fill_level <= 8, who, ": fill_level must lie in [0, 8] (got ", opt.fill_level,
            ")");
    require(opt.tolerance > 0 && std::isfinite(opt.tolerance), who, ": tolerance must be finite and > 0");
    require(opt.max_iterations >= 1, who, ": max_iterations must be >= 1");
    require(opt.eta_max > 0 && opt.eta_max < 1, who, ": eta_max must lie in (0, 1)");
  });
  d.check_state(w0, ubar, who);
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
  basic_distributed_aerofoil_preconditioner<double> pc(io);
  distributed_aerofoil::jacobian_rows a, l;
  vec<double> f = d.residual(r.w, ubar);
  r.residual = norm(f);
  for (int k = 0;; ++k) {
    if (!std::isfinite(r.residual)) {
      r.reason = aerohopf::internal::concat(who, ": the residual is not finite at iterate ", k, " (Ubar = ", ubar, ")");
      return r;
    }
    if (r.residual <= opt.tolerance) {
      r.converged = true;
      return r;
    }
    if (k >= opt.max_iterations) {
      r.reason = aerohopf::internal::concat(who, ": no convergence in ", opt.max_iterations,
                                            " Newton iterations (||f|| = ", r.residual, ", Ubar = ", ubar, ")");
      return r;
    }
    try {
      d.jacobians(r.w, ubar, a, l);
      pc.compute(d, l, 0.0);
      const real_aerofoil_operator op(d, a);
      krylov_options ko = opt.krylov;
      ko.relative_tolerance = std::min(opt.eta_max, std::max(r.residual, 0.1 * opt.tolerance / r.residual));
      ko.throw_on_failure = true;
      ko.context = aerohopf::internal::concat(who, ": GMRES, Newton step ", k + 1);
      vec<double> dw = vec<double>::Zero(r.w.size());
      r.linear_iterations += gmres<double>(op, pc, vec<double>(-f), dw, ko).iterations;
      vec<double> w = r.w + dw;
      const vec<double> fw = d.residual(w, ubar);
      const double fn = norm(fw);
      r.iterations = k + 1;
      if (!std::isfinite(fn)) {
        r.reason = aerohopf::internal::concat(who, ": the residual is not finite after Newton step ", k + 1,
                                              " (Ubar = ", ubar, ")");
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

/// The root locus (bifurcation/root_locus.hpp, the same loop) on the ranks: equilibrium(Ubar)
/// returns this rank's part of w0(Ubar) (e.g. the distributed steady solve's, or local_part of
/// a known state); each point's eigenpair by inverse_power above, from the previous point's
/// eigenvalue (shift) and eigenvector part (start). Collective; errors as root_locus.
inline std::vector<root_locus_point> root_locus(distributed_aerofoil& d,
                                                const std::function<vec<double>(double)>& equilibrium,
                                                const std::vector<double>& ubars, std::complex<double> shift0,
                                                const distributed_inverse_power_options& opt = {}) {
  distributed_aerofoil::jacobian_rows a, p;
  return aerohopf::internal::root_locus_loop(
      equilibrium, [&d](const vec<double>& w, double ubar) { d.check_state(w, ubar, "distributed root_locus"); },
      [&](double ubar, const vec<double>& w, std::complex<double> shift, const vec<std::complex<double>>* start) {
        d.jacobians(w, ubar, a, p);
        return inverse_power(d, a, &p, shift, opt, start);
      },
      ubars, shift0, opt.power, "distributed root_locus");
}

}  // namespace aerohopf::distributed
