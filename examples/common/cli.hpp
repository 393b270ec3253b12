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
  double number() {
    const std::string v = value();
    std::size_t used = 0;
    double x = 0;
    try {
      x = std::stod(v, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != v.size()) throw aerohopf::input_error(option_ + " takes a number, not '" + v + "'");
    return x;
  }
  int integer() {
    const std::string v = value();
    std::size_t used = 0;
    int x = 0;
    try {
      x = std::stoi(v, &used);
    } catch (const std::exception&) {
      used = 0;
    }
    if (used == 0 || used != v.size()) throw aerohopf::input_error(option_ + " takes an integer, not '" + v + "'");
    return x;
  }

 private:
  int argc_;
  char** argv_;
  int i_ = 0;
  std::string option_;
};

}  // namespace example_cli
