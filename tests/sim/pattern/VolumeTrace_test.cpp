// Unit: reading and preparing a measured volume trace (VolumeTrace.h): units, resampling, the zero-phase
// low-pass, the offset to the minimum, and one-line errors naming the line and column.
#include "pneuma/sim/pattern/VolumeTrace.h"

#include <gtest/gtest.h>

#include <cmath>
#include <sstream>
#include <string>

#include "pneuma/sim/Error.h"

using namespace pneuma::sim;
using namespace pneuma::sim::pattern;

namespace {

constexpr double kStep = 0.01;  // [s]

// "time [s],volume [<unit>]" rows of f(t) [in that unit] at `rate` [Hz] over [0, seconds]
template <class F>
std::string csv(const char* unit, double rate, double seconds, F f) {
  std::ostringstream out;
  out.precision(12);
  out << "time [s],volume [" << unit << "]\n";
  for (int k = 0; k <= static_cast<int>(std::round(seconds * rate)); ++k)
    out << k / rate << "," << f(k / rate) << "\n";
  return out.str();
}

std::string errorOf(const std::string& text) {
  try {
    parseVolumeTrace(text, "t.csv", kStep);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

}  // namespace

// a slow breath survives resampling and filtering; 25 Hz noise of 10 % of its swing is removed; the
// minimum is at 0 and litres and millilitres read alike
TEST(VolumeTrace, KeepsTheBreathRemovesNoiseAndOffsetsToTheMinimum) {
  const double pi = std::acos(-1.0);
  const auto breath = [&](double t) { return 2.4 + 0.25 * (1.0 - std::cos(2.0 * pi * 0.25 * t)); };  // [L]
  const auto noisy = [&](double t) { return breath(t) + 0.05 * std::sin(2.0 * pi * 25.0 * t + 0.3); };
  const VolumeTrace litres = parseVolumeTrace(csv("L", 200.0, 20.0, noisy), "t.csv", kStep);
  const VolumeTrace ml =
      parseVolumeTrace(csv("mL", 200.0, 20.0, [&](double t) { return 1e3 * noisy(t); }), "t.csv", kStep);
  ASSERT_EQ(litres.volume.size(), 2001u);
  EXPECT_NEAR(litres.duration(), 20.0, 1e-9);
  double lo = 1.0, hi = -1.0, worst = 0.0;
  for (std::size_t k = 0; k < litres.volume.size(); ++k) {
    const double t = kStep * static_cast<double>(k);
    lo = std::min(lo, litres.volume[k]), hi = std::max(hi, litres.volume[k]);
    // the clean breath above its minimum (2.4 L), in m^3
    // within 0.5 s of either end the filter's steady start (the mean of its first 0.25 s) leaves up to 2 %
    const double error = std::abs(litres.volume[k] - (breath(t) - 2.4) * 1e-3);
    if (t > 0.5 && t < 19.5) worst = std::max(worst, error);
    EXPECT_LT(error, 0.012e-3) << t;
    EXPECT_NEAR(ml.volume[k], litres.volume[k], 1e-12);
  }
  EXPECT_DOUBLE_EQ(lo, 0.0);
  EXPECT_NEAR(hi, 0.5e-3, 0.005e-3);  // the 0.5 L swing within 1 %
  EXPECT_LT(worst, 0.005e-3);         // 50 mL of noise down below 5 mL, edges included
  EXPECT_NEAR(litres.sample(2.0), (breath(2.0) - 2.4) * 1e-3, 0.005e-3);
}

TEST(VolumeTrace, RejectsBadInputNamingTheLineAndColumn) {
  const std::string ok = "time [s],volume [L]\n0,2.4\n0.5,2.6\n1,2.4\n";
  EXPECT_EQ(errorOf(ok), "");
  EXPECT_EQ(errorOf("time [s],volume [L]\n0,2.4\n0.5,2.6\n0.5,2.4\n"),
            "t.csv:4: column 1 'time [s]': time must increase, got 0.5 after line 3");
  EXPECT_EQ(errorOf("time,volume [L]\n0,2.4\n1,2.5\n"),
            "t.csv:1: column 1 'time': missing unit (write 'time [s]')");
  EXPECT_EQ(errorOf("time [s],volume [cc]\n0,2.4\n1,2.5\n"),
            "t.csv:1: column 2 'volume [cc]': unknown unit 'cc' (use L or mL)");
  EXPECT_EQ(errorOf("time [s],volume [L]\n0,2.4\n1,nan\n"),
            "t.csv:3: column 2 'volume [L]': not a finite number: 'nan'");
  EXPECT_EQ(errorOf("time [s],volume [L]\n0,2.4\n1,-0.1\n"),
            "t.csv:3: column 2 'volume [L]': negative volume -0.1");
  EXPECT_NE(errorOf("time [s],volume [L]\n0,0.5\n1,2.5\n2,6.0\n")
                .find("t.csv:4: column 2 'volume [L]': volume swing 5.5"),
            std::string::npos);
  EXPECT_NE(errorOf("t [s],v [L]\n0,1\n1,2\n").find("t.csv:1: header needs"), std::string::npos);
  EXPECT_NE(errorOf("time [s],volume [L]\n0,2.4\n").find("at least two rows"), std::string::npos);
}
