#include <catch2/catch.hpp>

#include <cmath>
#include <cstdlib>
#include <iomanip>
#include <limits>
#include <sstream>
#include <string>

#include "dualgrid/core/text.hpp"

using namespace dualgrid;

TEST_CASE("FormatShort writes the shortest text that reads back exactly", "[core][text]") {
  CHECK(FormatShort(0.0) == "0");
  CHECK(FormatShort(-0.0) == "-0");
  CHECK(FormatShort(1.0) == "1");
  CHECK(FormatShort(-1.0) == "-1");
  CHECK(FormatShort(0.1) == "0.1");
  CHECK(FormatShort(2.5) == "2.5");
  CHECK(FormatShort(0.1 + 0.2) == "0.30000000000000004");
  CHECK(FormatShort(1.0 / 3.0) == "0.3333333333333333");
  CHECK(FormatShort(1e-7) == "1e-07");
  CHECK(FormatShort(0.0001) == "0.0001");
  // Whole numbers are written out below 1e15, not as %g's 1e+02.
  CHECK(FormatShort(100.0) == "100");
  CHECK(FormatShort(-2e8) == "-200000000");
  CHECK(FormatShort(123456789.0) == "123456789");
  CHECK(FormatShort(1e20) == "1e+20");
  CHECK(FormatShort(std::numeric_limits<double>::quiet_NaN()) == "nan");
  CHECK(FormatShort(-std::numeric_limits<double>::quiet_NaN()) == "nan");
  CHECK(FormatShort(std::numeric_limits<double>::infinity()) == "inf");
  CHECK(FormatShort(-std::numeric_limits<double>::infinity()) == "-inf");
  const double v =
      GENERATE(0.05, 1.0 / 7.0, 6.283185307179586, 1e-300, 4.9e-324, 1.7976931348623157e308,
               -123.456, 9007199254740993.0, 0.07200000000000001);
  CHECK(std::strtod(FormatShort(v).c_str(), nullptr) == v);
}

TEST_CASE("FormatSignificant and FormatFixed are printf's %g and %f", "[core][text]") {
  // The SUMO files and CSVs were written with an ostream at setprecision(10), the tables with
  // std::fixed: the helpers must give the same bytes.
  const double v =
      GENERATE(0.0, -0.0, 1.0, 0.1 + 0.2, 1.0 / 3.0, 123456.789, -2.5e-7, 1e15, 1e300,
               std::numeric_limits<double>::infinity(), -std::numeric_limits<double>::infinity(),
               std::numeric_limits<double>::quiet_NaN());
  std::ostringstream g;
  g << std::setprecision(10) << v;
  CHECK(FormatSignificant(v, 10) == g.str());
  const int decimals = GENERATE(0, 1, 3, 6);
  std::ostringstream f;
  f << std::fixed << std::setprecision(decimals) << v;
  CHECK(FormatFixed(v, decimals) == f.str());
  CHECK(FormatSignificant(1234.5678, 4) == "1235");
  CHECK(FormatSignificant(0.000123456, 4) == "0.0001235");
  CHECK(FormatSignificant(12345678.0, 4) == "1.235e+07");
  CHECK(FormatFixed(2.5, 2) == "2.50");
  CHECK(FormatFixed(-0.0001, 3) == "-0.000");
  CHECK(FormatFixed(1e300, 1).size() == 303);  // no fixed-size buffer cuts it short
}

TEST_CASE("XmlEscape escapes markup and drops characters XML cannot hold", "[core][text]") {
  CHECK(XmlEscape("") == "");
  CHECK(XmlEscape("plain_id-1.5") == "plain_id-1.5");
  CHECK(XmlEscape("a&b<c>d\"e'f") == "a&amp;b&lt;c&gt;d&quot;e&apos;f");
  CHECK(XmlEscape("&amp;") == "&amp;amp;");  // text, not markup: escaped again
  CHECK(XmlEscape("tab\tnl\ncr\r") == "tab\tnl\ncr\r");
  CHECK(XmlEscape(std::string("bell\x07nul", 8) + std::string(1, '\0')) == "bell?nul?");
  CHECK(XmlEscape("stra\xc3\x9f"
                  "e") ==
        "stra\xc3\x9f"
        "e");  // UTF-8 kept
}

TEST_CASE("FormatTuple lists values by FormatShort", "[core][text]") {
  CHECK(FormatTuple({}) == "()");
  CHECK(FormatTuple({1.5}) == "(1.5)");
  CHECK(FormatTuple({1.5, -2.0, std::nan("")}) == "(1.5, -2, nan)");
}
