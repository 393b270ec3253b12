#pragma once
// The refusal tests' two helpers: the message of the exception an action throws, and a substring
// test for it (the tests assert that a message names the function, the entry and the value).
#include <aerohopf/error.hpp>

#include <gtest/gtest.h>

#include <string>

namespace aerohopf::test {

/// what() of the E that fn() throws ("" and a test failure if it throws none or another type).
template <class E, class Fn>
std::string error_of(Fn&& fn) {
  try {
    fn();
  } catch (const E& e) {
    return e.what();
  }
  ADD_FAILURE() << "no exception of the expected type thrown";
  return "";
}

template <class Fn>
std::string input_error_of(Fn&& fn) {
  return error_of<input_error>(fn);
}

inline bool contains(const std::string& s, const std::string& part) { return s.find(part) != std::string::npos; }

}  // namespace aerohopf::test
