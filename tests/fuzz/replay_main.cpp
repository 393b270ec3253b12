// Replay driver of a libFuzzer harness for builds without libFuzzer: runs every file of the
// seed corpus directories given on the command line, and a deterministic set of mutations of
// each (every truncation, bit flips, inserted bytes, overwritten integers, replaced text
// tokens, appended data), through LLVMFuzzerTestOneInput. The harness aborts on a contract
// violation; an exception escaping it ends the program (std::terminate). Fails if no seed is
// found, so a wrong path cannot pass, and if a seed is not accepted by the reader (the harness
// counts accepted inputs in aerohopf_fuzz_accepted), except seeds named reject-* or crash-*
// (inputs that must be refused, such as fixed crashes).
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <string>
#include <vector>

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size);
extern "C" std::size_t aerohopf_fuzz_accepted;

namespace {

std::size_t runs = 0;

void run(const std::string& s) {
  LLVMFuzzerTestOneInput(reinterpret_cast<const std::uint8_t*>(s.data()), s.size());
  ++runs;
}

template <class T>
void overwrite(std::string s, std::size_t at, T v) {
  if (at + sizeof(T) > s.size()) return;
  std::memcpy(s.data() + at, &v, sizeof(T));
  run(s);
}

bool is_space(char c) { return c == ' ' || c == '\n' || c == '\t' || c == '\r'; }

void mutate(const std::string& seed) {
  for (std::size_t n = 0; n < seed.size(); ++n) run(seed.substr(0, n));
  for (std::size_t i = 0; i < seed.size(); ++i) {
    const int bits = i < 64 ? 8 : 1;
    for (int b = 0; b < bits; ++b) {
      std::string s = seed;
      s[i] = static_cast<char>(s[i] ^ (1 << ((i + b) % 8)));
      run(s);
    }
  }
  for (std::size_t i = 0; i < std::min<std::size_t>(seed.size(), 64); ++i)
    for (char c : {'\0', ' ', 'e', '-', '9'}) {
      std::string s = seed;
      s.insert(s.begin() + static_cast<std::ptrdiff_t>(i), c);
      run(s);
    }
  // Binary: block counts, sizes and record markers replaced by extreme values.
  for (std::size_t at = 0; at < std::min<std::size_t>(seed.size(), 128); at += 4)
    for (std::int32_t v : {0, 1, -1, 2, 3, 4, 8, 12, 16, 1 << 24, 1 << 30, std::numeric_limits<std::int32_t>::max(),
                           std::numeric_limits<std::int32_t>::min()})
      overwrite(seed, at, v);
  for (std::size_t at = 0; at < std::min<std::size_t>(seed.size(), 64); at += 8)
    for (std::int64_t v : {std::int64_t(4), std::int64_t(-1), std::int64_t(1) << 40, std::numeric_limits<std::int64_t>::max()})
      overwrite(seed, at, v);
  for (std::size_t at = 0; at + 8 <= seed.size(); at += 8)
    for (double v : {std::numeric_limits<double>::quiet_NaN(), std::numeric_limits<double>::infinity(), 1e300, -0.0})
      overwrite(seed, at, v);
  // Text: each of the first 40 tokens replaced by hostile ones.
  std::size_t pos = 0;
  for (int t = 0; t < 40 && pos < seed.size(); ++t) {
    while (pos < seed.size() && is_space(seed[pos])) ++pos;
    const std::size_t b = pos;
    while (pos < seed.size() && !is_space(seed[pos])) ++pos;
    if (b == pos) break;
    for (const char* r : {"0", "-1", "1", "2", "2147483647", "2147483648", "99999999999999999999", "4194304", "nan",
                          "-inf", "1e999", "1D+400", "1e-400", "+", "-", "1.0-", "1-2-3", "0x10", "2.5", "", "\xEF\xBB\xBF"}) {
      std::string s = seed;
      s.replace(b, pos - b, r);
      run(s);
    }
  }
  run(seed + std::string(1, '\0'));
  run(seed + " 1");
  run(seed + seed);
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::filesystem::path> seeds;
  for (int a = 1; a < argc; ++a)
    for (const auto& e : std::filesystem::directory_iterator(argv[a]))
      if (e.is_regular_file()) seeds.push_back(e.path());
  std::sort(seeds.begin(), seeds.end());
  if (seeds.empty()) {
    std::fprintf(stderr, "replay: no seed files in the given directories\n");
    return 1;
  }
  for (const auto& p : seeds) {
    std::ifstream in(p, std::ios::binary);
    const std::string seed((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
    const std::size_t before = runs;
    const std::size_t accepted = aerohopf_fuzz_accepted;
    run(seed);
    const auto stem = p.filename().string();
    if (aerohopf_fuzz_accepted == accepted && stem.rfind("reject-", 0) != 0 && stem.rfind("crash-", 0) != 0) {
      std::fprintf(stderr, "replay: seed %s is not accepted by the reader\n", stem.c_str());
      return 1;
    }
    mutate(seed);
    std::printf("%-40s %6zu bytes %7zu inputs\n", p.filename().string().c_str(), seed.size(), runs - before);
  }
  std::printf("replay: %zu inputs from %zu seeds (%zu accepted), no contract violation\n", runs,
              seeds.size(), aerohopf_fuzz_accepted);
  return 0;
}
