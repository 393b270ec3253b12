#pragma once
// QD's dd_real (about 32 digits) and qd_real (about 64 digits) as aerohopf and Eigen scalars.
//
// The original method evaluated the residual in double-double and quad-double so that 2nd and
// 3rd derivative products by finite differences keep their accuracy over a wide range of step
// sizes. For that the QD types must flow through Eigen (vectors, dense LU) and through our
// templated residuals:
//  * Eigen::NumTraits gives epsilon() and dummy_precision() IN THE QD TYPE (QD's own
//    numeric_limits::epsilon() returns a double, and without dummy_precision isApprox()
//    degenerates into exact equality);
//  * sqrt, exp, log, pow, abs, isfinite are QD's own free functions in the global namespace,
//    found by argument-dependent lookup from generic code that writes `using std::sqrt;`.
// Dense factorisations: PartialPivLU and HouseholderQR work; Eigen's FullPivLU does not compile
// (it forms RealScalar(Index), ambiguous between QD's int and double constructors).
// QD arithmetic relies on exactly rounded IEEE operations: never compile it with -ffast-math,
// and keep FMA contraction off (the aerohopf target adds -ffp-contract=off).
#include <Eigen/Core>
#include <qd/dd_real.h>
#include <qd/qd_real.h>

#include "traits.hpp"

namespace aerohopf {

template <>
struct scalar_traits<dd_real> {
  static constexpr std::string_view name() { return "dd"; }
  static constexpr double epsilon() { return 0x1p-104; }  // exact power of two (QD's _eps is a rounded decimal)
  static constexpr int digits10 = 31;
  static double to_double(const dd_real& x) { return x.x[0]; }
};

template <>
struct scalar_traits<qd_real> {
  static constexpr std::string_view name() { return "qd"; }
  static constexpr double epsilon() { return 0x1p-209; }
  static constexpr int digits10 = 62;
  static double to_double(const qd_real& x) { return x.x[0]; }
};

}  // namespace aerohopf

namespace Eigen {

namespace internal {
template <class QD>
struct qd_num_traits_base {
  using Real = QD;
  using NonInteger = QD;
  using Literal = QD;
  using Nested = QD;
  enum {
    IsComplex = 0,
    IsInteger = 0,
    IsSigned = 1,
    RequireInitialization = 1,
  };
  static inline QD epsilon() { return QD(aerohopf::scalar_traits<QD>::epsilon()); }
  static inline QD highest() { return QD(std::numeric_limits<double>::max()); }
  static inline QD lowest() { return -highest(); }
  static inline QD infinity() { return QD(std::numeric_limits<double>::infinity()); }
  static inline QD quiet_NaN() { return QD(std::numeric_limits<double>::quiet_NaN()); }
  static inline int digits10() { return aerohopf::scalar_traits<QD>::digits10; }
};
}  // namespace internal

template <>
struct NumTraits<dd_real> : internal::qd_num_traits_base<dd_real> {
  enum { ReadCost = 2, AddCost = 20, MulCost = 25 };
  static inline dd_real dummy_precision() { return dd_real(1e-28); }
  static inline int digits() { return 104; }
};

template <>
struct NumTraits<qd_real> : internal::qd_num_traits_base<qd_real> {
  enum { ReadCost = 4, AddCost = 80, MulCost = 120 };
  static inline qd_real dummy_precision() { return qd_real(1e-58); }
  static inline int digits() { return 209; }
};

// Mixed double * dd/qd expressions (e.g. scaling a dd vector by a double step).
template <class BinaryOp>
struct ScalarBinaryOpTraits<dd_real, double, BinaryOp> { using ReturnType = dd_real; };
template <class BinaryOp>
struct ScalarBinaryOpTraits<double, dd_real, BinaryOp> { using ReturnType = dd_real; };
template <class BinaryOp>
struct ScalarBinaryOpTraits<qd_real, double, BinaryOp> { using ReturnType = qd_real; };
template <class BinaryOp>
struct ScalarBinaryOpTraits<double, qd_real, BinaryOp> { using ReturnType = qd_real; };

}  // namespace Eigen
