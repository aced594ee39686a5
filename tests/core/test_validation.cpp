#include <catch2/catch.hpp>

#include <cmath>
#include <limits>
#include <string>

#include "dualgrid/core/validation.hpp"

using namespace dualgrid;

namespace {

constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

struct Inner {
  double gate = 1.0;
  bool IsValid(std::string* error) const {
    return FieldCheck().Positive("gate", gate, "m").Done(error);
  }
};

// The message of the one check `run` makes on a fresh checker ("" when it passes).
template <typename F>
std::string MessageOf(F run) {
  FieldCheck c;
  run(c);
  return c.message();
}

}  // namespace

TEST_CASE("FieldCheck keeps the first failure", "[core][validation]") {
  FieldCheck c;
  c.Positive("a", 1.0);
  c.Positive("b", -2.0);
  c.InRange("c", 7.0, 0.0, 1.0);
  c.Expect(false, "d", "x", "anything");
  std::string error;
  CHECK_FALSE(c.ok());
  CHECK_FALSE(c.Done(&error));
  CHECK(error == "b = -2: expected finite and > 0");
  CHECK(c.message() == error);
  CHECK_FALSE(c.Done(nullptr));  // no message wanted: still false
}

TEST_CASE("FieldCheck messages name the field, the value and the expectation",
          "[core][validation]") {
  CHECK(MessageOf([](FieldCheck& c) { c.Positive("sigma_v", -1.0, "m/s"); }) ==
        "sigma_v = -1: expected finite and > 0 m/s");
  CHECK(MessageOf([](FieldCheck& c) { c.NonNegative("gain", -0.25); }) ==
        "gain = -0.25: expected finite and >= 0");
  CHECK(MessageOf([](FieldCheck& c) { c.Finite("rcs", -kInf, "dBsm"); }) ==
        "rcs = -inf: expected finite dBsm");
  CHECK(MessageOf([](FieldCheck& c) {
          c.InRange("persistence", 1.5, 0.0, 1.0, Interval::kLeftOpen);
        }) == "persistence = 1.5: expected in (0, 1]");
  CHECK(MessageOf([](FieldCheck& c) { c.InRange("p", 1.0, 0.0, 1.0, Interval::kRightOpen); }) ==
        "p = 1: expected in [0, 1)");
  CHECK(MessageOf([](FieldCheck& c) { c.InRange("p", 0.0, 0.0, 0.5, Interval::kOpen, "s"); }) ==
        "p = 0: expected in (0, 0.5) s");
  CHECK(MessageOf([](FieldCheck& c) { c.AtLeast("num_particles", 0, 1); }) ==
        "num_particles = 0: expected >= 1");
  CHECK(MessageOf([](FieldCheck& c) { c.InRange("width", 50, 100, 5000); }) ==
        "width = 50: expected in [100, 5000]");
  CHECK(MessageOf([](FieldCheck& c) { c.Expect(false, "mode", "'quantum'", "dual"); }) ==
        "mode = 'quantum': expected dual");
  // Values are written so that they read back exactly.
  CHECK(MessageOf([](FieldCheck& c) { c.Expect(false, "x", 0.1 + 0.2, "0.3"); }) ==
        "x = 0.30000000000000004: expected 0.3");
  // The prefix goes before every field; a member's message gets its own prefix too.
  FieldCheck c("series[2].");
  c.Member("inner.", Inner{.gate = 0.0});
  CHECK(c.message() == "series[2].inner.gate = 0: expected finite and > 0 m");
}

TEST_CASE("FieldCheck rejects NaN in every numeric check", "[core][validation]") {
  CHECK(MessageOf([](FieldCheck& c) { c.Positive("v", kNan); }) ==
        "v = nan: expected finite and > 0");
  CHECK(MessageOf([](FieldCheck& c) { c.NonNegative("v", kNan); }) ==
        "v = nan: expected finite and >= 0");
  CHECK(MessageOf([](FieldCheck& c) { c.Finite("v", kNan); }) == "v = nan: expected finite");
  const Interval ends =
      GENERATE(Interval::kClosed, Interval::kOpen, Interval::kLeftOpen, Interval::kRightOpen);
  CHECK(MessageOf([&](FieldCheck& c) {
          c.InRange("v", kNan, 0.0, 1.0, ends);
        }).rfind("v = nan: expected in ", 0) == 0);
  CHECK(MessageOf([&](FieldCheck& c) {
          c.InRange("v", -kNan, -kInf, kInf, ends);
        }).rfind("v = nan: expected in ", 0) == 0);
  // Infinities are outside finite bounds and not positive-and-finite.
  CHECK_FALSE(FieldCheck().Positive("v", kInf).ok());
  CHECK_FALSE(FieldCheck().InRange("v", kInf, 0.0, 1e300).ok());
}

TEST_CASE("FieldCheck interval ends", "[core][validation]") {
  const auto in = [](double v, Interval ends) {
    return FieldCheck().InRange("v", v, 0.0, 1.0, ends).ok();
  };
  CHECK(in(0.0, Interval::kClosed));
  CHECK(in(1.0, Interval::kClosed));
  CHECK_FALSE(in(0.0, Interval::kOpen));
  CHECK_FALSE(in(1.0, Interval::kOpen));
  CHECK_FALSE(in(0.0, Interval::kLeftOpen));
  CHECK(in(1.0, Interval::kLeftOpen));
  CHECK(in(0.0, Interval::kRightOpen));
  CHECK_FALSE(in(1.0, Interval::kRightOpen));
  CHECK(in(0.5, Interval::kOpen));
}

TEST_CASE("A passing FieldCheck leaves *error untouched", "[core][validation]") {
  FieldCheck c;
  c.Positive("a", 1.0)
      .NonNegative("b", 0.0)
      .Finite("c", -3.0)
      .InRange("d", 0.5, 0.0, 1.0)
      .AtLeast("e", 1, 1)
      .InRange("f", 5, 0, 5)
      .Expect(true, "g", "x", "y")
      .Member("h.", Inner{});
  std::string error = "untouched";
  CHECK(c.ok());
  CHECK(c.message().empty());
  CHECK(c.Done(&error));
  CHECK(error == "untouched");
  CHECK(c.Done(nullptr));
}

TEST_CASE("Checks after a failure are skipped", "[core][validation]") {
  int calls = 0;
  struct Counting {
    int* calls;
    bool IsValid(std::string*) const {
      ++*calls;
      return true;
    }
  };
  FieldCheck c;
  c.AtLeast("n", -1, 0);
  c.Member("m.", Counting{&calls});
  CHECK(calls == 0);
  CHECK(c.message() == "n = -1: expected >= 0");
}

TEST_CASE("Indexed names a list element", "[core][validation]") {
  CHECK(Indexed("series", 0) == "series[0]");
  CHECK(Indexed("series[2].errors", 17) == "series[2].errors[17]");
}
