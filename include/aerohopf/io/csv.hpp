#pragma once
// Minimal CSV writer for results: a fixed header, rows of numbers or strings, full precision
// (17 significant digits) so that results can be re-read without loss. Parent folders are
// created; failure to open or write throws an aerohopf::error naming the file.
#include <filesystem>
#include <fstream>
#include <initializer_list>
#include <sstream>
#include <string>
#include <variant>
#include <vector>

#include "../error.hpp"

namespace aerohopf {

class csv_writer {
 public:
  using cell = std::variant<double, long long, std::string>;

  csv_writer(const std::filesystem::path& file, const std::string& header) : path_(file) {
    if (file.has_parent_path()) std::filesystem::create_directories(file.parent_path());
    os_.open(file);
    if (!os_) throw error("csv_writer: cannot open " + file.string() + " for writing");
    os_ << header << "\n";
    os_.precision(17);
  }
  void row(std::initializer_list<cell> cells) {
    bool first = true;
    for (const auto& c : cells) {
      if (!first) os_ << ",";
      first = false;
      if (const double* d = std::get_if<double>(&c)) os_ << *d;
      else if (const long long* i = std::get_if<long long>(&c)) os_ << *i;
      else os_ << std::get<std::string>(c);
    }
    os_ << "\n";
    os_.flush();  // long runs: every row is on disk as soon as it is computed
    if (!os_) throw error("csv_writer: write to " + path_.string() + " failed");
  }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
  std::ofstream os_;
};

}  // namespace aerohopf
