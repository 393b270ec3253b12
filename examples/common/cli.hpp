#pragma once
// Command-line reading shared by the example programs: a walk over the arguments with the value,
// number and integer of the current option, each refusal an aerohopf::input_error naming the
// option (the examples' main functions report it and exit with status 2).
#include <aerohopf/error.hpp>

#include <exception>
#include <string>
#include <vector>

namespace example_cli {

class arguments {
 public:
  arguments(int argc, char** argv) : argc_(argc), argv_(argv) {}

  /// The next argument into a; false after the last one.
  bool next(std::string& a) {
    if (i_ + 1 >= argc_) return false;
    option_ = a = argv_[++i_];
    return true;
  }
  /// The value that follows the current option.
  std::string value() {
    aerohopf::require(i_ + 1 < argc_, "option ", option_, " needs a value");
    return argv_[++i_];
  }
  double number() { return parsed<double>("a number", [](const std::string& v, std::size_t* u) { return std::stod(v, u); }); }
  int integer() { return parsed<int>("an integer", [](const std::string& v, std::size_t* u) { return std::stoi(v, u); }); }
  /// A comma-separated list of numbers (at least one).
  std::vector<double> numbers() {
    const std::string v = value();
    std::vector<double> out;
    std::size_t from = 0;
    while (true) {
      const std::size_t comma = v.find(',', from);
      const std::string item = v.substr(from, comma == std::string::npos ? std::string::npos : comma - from);
      std::size_t used = 0;
      double x = 0;
      try {
        x = std::stod(item, &used);
      } catch (const std::exception&) {
        used = 0;
      }
      if (item.empty() || used != item.size())
        throw aerohopf::input_error(option_ + " takes a comma-separated list of numbers, not '" + v + "'");
      out.push_back(x);
      if (comma == std::string::npos) break;
      from = comma + 1;
    }
    return out;
  }
  /// A comma-separated list of words (at least one, none empty).
  std::vector<std::string> words() {
    const std::string v = value();
    std::vector<std::string> out;
    std::size_t from = 0;
    while (true) {
      const std::size_t comma = v.find(',', from);
      out.push_back(v.substr(from, comma == std::string::npos ? std::string::npos : comma - from));
      if (out.back().empty()) throw aerohopf::input_error(option_ + " takes a comma-separated list, not '" + v + "'");
      if (comma == std::string::npos) break;
      from = comma + 1;
    }
    return out;
  }

 private:
  /// The value converted by convert (std::stod-like), all of it used, else input_error.
  template <class T, class Convert>
  T parsed(const char* what, Convert convert) {
    const std::string v = value();
    std::size_t used = 0;
    T x{};
    try {
      x = convert(v, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != v.size()) throw aerohopf::input_error(option_ + " takes " + what + ", not '" + v + "'");
    return x;
  }
  int argc_;
  char** argv_;
  int i_ = 0;
  std::string option_;
};

}  // namespace example_cli
