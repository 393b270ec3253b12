#pragma once
// Numbers in text files as engineering codes write them, shared by the readers (Plot3D text,
// NASTRAN bulk data and punch output): whole-token integers and reals in C or Fortran notation
// (D exponents, the exponent letter left out before a signed exponent). Locale-independent
// (std::from_chars), no hexadecimal, no partial tokens.
#include <cctype>
#include <charconv>
#include <cstddef>
#include <cstring>
#include <string_view>
#include <system_error>

namespace aerohopf::io::internal {

/// A whole token as a decimal integer with optional sign.
inline bool parse_integer(std::string_view t, long long& v) {
  if (t.size() > 1 && t[0] == '+' && t[1] != '-') t.remove_prefix(1);
  const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
  return !t.empty() && r.ec == std::errc() && r.ptr == t.data() + t.size();
}

enum class real_status { ok, not_a_number, out_of_range };

/// A whole token as a real number: C or Fortran notation (D/d exponents, and a sign after
/// the mantissa without exponent letter, 1.0-100 = 1e-100). "nan" and "inf" parse (as
/// non-finite values, which the caller refuses with its own message).
inline real_status parse_real(std::string_view t, double& v) {
  char buf[128];
  if (t.empty() || t.size() + 2 > sizeof buf) return real_status::not_a_number;
  std::size_t i = 0, n = 0;
  if (t[0] == '+') {
    if (t.size() == 1 || t[1] == '+' || t[1] == '-') return real_status::not_a_number;
    i = 1;
  }
  bool letter = false;
  std::size_t exponent_sign = 0;  // position in buf of a sign directly after the mantissa
  for (; i < t.size(); ++i) {
    char c = t[i];
    if (c == 'd' || c == 'D') c = 'e';
    if (c == 'e' || c == 'E') letter = true;
    if ((c == '+' || c == '-') && n > 0 && !exponent_sign && (std::isdigit(static_cast<unsigned char>(buf[n - 1])) || buf[n - 1] == '.'))
      exponent_sign = n;
    buf[n++] = c;
  }
  if (!letter && exponent_sign) {
    std::memmove(buf + exponent_sign + 1, buf + exponent_sign, n - exponent_sign);
    buf[exponent_sign] = 'e';
    ++n;
  }
  const auto r = std::from_chars(buf, buf + n, v, std::chars_format::general);
  if (r.ptr != buf + n || r.ec == std::errc::invalid_argument) return real_status::not_a_number;
  if (r.ec == std::errc::result_out_of_range) return real_status::out_of_range;
  return r.ec == std::errc() ? real_status::ok : real_status::not_a_number;
}

}  // namespace aerohopf::io::internal
