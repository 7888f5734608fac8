#include "pneuma/meshing/AnatomyParams.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "pneuma/meshing/ModelBuilder.h"
#include "pneuma/sim/Error.h"
#include "pneuma/sim/Ties.h"

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
    buildModel(a, "");  // no skin: the anatomy's errors come before it
  } catch (const sim::Error& e) {
    return e.what();
  }
  return "no error";
}

TEST(AnatomyParams, PresetsLoadInSiUnits) {
  for (const char* name : {"male.json", "female.json"}) {
    const AnatomyParams a = loadAnatomy(kDir + name);
    ASSERT_EQ(a.ribs.size(), 12u) << name;
    EXPECT_GT(a.ribs[6].arcLength, 0.2) << name;  // rib 7 is ~30 cm long
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
  EXPECT_NE(e.find("male.json: ribs[3].arc_length_mm: must be in [30, 600], got -5"), std::string::npos) << e;
}

TEST(AnatomyParams, ZeroRibCountIsRejected) {
  const std::string e = errorOf([](nlohmann::json& j) { j["ribs"] = nlohmann::json::array(); });
  EXPECT_NE(e.find("male.json: ribs: must list 12 rib levels, got 0"), std::string::npos) << e;
}

TEST(AnatomyParams, MissingFieldIsNamed) {
  const std::string e = errorOf([](nlohmann::json& j) { j["sternum"].erase("body_length_mm"); });
  EXPECT_NE(e.find("male.json: sternum.body_length_mm: missing"), std::string::npos) << e;
}

TEST(AnatomyParams, ZoneOfAppositionAboveTheApexIsRejected) {
  const std::string e = errorOf([](nlohmann::json& j) { j["abdomen"]["apposition_height_mm"] = 100; });
  EXPECT_NE(e.find("male.json: abdomen.apposition_height_mm: must be below dome_height_mm"),
            std::string::npos)
      << e;
}

// the zone of apposition is the dome's outer band from the rim up to apposition_height_mm above the costal
// margin: only the rim below the first ring's rise (23 mm in the man), more of the dome tied to the ribs the
// taller the zone
TEST(AnatomyParams, ZoneOfAppositionGrowsWithItsHeight) {
  auto apposed = [](double heightMm) {
    nlohmann::json j = nlohmann::json::parse(read(kDir + "male.json"));
    j["abdomen"]["apposition_height_mm"] = heightMm;
    const sim::Model m = buildModel(parseAnatomy(j.dump(), read(kDir + "muscle_gains.json")), "").model;
    int n = 0;
    for (int e = 0; e < m.elements.size(); ++e) n += sim::isApposition(m, e) ? 1 : 0;
    return n;
  };
  const int rim = apposed(20), preset = apposed(65), tall = apposed(90);
  EXPECT_GT(rim, 0);  // the rim's nodes within reach of a rib (16 of its 48 in the man)
  EXPECT_LT(rim, 48);
  EXPECT_GT(preset, rim + 48);  // and at least two more rings
  EXPECT_GT(tall, preset);
}

TEST(AnatomyParams, RibJointFrictionScaleOutOfRangeIsRejectedNamingTheField) {
  const std::string e = errorOf([](nlohmann::json& j) { j["rib_joint_friction_scale"] = -1; });
  EXPECT_NE(e.find("male.json: rib_joint_friction_scale: must be in [0.1, 10], got -1"), std::string::npos)
      << e;
}

// the preset's rib-joint friction scales the costovertebral joints' mu of Eq. 3 and no other joint's; absent,
// the shared value holds; the female rib cage moves with less resistance than the male (README: the female
// preset's rib-cage share is at least the male's, Bellemare et al. 2003, Romei et al. 2010)
TEST(AnatomyParams, RibJointFrictionScaleActsOnTheRibJointsOnly) {
  nlohmann::json g = nlohmann::json::parse(read(kDir + "muscle_gains.json"));
  g["joints"]["spine"]["friction"] = 3.0;  // a spine joint with friction of its own, which must stay
  const std::string gains = g.dump();
  const auto friction = [&](const nlohmann::json& j, const std::string& prefix) {
    const sim::Model m = buildModel(parseAnatomy(j.dump(), gains), "").model;
    std::vector<double> mu;
    for (std::size_t i = 0; i < m.joints.name.size(); ++i)
      if (m.joints.name[i].rfind(prefix, 0) == 0)
        mu.push_back(m.joints.friction(static_cast<Eigen::Index>(i)));
    return mu;
  };
  nlohmann::json j = nlohmann::json::parse(read(kDir + "male.json"));
  j.erase("rib_joint_friction_scale");
  const std::vector<double> ribShared = friction(j, "costovertebral"), spineShared = friction(j, "spine");
  j["rib_joint_friction_scale"] = 0.5;
  const std::vector<double> ribHalf = friction(j, "costovertebral"), spineHalf = friction(j, "spine");
  ASSERT_EQ(ribShared.size(), 20u);  // ribs 1-10 per side move
  const double mu = loadAnatomy(kDir + "male.json").gains.joints[kCostovertebralJoint].friction;
  for (std::size_t i = 0; i < ribShared.size(); ++i) {
    EXPECT_DOUBLE_EQ(ribShared[i], mu);
    EXPECT_DOUBLE_EQ(ribHalf[i], 0.5 * mu);
  }
  ASSERT_FALSE(spineShared.empty());
  for (std::size_t i = 0; i < spineShared.size(); ++i) {
    EXPECT_DOUBLE_EQ(spineShared[i], 3.0);
    EXPECT_DOUBLE_EQ(spineHalf[i], 3.0);
  }
  EXPECT_DOUBLE_EQ(loadAnatomy(kDir + "male.json").ribJointFrictionScale, 1.0);
  EXPECT_LT(loadAnatomy(kDir + "female.json").ribJointFrictionScale, 1.0);
}

TEST(AnatomyParams, TooFewSpineSegmentsAreRejected) {
  const std::string e = errorOf([](nlohmann::json& j) {
    j["spine"]["thoracic_segments"] = {{1, 6}, {7, 12}};
  });
  EXPECT_NE(e.find("thoracic_segments: needs at least 3"), std::string::npos) << e;
}

TEST(AnatomyParams, OverlappingRibsAreRejectedNamingTheLevels) {
  // rib 6 made 40 mm tall: it runs into rib 5 next to the spine
  const std::string e = errorOf([](nlohmann::json& j) { j["ribs"][5]["height_mm"] = 40; });
  EXPECT_NE(e.find("ribs[4] and ribs[5] overlap"), std::string::npos) << e;
}

TEST(AnatomyParams, BadGainsAreRejectedNamingTheFile) {
  for (const char* field :
       {"/groups/diaphragm/kpe", "/shoulder_springs/suspension_kpe", "/scapulothoracic/kpe", "/scalenes/kac",
        "/first_costal_cartilage_stiffness_scale"}) {
    nlohmann::json g = nlohmann::json::parse(read(kDir + "muscle_gains.json"));
    g[nlohmann::json::json_pointer(field)] = -1;
    std::string name = std::string(field).substr(1);
    std::replace(name.begin(), name.end(), '/', '.');
    try {
      parseAnatomy(read(kDir + "male.json"), g.dump(), "male.json", "muscle_gains.json");
      ADD_FAILURE() << "negative gain accepted: " << field;
    } catch (const sim::Error& e) {
      EXPECT_NE(std::string(e.what()).find("muscle_gains.json: " + name), std::string::npos) << e.what();
    }
  }
}

// typos, duplicates, huge numbers and deep nesting in the anatomy and the gains give clear errors
TEST(AnatomyParams, StrictJsonNamesTheKeyAndPath) {
  EXPECT_EQ(errorOf([](nlohmann::json& j) { j["sternum"]["body_lenght_mm"] = 1; }),
            "male.json: sternum.body_lenght_mm: unknown field (did you mean body_length_mm?)");
  EXPECT_EQ(errorOf([](nlohmann::json& j) { j["ribs"][2]["posterior_ratio"] = 7; }),
            "male.json: ribs[2].posterior_ratio: must be in [0.05, 5], got 7");
  EXPECT_EQ(errorOf([](nlohmann::json& j) { j["resolution"]["ring_nodes"] = 4294967312LL; }),
            "male.json: resolution.ring_nodes: must be an integer in [8, 96], got 4294967312");
  auto parseError = [](const std::string& anatomy, const std::string& gains) {
    try {
      parseAnatomy(anatomy, gains, "male.json", "muscle_gains.json");
    } catch (const sim::Error& e) {
      return std::string(e.what());
    }
    return std::string("accepted");
  };
  const std::string male = read(kDir + "male.json");
  const std::string gains = read(kDir + "muscle_gains.json");
  EXPECT_EQ(parseError("{\"name\": \"a\", \"name\": \"b\"}", gains), "male.json: name: duplicate key");
  EXPECT_EQ(parseError("{\"bone_density_kg_m3\": 1e400}", gains),
            "male.json: bone_density_kg_m3: number 1e400 is beyond the range of a double");
  EXPECT_NE(parseError(std::string(5000, '[') + std::string(5000, ']'), gains).find("nesting deeper than 64"),
            std::string::npos);
  nlohmann::json g = nlohmann::json::parse(gains);
  g["groups"]["rectus"]["kpee"] = 1.0;
  EXPECT_EQ(parseError(male, g.dump()),
            "muscle_gains.json: groups.rectus.kpee: unknown field (did you mean kpe?)");
  g = nlohmann::json::parse(gains);
  g["groups"]["biceps"] = g["groups"]["rectus"];
  EXPECT_EQ(parseError(male, g.dump()), "muscle_gains.json: groups.biceps: unknown muscle group");
}

TEST(AnatomyParams, MalformedJsonAndMissingFileAreErrors) {
  EXPECT_THROW(parseAnatomy("{ not json", read(kDir + "muscle_gains.json")), sim::Error);
  EXPECT_THROW(loadAnatomy(kDir + "does_not_exist.json"), sim::Error);
}

// degenerate anatomy (issue 15, class 6): a length of 1e-12 mm made TetGen crash (SIGSEGV) on the flattened
// gut; every length now has a lower bound as well as an upper one
TEST(AnatomyParams, DegenerateLengthsAreRefusedBeforeMeshing) {
  EXPECT_EQ(errorOf([](nlohmann::json& j) { j["abdomen"]["inner_width_mm"] = 1e-12; }),
            "male.json: abdomen.inner_width_mm: must be in [60, 600], got 1e-12");
  EXPECT_EQ(errorOf([](nlohmann::json& j) { j["ribs"][4]["thickness_mm"] = 1e-9; }),
            "male.json: ribs[4].thickness_mm: must be in [1, 20], got 1e-09");
  EXPECT_EQ(errorOf([](nlohmann::json& j) { j["spine"]["thoracic_body_heights_mm"][3] = 0.001; }),
            "male.json: spine.thoracic_body_heights_mm[3]: must be in [4, 40], got 0.001");
  EXPECT_EQ(errorOf([](nlohmann::json& j) { j["pelvis"]["asis_depth_mm"] = 2; }),
            "male.json: pelvis.asis_depth_mm: must be in [30, 300], got 2");
}

}  // namespace
}  // namespace pneuma::meshing
