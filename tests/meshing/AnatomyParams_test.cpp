#include "pneuma/meshing/AnatomyParams.h"
#include "pneuma/meshing/ModelBuilder.h"
#include "pneuma/sim/Error.h"

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include <fstream>
#include <sstream>

namespace pneuma::meshing {
namespace {

const std::string kDir = std::string(PNEUMA_RESOURCE_DIR) + "/anatomy/";

std::string read(const std::string& path) {
  std::ifstream in(path);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

/// The error message of parsing the male preset after `corrupt` edited its JSON.
template <typename F>
std::string errorOf(F corrupt) {
  nlohmann::json j = nlohmann::json::parse(read(kDir + "male.json"));
  corrupt(j);
  try {
    const AnatomyParams a = parseAnatomy(j.dump(), read(kDir + "muscle_gains.json"), "male.json");
    buildModel(a);
  } catch (const sim::Error& e) {
    return e.what();
  }
  return "no error";
}

TEST(AnatomyParams, PresetsLoadInSiUnits) {
  for (const char* name : {"male.json", "female.json"}) {
    const AnatomyParams a = loadAnatomy(kDir + name);
    ASSERT_EQ(a.ribs.size(), 12u) << name;
    EXPECT_GT(a.ribs[6].arcLength, 0.2) << name;   // rib 7 is ~30 cm long
    EXPECT_LT(a.ribs[6].arcLength, 0.4) << name;
    EXPECT_GE(a.spine.thoracicSegments.size(), 3u) << name;
    EXPECT_DOUBLE_EQ(a.gains.wallMass, 8.0) << name;
  }
  // the female ribcage is smaller and its ribs are more inclined (Bellemare et al. 2003)
  const AnatomyParams m = loadAnatomy(kDir + "male.json");
  const AnatomyParams f = loadAnatomy(kDir + "female.json");
  EXPECT_LT(f.ribs[6].arcLength, m.ribs[6].arcLength);
  EXPECT_GT(f.ribs[6].inclination, m.ribs[6].inclination);
}

TEST(AnatomyParams, NegativeLengthIsRejectedNamingTheField) {
  const std::string e = errorOf([](nlohmann::json& j) { j["ribs"][3]["arc_length_mm"] = -5; });
  EXPECT_NE(e.find("male.json.ribs[3].arc_length_mm: must be > 0, got -5"), std::string::npos) << e;
}

TEST(AnatomyParams, ZeroRibCountIsRejected) {
  const std::string e = errorOf([](nlohmann::json& j) { j["ribs"] = nlohmann::json::array(); });
  EXPECT_NE(e.find("male.json.ribs: must list 12 rib levels, got 0"), std::string::npos) << e;
}

TEST(AnatomyParams, MissingFieldIsNamed) {
  const std::string e = errorOf([](nlohmann::json& j) { j["sternum"].erase("body_length_mm"); });
  EXPECT_NE(e.find("male.json.sternum.body_length_mm: missing"), std::string::npos) << e;
}

TEST(AnatomyParams, TooFewSpineSegmentsAreRejected) {
  const std::string e = errorOf([](nlohmann::json& j) { j["spine"]["thoracic_segments"] = {{1, 6}, {7, 12}}; });
  EXPECT_NE(e.find("thoracic_segments: needs at least 3"), std::string::npos) << e;
}

TEST(AnatomyParams, OverlappingRibsAreRejectedNamingTheLevels) {
  // rib 6 made 40 mm tall: it runs into rib 5 next to the spine
  const std::string e = errorOf([](nlohmann::json& j) { j["ribs"][5]["height_mm"] = 40; });
  EXPECT_NE(e.find("ribs[4] and ribs[5] overlap"), std::string::npos) << e;
}

TEST(AnatomyParams, BadGainsAreRejectedNamingTheFile) {
  nlohmann::json g = nlohmann::json::parse(read(kDir + "muscle_gains.json"));
  g["groups"]["diaphragm"]["kpe"] = -1;
  try {
    parseAnatomy(read(kDir + "male.json"), g.dump(), "male.json", "muscle_gains.json");
    FAIL() << "negative gain accepted";
  } catch (const sim::Error& e) {
    EXPECT_NE(std::string(e.what()).find("muscle_gains.json.groups.diaphragm.kpe"), std::string::npos) << e.what();
  }
}

TEST(AnatomyParams, MalformedJsonAndMissingFileAreErrors) {
  EXPECT_THROW(parseAnatomy("{ not json", read(kDir + "muscle_gains.json")), sim::Error);
  EXPECT_THROW(loadAnatomy(kDir + "does_not_exist.json"), sim::Error);
}

}  // namespace
}  // namespace pneuma::meshing
