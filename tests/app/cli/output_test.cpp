// The output helpers behind simulate's files (issue 15): the atomic writer never leaves a partial file under
// a final name, and MinMaxSeries thins a series to bounded size while keeping every extreme.
#include <gtest/gtest.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "viz/AtomicFile.h"
#include "viz/MinMaxSeries.h"

namespace fs = std::filesystem;
using pneuma::viz::AtomicFileWriter;
using pneuma::viz::MinMaxSeries;

namespace {

std::string dirFor(const std::string& name) {
  const std::string d = testing::TempDir() + "pneuma_output_" + std::to_string(getpid()) + "_" + name;
  fs::remove_all(d);
  fs::create_directories(d);
  return d;
}

std::string read(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

}  // namespace

TEST(AtomicFileWriter, CommitPutsTheWholeFileInPlaceAndAbandoningKeepsTheOldOne) {
  const std::string dir = dirFor("writer");
  const std::string path = dir + "/a.csv";
  pneuma::viz::writeFileAtomically(path, "old\n");
  {
    AtomicFileWriter w(path);
    for (int i = 0; i < 100000; ++i) w.write("0123456789\n");  // beyond the buffer: written in pieces
    EXPECT_EQ(read(path), "old\n");                            // the final name is untouched until commit
  }  // abandoned: the temporary goes, the old file stays
  EXPECT_EQ(read(path), "old\n");
  EXPECT_EQ(std::distance(fs::directory_iterator(dir), fs::directory_iterator()), 1);
  AtomicFileWriter w(path);
  w.write("new\n");
  w.commit();
  EXPECT_EQ(read(path), "new\n");
}

TEST(AtomicFileWriter, AFullDeviceIsAnErrorNamingTheFileAndLeavesNothing) {
  // the temporary name made a link to /dev/full, which takes no byte (ENOSPC), as a full disk
  if (!fs::exists("/dev/full")) GTEST_SKIP() << "no /dev/full";
  const std::string dir = dirFor("full");
  const std::string path = dir + "/summary.json";
  fs::create_symlink("/dev/full", pneuma::viz::temporaryPathFor(path));
  try {
    pneuma::viz::writeFileAtomically(path, std::string(100000, 'x'));
    FAIL() << "writing to /dev/full succeeded";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()), "cannot write " + path + ": No space left on device");
  }
  EXPECT_FALSE(fs::exists(path));
  EXPECT_FALSE(fs::is_symlink(pneuma::viz::temporaryPathFor(path)));
}

TEST(MinMaxSeries, ShortSeriesAreExact) {
  MinMaxSeries s(8);
  for (int i = 0; i < 8; ++i) s.append(i, i * i);
  std::vector<double> t, v;
  s.points(t, v);
  ASSERT_EQ(t.size(), 8u);
  for (int i = 0; i < 8; ++i) EXPECT_EQ(v[static_cast<std::size_t>(i)], i * i);
}

TEST(MinMaxSeries, LongSeriesKeepEveryPeakAndTroughInBoundedSize) {
  // an hour at 60 Hz of a 15 /min sine with one-frame spikes
  MinMaxSeries s(1024);
  double lo = 0.0, hi = 0.0;
  const int n = 60 * 3600;
  for (int i = 0; i < n; ++i) {
    const double t = i / 60.0;
    double v = std::sin(2.0 * M_PI * t / 4.0);
    if (i == 123457) v = 5.0;   // a spike
    if (i == 200001) v = -7.0;  // a dip
    lo = std::min(lo, v), hi = std::max(hi, v);
    s.append(t, v);
  }
  std::vector<double> t, v;
  s.points(t, v);
  EXPECT_LE(t.size(), 2048u);
  EXPECT_EQ(s.sampleCount(), static_cast<std::size_t>(n));
  EXPECT_EQ(*std::max_element(v.begin(), v.end()), hi);
  EXPECT_EQ(*std::min_element(v.begin(), v.end()), lo);
  EXPECT_TRUE(std::is_sorted(t.begin(), t.end()));
}
