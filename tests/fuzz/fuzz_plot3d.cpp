// libFuzzer harness of the Plot3D reader (io::read_plot3d_bytes), in 2D and in 3D.
//
// Contract checked on every input:
//  - the reader either returns a grid or throws aerohopf::input_error whose message names the
//    file; any other exception escaping, a crash or a sanitizer report is a bug;
//  - a grid it returns is consistent (x.size() == points of every block, every coordinate
//    finite) and survives exact round trips through write_plot3d in binary and in ASCII.
// Built with -fsanitize=fuzzer for libFuzzer, or with replay_main.cpp as a plain regression
// test (see CMakeLists.txt).
#include <aerohopf/io/plot3d.hpp>

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <sstream>
#include <string>
#include <string_view>

/// Inputs accepted so far (in 2D or 3D); replay_main.cpp checks that every seed is.
extern "C" {
std::size_t aerohopf_fuzz_accepted = 0;
}

namespace {

[[noreturn]] void violated(const char* what, const std::string& detail) {
  std::fprintf(stderr, "fuzz_plot3d: contract violated: %s: %s\n", what, detail.c_str());
  std::abort();
}

template <int Dim>
void same_grid(const aerohopf::flow::multiblock_points<double, Dim>& a,
               const aerohopf::flow::multiblock_points<double, Dim>& b, const char* how) {
  if (a.blocks.size() != b.blocks.size()) violated(how, "block count changed");
  for (std::size_t k = 0; k < a.blocks.size(); ++k)
    if (a.blocks[k].points != b.blocks[k].points || a.blocks[k].x != b.blocks[k].x)
      violated(how, "block " + std::to_string(k) + " changed");
}

template <int Dim>
void check(std::string_view bytes) {
  namespace io = aerohopf::io;
  const std::string name = "fuzz" + std::to_string(Dim) + "d.xyz";
  aerohopf::flow::multiblock_points<double, Dim> g;
  try {
    g = io::read_plot3d_bytes<Dim>(bytes, name);
  } catch (const aerohopf::error& e) {
    if (!dynamic_cast<const aerohopf::input_error*>(&e)) violated("not an input_error", e.what());
    if (std::string_view(e.what()).find(name) == std::string_view::npos) violated("message without the file name", e.what());
    return;
  }
  if (g.blocks.empty()) violated("accepted", "a grid without blocks");
  for (std::size_t b = 0; b < g.blocks.size(); ++b) {
    const auto& blk = g.blocks[b];
    if (blk.x.size() != blk.n_points()) violated("accepted", "block " + std::to_string(b) + " of inconsistent size");
    for (const auto& p : blk.x)
      for (double v : p)
        if (!std::isfinite(v)) violated("accepted", "a non-finite coordinate in block " + std::to_string(b));
  }
  ++aerohopf_fuzz_accepted;
  for (auto fmt : {io::plot3d_format::binary, io::plot3d_format::ascii}) {
    std::ostringstream out;
    io::write_plot3d<Dim>(out, g, fmt);
    const std::string written = out.str();
    try {
      same_grid<Dim>(g, io::read_plot3d_bytes<Dim>(written, name), "round trip");
    } catch (const aerohopf::error& e) {
      violated("round trip of an accepted grid refused", e.what());
    }
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view bytes(reinterpret_cast<const char*>(data), size);
  check<2>(bytes);
  check<3>(bytes);
  return 0;
}
