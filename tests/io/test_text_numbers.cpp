// Numbers in text files: the C and Fortran forms engineering codes write (D exponents, the
// exponent letter left out, a trailing point) against their values, and the refusals (partial
// tokens, hexadecimal, a lone sign, out of range) that the Plot3D and NASTRAN readers rely on.
#include <gtest/gtest.h>

#include <aerohopf/io/text_numbers.hpp>

#include <cmath>

using namespace aerohopf::io::internal;

TEST(TextNumbers, RealsInCAndFortranForms) {
  const std::pair<const char*, double> ok[] = {{"1.5", 1.5},     {"1.5E-3", 1.5e-3}, {"1.5D-3", 1.5e-3}, {"1.5d+2", 150.0},
                                               {"1.5-3", 1.5e-3}, {"-2.5+1", -25.0},  {"7.", 7.0},         {"+0.25", 0.25},
                                               {".5", 0.5},       {"-3.9478418E+3", -3947.8418}};
  for (const auto& [text, value] : ok) {
    double v = 0;
    EXPECT_EQ(parse_real(text, v), real_status::ok) << text;
    EXPECT_DOUBLE_EQ(v, value) << text;
  }
  for (const char* bad : {"", "abc", "1.5x", "0x10", "+", "-", "++1", "1.0 2", "1,5"}) {
    double v = 0;
    EXPECT_EQ(parse_real(bad, v), real_status::not_a_number) << bad;
  }
  double v = 0;
  EXPECT_EQ(parse_real("1e999", v), real_status::out_of_range);
  EXPECT_EQ(parse_real("nan", v), real_status::ok);  // parses; the readers refuse non-finite values
  EXPECT_TRUE(std::isnan(v));
}

TEST(TextNumbers, WholeTokenIntegers) {
  long long v = 0;
  EXPECT_TRUE(parse_integer("42", v));
  EXPECT_EQ(v, 42);
  EXPECT_TRUE(parse_integer("+7", v));
  EXPECT_EQ(v, 7);
  EXPECT_TRUE(parse_integer("-3", v));
  EXPECT_EQ(v, -3);
  for (const char* bad : {"", "4.0", "1e3", "12a", "+-1", "99999999999999999999"}) EXPECT_FALSE(parse_integer(bad, v)) << bad;
}
