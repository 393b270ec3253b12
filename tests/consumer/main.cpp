// Downstream use of the installed package: the first Hopf point of the tubular reactor.
#include <aerohopf/bifurcation.hpp>
#include <aerohopf/models/tubular_reactor.hpp>

#include <cmath>
#include <iostream>

int main() {
  using namespace aerohopf;
  const tubular_reactor r(16);
  vec<double> w = r.rest_state();
  for (int k = 1; k <= 8; ++k) w = newton(r, w, 0.16 * k / 8).x;
  const hopf_result h = solve_hopf(r, hopf_start(r, w, 0.16, 0.4));
  std::cout.precision(12);
  std::cout << "consumer: Hopf point mu* = " << h.point.mu << ", omega = " << h.point.omega << " in "
            << h.report.iterations << " Newton iterations\n";
  return (h.report.converged && std::abs(h.point.mu - 0.165) < 0.01) ? 0 : 1;
}
