// libFuzzer harness of the modal-data readers: the documented modal CSV
// (structure::read_modal_csv), NASTRAN GRID bulk data (io::read_nastran_grid) and NASTRAN
// punch eigenvectors over four fixed grid points (io::read_nastran_modes). The first byte of the
// input picks the reader (its value mod 3: '0' CSV, '1' GRID, '2' punch); the rest is the file.
//
// Contract checked on every input:
//  - the reader either returns or throws aerohopf::input_error whose message names the file;
//    any other exception escaping, a crash or a sanitizer report is a bug;
//  - modal data it returns passes modal_data::validate (finite, consistent sizes, unique ids,
//    positive generalised masses) and an accepted CSV survives a write/read round trip (shapes
//    and points exactly, frequencies to 4 ulp through Hz).
// Built with -fsanitize=fuzzer for libFuzzer, or with replay_main.cpp as a plain regression
// test (see CMakeLists.txt).
#include <aerohopf/io/nastran.hpp>
#include <aerohopf/structure/modal_data.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <limits>
#include <sstream>
#include <string>
#include <string_view>

extern "C" {
std::size_t aerohopf_fuzz_accepted = 0;
}

namespace {

[[noreturn]] void violated(const char* what, const std::string& detail) {
  std::fprintf(stderr, "fuzz_modal_data: contract violated: %s: %s\n", what, detail.c_str());
  std::abort();
}

template <class F>
bool guarded(const std::string& name, F&& read) {
  try {
    read();
    return true;
  } catch (const aerohopf::error& e) {
    if (!dynamic_cast<const aerohopf::input_error*>(&e)) violated("not an input_error", e.what());
    if (std::string_view(e.what()).find(name) == std::string_view::npos) violated("message without the file name", e.what());
    return false;
  }
}

void check_valid(const aerohopf::structure::modal_data& d, const std::string& name) {
  try {
    d.validate(name);
  } catch (const aerohopf::error& e) {
    violated("accepted data fails validate", e.what());
  }
}

void csv(std::string_view text) {
  namespace st = aerohopf::structure;
  const std::string name = "fuzz_modes.csv";
  st::modal_data d;
  std::istringstream in{std::string(text)};
  if (!guarded(name, [&] { d = st::read_modal_csv(in, name); })) return;
  check_valid(d, name);
  ++aerohopf_fuzz_accepted;
  std::ostringstream out;
  st::write_modal_csv(out, d, name);
  std::istringstream back(out.str());
  st::modal_data r;
  try {
    r = st::read_modal_csv(back, name);
  } catch (const aerohopf::error& e) {
    violated("round trip of accepted modal data refused", e.what());
  }
  if (r.point_ids != d.point_ids || r.points != d.points || r.shapes != d.shapes ||
      r.generalised_mass != d.generalised_mass)
    violated("round trip", "points, shapes or generalised masses changed");
  for (Eigen::Index k = 0; k < d.modes(); ++k)
    if (!(std::abs(r.omega[k] - d.omega[k]) <= 4 * std::numeric_limits<double>::epsilon() * d.omega[k]))
      violated("round trip", "frequency of mode " + std::to_string(k + 1) + " changed");
}

void grid(std::string_view text) {
  const std::string name = "fuzz_grid.bdf";
  std::istringstream in{std::string(text)};
  std::vector<aerohopf::io::nastran_grid_point> pts;
  if (!guarded(name, [&] { pts = aerohopf::io::read_nastran_grid(in, name); })) return;
  if (pts.empty()) violated("accepted", "no points");
  for (const auto& p : pts)
    if (!p.x.allFinite()) violated("accepted", "a non-finite coordinate of GRID " + std::to_string(p.id));
  ++aerohopf_fuzz_accepted;
}

void punch(std::string_view text) {
  const std::string name = "fuzz_modes.pch";
  std::vector<aerohopf::io::nastran_grid_point> pts(4);
  for (int i = 0; i < 4; ++i) {
    pts[static_cast<std::size_t>(i)].id = i + 1;
    pts[static_cast<std::size_t>(i)].x = Eigen::Vector3d(i, 0.5 * i, 0);
  }
  std::istringstream in{std::string(text)};
  aerohopf::structure::modal_data d;
  if (!guarded(name, [&] { d = aerohopf::io::read_nastran_modes(in, name, pts, "fuzz_grid.bdf"); })) return;
  check_valid(d, name);
  ++aerohopf_fuzz_accepted;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size == 0) return 0;
  const std::string_view text(reinterpret_cast<const char*>(data) + 1, size - 1);
  switch (data[0] % 3) {
    case 0: csv(text); break;
    case 1: grid(text); break;
    default: punch(text); break;
  }
  return 0;
}
