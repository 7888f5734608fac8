// Every input of the fuzzers' seed corpus (fuzz/corpus/<loader>/) and every reproducer found so far
// (fuzz/reproducers/<loader>/) goes through its real loader: accepted or rejected with a sim::Error, never
// another exception, and quickly (issue 15, "fuzzing as part of the project"; CONTRIBUTING.md "Fuzzing").
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>

#include "FuzzLoaders.h"

namespace fs = std::filesystem;
using pneuma::fuzz::Loader;

namespace {

class Replay : public testing::TestWithParam<Loader> {};

TEST_P(Replay, CorpusAndReproducersAreAcceptedOrRejectedCleanly) {
  const std::string name = pneuma::fuzz::loaderName(GetParam());
  int inputs = 0;
  for (const char* set : {"corpus", "reproducers"}) {
    const fs::path dir = fs::path(PNEUMA_FUZZ_DIR) / set / name;
    if (!fs::exists(dir)) continue;
    for (const auto& e : fs::directory_iterator(dir)) {
      if (!e.is_regular_file()) continue;
      ++inputs;
      const std::string text = pneuma::fuzz::readFile(e.path().string());
      const auto start = std::chrono::steady_clock::now();
      EXPECT_NO_THROW(pneuma::fuzz::runLoader(GetParam(), text, PNEUMA_RESOURCE_DIR)) << e.path();
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
      EXPECT_LT(seconds, 5.0) << e.path() << " took " << seconds << " s";
    }
  }
  EXPECT_GT(inputs, 0) << "no seed corpus in fuzz/corpus/" << name;
  RecordProperty("inputs", inputs);
}

INSTANTIATE_TEST_SUITE_P(Loaders, Replay, testing::ValuesIn(pneuma::fuzz::allLoaders()),
                         [](const testing::TestParamInfo<Loader>& i) {
                           return pneuma::fuzz::loaderName(i.param);
                         });

}  // namespace
