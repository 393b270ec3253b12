#pragma once
// Command-line reading shared by the example programs: a walk over the arguments with the value,
// number and integer of the current option, each refusal an aerohopf::input_error naming the
// option (the examples' main functions report it and exit with status 2).
#include <aerohopf/error.hpp>

#include <exception>
#include <string>

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
