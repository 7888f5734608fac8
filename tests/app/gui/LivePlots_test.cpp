// The live plots over long and fast runs (issue 15, class 12): memory and plotted points do not grow with the
// output rate or the run length, every peak and trough stays visible, and at display rates the plots are
// exact.
#include "gui/LivePlots.h"

#include <gtest/gtest.h>
#include <malloc.h>

#include <algorithm>
#include <cmath>

#include "GuiTestSupport.h"
#include "gui/PlotView.h"

using namespace pneuma;
using pneuma::app::PlotSample;

namespace {

constexpr std::size_t kElements = 64;

// a calm-looking sample at time t [s]: volume 3 L +/- 0.25 L at 15 breaths/min, every element at 10 N tension
PlotSample sampleAt(double t) {
  PlotSample s;
  s.time = t;
  s.lungVolume = 3e-3 + 0.25e-3 * std::sin(2.0 * M_PI * t / 4.0);
  s.gutVolumeError = 1e-3 * std::cos(2.0 * M_PI * t / 4.0);
  for (auto& a : s.activations) a.r = a.alpha = 0.5 + 0.5 * std::sin(2.0 * M_PI * t / 4.0);
  s.elementForce.assign(kElements, -10.0f);
  return s;
}

// feeds `seconds` at `rate` [Hz] from `t0` in batches of 1/30 s, as the main window's refresh does
double feed(app::LivePlots& plots, double t0, double seconds, double rate) {
  const auto count = static_cast<long>(std::lround(seconds * rate));
  std::vector<PlotSample> batch;
  for (long i = 1; i <= count; ++i) {
    batch.push_back(sampleAt(t0 + static_cast<double>(i) / rate));
    if (batch.size() >= static_cast<std::size_t>(rate / 30.0)) plots.append(std::move(batch)), batch.clear();
  }
  plots.append(std::move(batch));
  return t0 + static_cast<double>(count) / rate;
}

// [bytes] allocated on the heap, small blocks and mapped ones
std::size_t heapInUse() {
  const struct mallinfo2 m = mallinfo2();
  return m.uordblks + m.hblkhd;
}

}  // namespace

// two hours at the highest output rate the scenario files allow would hold 1.2 million samples over the 120 s
// history; 130 s at 2 kHz (260,000 samples, each with its element forces) shows the growth within seconds
TEST(LivePlots, MemoryAndPlottedPointsStayBoundedAtAnyOutputRate) {
  app::test::application();
  app::LivePlots plots;
  plots.addTrace({"element 3", {3}});
  double t = feed(plots, 0.0, 2.0, 2000.0);
  const std::size_t before = heapInUse();
  t = feed(plots, t, 128.0, 2000.0);
  // a single-sample spike and dip inside the shown window
  plots.append({sampleAt(t + 0.0005)});
  PlotSample spike = sampleAt(t + 0.001), dip = sampleAt(t + 0.0015);
  spike.lungVolume = 10e-3;
  dip.lungVolume = 1e-3;
  plots.append({spike, dip});
  t = feed(plots, t + 0.0015, 5.0, 2000.0);
  const std::size_t after = heapInUse();
  // the old history held every sample of 120 s: about 240,000 x 0.5 kB = 115 MB here
  EXPECT_LT(after - std::min(after, before), 32u << 20)
      << "heap grew by " << (after - before) / 1024 << " kB";

  ASSERT_TRUE(plots.refresh());
  const app::PlotView& volume = *plots.volumePlot();
  // the 120 s history the plots scroll over: at most two points per bucket of its segments, not the 240,000
  // samples
  EXPECT_LT(volume.time().size(), 24000u);
  EXPECT_GT(volume.time().size(), 6000u);
  EXPECT_GE(volume.time().front(), t - 120.0 - 6.0);
  EXPECT_DOUBLE_EQ(volume.time().back(), t);
  const std::vector<double>& v = volume.series()[0].y;
  EXPECT_DOUBLE_EQ(*std::max_element(v.begin(), v.end()), 10000.0);  // [mL] the spike, kept
  EXPECT_DOUBLE_EQ(*std::min_element(v.begin(), v.end()), 1000.0);   // the dip, kept
  EXPECT_TRUE(std::is_sorted(volume.time().begin(), volume.time().end()));
  // the picked element's trace: 10 N wherever it has a frame, which is everywhere in the window
  const app::PlotView& tension = *plots.plots()[3];
  const std::vector<double>& trace = tension.series().back().y;
  ASSERT_EQ(trace.size(), volume.time().size());
  for (std::size_t k = 0; k < trace.size(); ++k) {
    if (volume.time()[k] >= t - 20.0) {
      ASSERT_EQ(trace[k], 10.0) << "at " << volume.time()[k] << " s";
    }
  }
  // the tidal volume still sees the last breath's extremes: 0.5 L peak to trough
  EXPECT_NEAR(plots.tidalVolume(), 0.5e-3, 1e-6);
}

// at the app's 60 Hz every sample of the history is plotted as it came; the 20 s window shows the newest
TEST(LivePlots, DisplayRatesArePlottedExactly) {
  app::test::application();
  app::LivePlots plots;
  const double t = feed(plots, 0.0, 30.0, 60.0);
  ASSERT_TRUE(plots.refresh());
  const app::PlotView& volume = *plots.volumePlot();
  ASSERT_EQ(volume.time().size(), 30u * 60u);  // (0, t]: every sample, to scroll back over
  for (std::size_t k = 0; k < volume.time().size(); ++k) {
    const double tk = static_cast<double>(k + 1) / 60.0;
    ASSERT_NEAR(volume.time()[k], tk, 1e-9);
    ASSERT_EQ(volume.series()[0].y[k], 1e6 * sampleAt(volume.time()[k]).lungVolume);
  }
  const viz::Plot shown = volume.toPlot(1.0);
  EXPECT_NEAR(shown.series()[0].x.front(), t - 20.0, 1e-9);
  EXPECT_NEAR(shown.series()[0].x.back(), t, 1e-9);
}
