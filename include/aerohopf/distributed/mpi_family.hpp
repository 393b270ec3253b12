#pragma once
// What a distributed flutter family (mpi_aerofoil_family.hpp, mpi_wing_family.hpp) takes from
// its serial one unchanged: the systems, the levels and their transfers, the mode test's
// structural part, the parameter's stiffness factor and the driver's options, and the
// communicator. The derived family adds the solves on the ranks (equilibrium, hopf_start,
// solve_hopf). Tested through both families (tests/distributed/test_mpi_*_family.cpp).
#include <mpi.h>

#include <aerohopf/bifurcation/flutter_boundary.hpp>
#include <aerohopf/distributed/mpi_euler.hpp>

#include <complex>
#include <optional>
#include <string>
#include <utility>

namespace aerohopf::distributed {

template <class Serial>
class distributed_family_base {
 public:
  using system_type = typename Serial::system_type;
  static constexpr int block_size = Serial::block_size;

  system_type system(int stride, double mach) const { return serial_.system(stride, mach); }
  static std::string level_name(int stride) { return Serial::level_name(stride); }
  bool fixed_equilibrium() const { return serial_.fixed_equilibrium(); }
  flutter_boundary_options boundary_options() const { return serial_.boundary_options(); }
  bool refines(int coarse_stride, int fine_stride) const { return serial_.refines(coarse_stride, fine_stride); }
  std::optional<int> coarser_level(int stride) const { return serial_.coarser_level(stride); }
  vec<std::complex<double>> prolong(const system_type& fine, const system_type& coarse,
                                    const vec<std::complex<double>>& p) const {
    return serial_.prolong(fine, coarse, p);
  }
  vec<std::complex<double>> structure_part(const vec<std::complex<double>>& p) const {
    return serial_.structure_part(p);
  }
  static double stiffness_factor(double mu) { return Serial::stiffness_factor(mu); }
  static double parameter_of_factor(double q) { return Serial::parameter_of_factor(q); }

  const Serial& serial() const { return serial_; }
  MPI_Comm communicator() const { return comm_; }
  int ranks() const { return ranks_; }
  int rank() const { return rank_; }

 protected:
  /// Collective: every rank must construct it.
  distributed_family_base(Serial serial, MPI_Comm comm) : serial_(std::move(serial)), comm_(comm) {
    ranks_ = internal::comm_size(comm_);
    rank_ = internal::comm_rank(comm_);
  }

  Serial serial_;
  MPI_Comm comm_;
  int ranks_ = 1, rank_ = 0;
};

}  // namespace aerohopf::distributed
