#include "pneuma/meshing/AnatomyParams.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <sstream>
#include <utility>

#include "pneuma/sim/Error.h"
#include "pneuma/sim/JsonReader.h"

namespace pneuma::meshing {

namespace {

constexpr double kMm = 1e-3;                             // [m/mm]
constexpr double kDeg = 3.14159265358979323846 / 180.0;  // [rad/deg]
constexpr double kPaPerCmH2O = 98.0665;                  // [Pa/cmH2O]

using Reader = sim::JsonReader;

/// an array of `count` lengths in [loMm, hiMm] mm, returned in m. Every length has a lower bound as well as
/// an upper one: a body part of 1e-12 mm would reach the mesher as a degenerate surface.
std::vector<double> lengthsMm(const Reader& v, std::size_t count, double loMm, double hiMm) {
  if (!v.isArray() || v.size() != count) v.fail("must be an array of " + std::to_string(count) + " numbers");
  std::vector<double> out;
  for (std::size_t i = 0; i < count; ++i) out.push_back(v[i].numberIn(loMm, hiMm) * kMm);
  return out;
}
std::array<double, 2> pairMm(const Reader& v, double loMm, double hiMm) {
  const std::vector<double> l = lengthsMm(v, 2, loMm, hiMm);
  return {l[0], l[1]};
}
double mm(const Reader& v, double loMm, double hiMm) { return v.numberIn(loMm, hiMm) * kMm; }
int count(const Reader& v, int lo, int hi) { return static_cast<int>(v.integerIn(lo, hi)); }

std::string readText(const std::string& path) { return sim::readInputFile(path); }

RibLevel readRib(const Reader& r, std::size_t i) {
  r.allowKeys({"level", "arc_length_mm", "posterior_ratio", "anterior_ratio", "end_angle_deg",
               "inclination_deg", "lateral_tilt_deg", "height_mm", "thickness_mm", "neck_axis_deg"});
  if (r.has("level") && r.at("level").integerIn(1, 12) != static_cast<std::int64_t>(i + 1))
    r.at("level").fail("must be " + std::to_string(i + 1) + " (the ribs are listed in order)");
  RibLevel rib;
  rib.arcLength = mm(r.at("arc_length_mm"), 30.0, 600.0);
  rib.posteriorRatio = r.at("posterior_ratio").numberIn(0.05, 5.0);
  rib.anteriorRatio = r.at("anterior_ratio").numberIn(0.05, 5.0);
  rib.endAngle = r.at("end_angle_deg").numberIn(180.0, 330.0) * kDeg;
  rib.inclination = r.at("inclination_deg").numberIn(-10.0, 80.0) * kDeg;
  rib.lateralTilt = r.at("lateral_tilt_deg").numberIn(-30.0, 60.0) * kDeg;
  rib.height = mm(r.at("height_mm"), 2.0, 40.0);
  rib.thickness = mm(r.at("thickness_mm"), 1.0, 20.0);
  rib.neckAxis = r.at("neck_axis_deg").numberIn(0.0, 90.0) * kDeg;
  if (rib.thickness > rib.height) r.at("thickness_mm").fail("must not exceed height_mm");
  return rib;
}

SpineParams readSpine(const Reader& r) {
  r.allowKeys({"lumbar_body_heights_mm", "thoracic_body_heights_mm", "lumbar_disc_mm", "thoracic_disc_mm",
               "lumbar_body_width_depth_mm", "t1_body_width_depth_mm", "t12_body_width_depth_mm",
               "kyphosis_mm", "spinous_process_mm", "thoracic_segments"});
  SpineParams s;
  s.lumbarHeights = lengthsMm(r.at("lumbar_body_heights_mm"), 5, 5.0, 60.0);
  s.thoracicHeights = lengthsMm(r.at("thoracic_body_heights_mm"), 12, 4.0, 40.0);
  s.lumbarDisc = mm(r.at("lumbar_disc_mm"), 1.0, 20.0);
  s.thoracicDisc = mm(r.at("thoracic_disc_mm"), 1.0, 15.0);
  s.lumbarBody = pairMm(r.at("lumbar_body_width_depth_mm"), 5.0, 80.0);
  s.thoracicBodyTop = pairMm(r.at("t1_body_width_depth_mm"), 5.0, 80.0);
  s.thoracicBodyBottom = pairMm(r.at("t12_body_width_depth_mm"), 5.0, 80.0);
  s.kyphosis = r.at("kyphosis_mm").numberIn(0.0, 80.0) * kMm;
  s.spinousLength = mm(r.at("spinous_process_mm"), 5.0, 100.0);
  const Reader segs = r.at("thoracic_segments");
  if (!segs.isArray() || segs.size() < 3) segs.fail("needs at least 3 articulated segments");
  int expected = 1;
  for (std::size_t i = 0; i < segs.size(); ++i) {
    const Reader seg = segs[i];
    if (!seg.isArray() || seg.size() != 2) seg.fail("must be [first, last] vertebra numbers");
    const int first = count(seg[0], 1, 12);
    const int last = count(seg[1], 1, 12);
    if (first != expected || last < first)
      seg.fail("must continue at T" + std::to_string(expected) + " and end at or before T12");
    s.thoracicSegments.push_back({first, last});
    expected = last + 1;
  }
  if (expected != 13) segs.fail("must cover T1..T12");
  return s;
}

SternumParams readSternum(const Reader& r) {
  r.allowKeys({"manubrium_length_mm", "body_length_mm", "xiphoid_length_mm", "manubrium_width_mm",
               "body_width_mm", "thickness_mm", "jugular_notch_vertebra", "jugular_notch_depth_mm",
               "inclination_deg"});
  SternumParams s;
  s.manubriumLength = mm(r.at("manubrium_length_mm"), 10.0, 120.0);
  s.bodyLength = mm(r.at("body_length_mm"), 20.0, 200.0);
  s.xiphoidLength = mm(r.at("xiphoid_length_mm"), 5.0, 100.0);
  s.manubriumWidth = mm(r.at("manubrium_width_mm"), 10.0, 120.0);
  s.bodyWidth = mm(r.at("body_width_mm"), 5.0, 80.0);
  s.thickness = mm(r.at("thickness_mm"), 2.0, 30.0);
  s.notchLevel = r.at("jugular_notch_vertebra").numberIn(1.0, 5.0);
  s.notchDepth = mm(r.at("jugular_notch_depth_mm"), 15.0, 300.0);
  s.inclination = r.at("inclination_deg").numberIn(0.0, 60.0) * kDeg;
  return s;
}

PelvisParams readPelvis(const Reader& r) {
  r.allowKeys({"bi_iliac_breadth_mm", "asis_depth_mm", "iliac_height_mm"});
  PelvisParams p;
  p.width = mm(r.at("bi_iliac_breadth_mm"), 80.0, 500.0);
  p.depth = mm(r.at("asis_depth_mm"), 30.0, 300.0);
  p.height = mm(r.at("iliac_height_mm"), 30.0, 250.0);
  return p;
}

AbdomenParams readAbdomen(const Reader& r) {
  r.allowKeys({"pelvic_floor_z_mm", "inner_width_mm", "anterior_depth_mm", "posterior_depth_mm",
               "dome_height_mm", "apposition_height_mm", "apposition_reach_mm", "umbilicus_z_mm"});
  AbdomenParams a;
  a.floorLevel = r.at("pelvic_floor_z_mm").numberIn(-300.0, 0.0) * kMm;
  a.width = mm(r.at("inner_width_mm"), 60.0, 600.0);
  a.anteriorDepth = mm(r.at("anterior_depth_mm"), 30.0, 400.0);
  a.posteriorDepth = mm(r.at("posterior_depth_mm"), 15.0, 200.0);
  a.domeHeight = mm(r.at("dome_height_mm"), 20.0, 200.0);
  a.appositionHeight = mm(r.at("apposition_height_mm"), 0.0, 200.0);
  if (a.appositionHeight >= a.domeHeight) r.at("apposition_height_mm").fail("must be below dome_height_mm");
  a.appositionReach = mm(r.at("apposition_reach_mm"), 1.0, 200.0);
  a.umbilicusLevel = r.at("umbilicus_z_mm").numberIn(0.0, 400.0) * kMm;
  return a;
}

Resolution readResolution(const Reader& r) {
  r.allowKeys(
      {"bone_edge_mm", "wall_rings", "ring_nodes", "dome_rings", "dome_rim_nodes", "intercostal_samples"});
  Resolution res;
  res.boneEdge = r.at("bone_edge_mm").numberIn(1.0, 30.0) * kMm;
  res.wallRings = count(r.at("wall_rings"), 3, 40);
  res.ringNodes = count(r.at("ring_nodes"), 8, 96);
  res.domeRings = count(r.at("dome_rings"), 2, 30);
  res.domeRimNodes = count(r.at("dome_rim_nodes"), 8, 128);
  res.intercostalSamples = count(r.at("intercostal_samples"), 1, 60);
  return res;
}

Gains readGains(const Reader& r) {
  r.allowKeys({"description", "reference_length_m", "groups", "gut_kappa_pa", "gut_drag_per_s",
               "abdominal_wall_tone_upright", "lung_recoil_cmh2o", "lung_compliance_l_per_cmh2o",
               "apposition_stiffness_fraction", "intercostal_external_space_scale", "gut_wall_mass_kg",
               "diaphragm_mass_kg", "joints", "shoulder_springs", "accessory_muscles", "scapulothoracic",
               "first_costal_cartilage_stiffness_scale", "scalenes", "tissue_bodies"});
  Gains g;
  g.referenceLength = r.at("reference_length_m").positiveAtMost(1.0);
  const Reader groups = r.at("groups");
  for (const std::string& key : groups.keys()) {
    sim::ElementGroup unused;
    if (!sim::groupFromName(key, unused)) groups.at(key).fail("unknown muscle group");
  }
  for (int i = 0; i < sim::kElementGroupCount; ++i) {
    const Reader gr = groups.at(sim::groupName(static_cast<sim::ElementGroup>(i)));
    gr.allowKeys({"kac", "kpe", "b"});
    GroupGains& gg = g.group[static_cast<std::size_t>(i)];
    gg.kac = gr.at("kac").numberIn(0.0, 1e9);
    gg.kpe = gr.at("kpe").numberIn(0.0, 1e9);
    gg.damping = gr.at("b").numberIn(0.0, 1e9);
  }
  if (g.group[static_cast<std::size_t>(sim::ElementGroup::Cartilage)].kpe <= 0.0)
    groups.at("cartilage").at("kpe").fail("must be > 0 (cartilage holds the ribs to the sternum)");
  g.gutKappa = r.at("gut_kappa_pa").positiveAtMost(1e9);
  g.gutDrag = r.at("gut_drag_per_s").numberIn(0.0, 1e3);
  // optional: no postural tone when absent
  if (r.has("abdominal_wall_tone_upright"))
    g.wallToneUpright = r.at("abdominal_wall_tone_upright").numberIn(0.0, 0.5);
  g.lungRecoil = r.at("lung_recoil_cmh2o").numberIn(0.0, 30.0) * kPaPerCmH2O;
  g.lungCompliance = r.at("lung_compliance_l_per_cmh2o").numberIn(0.0, 2.0) * 1e-3 / kPaPerCmH2O;
  g.appositionFraction = r.at("apposition_stiffness_fraction").numberIn(0.0, 10.0);
  // optional: the cartilage group's stiffness when absent
  if (r.has("first_costal_cartilage_stiffness_scale"))
    g.firstCartilageScale = r.at("first_costal_cartilage_stiffness_scale").numberIn(0.01, 100.0);
  // optional: passive springs with the cartilage group's gains when absent
  g.scalenes = g.group[static_cast<std::size_t>(sim::ElementGroup::Cartilage)];
  g.scalenes.kac = 0.0;
  if (r.has("scalenes")) {
    const Reader sc = r.at("scalenes");
    sc.allowKeys({"description", "kac", "kpe", "b"});
    g.scalenes.kac = sc.at("kac").numberIn(0.0, 1e9);
    g.scalenes.kpe = sc.at("kpe").numberIn(0.0, 1e9);
    g.scalenes.damping = sc.at("b").numberIn(0.0, 1e9);
  }
  // optional: 1 in every space when absent
  if (r.has("intercostal_external_space_scale")) {
    const Reader spaces = r.at("intercostal_external_space_scale");
    if (!spaces.isArray() || spaces.size() != g.externalIntercostalSpaceScale.size())
      spaces.fail("must be an array of 11 numbers, one per intercostal space (1-11)");
    for (std::size_t k = 0; k < g.externalIntercostalSpaceScale.size(); ++k)
      g.externalIntercostalSpaceScale[k] = spaces[k].numberIn(0.0, 10.0);
  }
  g.wallMass = r.at("gut_wall_mass_kg").positiveAtMost(100.0);
  g.diaphragmMass = r.at("diaphragm_mass_kg").positiveAtMost(10.0);
  // one row per kind of joint
  const Reader joints = r.at("joints");
  for (const std::string& key : joints.keys())
    if (std::find(kJointKinds.begin(), kJointKinds.end(), key) == kJointKinds.end())
      joints.at(key).fail("unknown kind of joint");
  for (std::size_t k = 0; k < kJointKinds.size(); ++k) {
    const Reader row = joints.at(kJointKinds[k]);
    row.allowKeys({"friction", "stiffness", "lock_stiffness"});
    JointGains& j = g.joints[k];
    j.friction = row.at("friction").numberIn(0.0, 1e6);
    j.stiffness = row.at("stiffness").numberIn(0.0, 1e6);
    j.lockStiffness = row.at("lock_stiffness").numberIn(0.0, 1e6);
  }
  const Reader shoulder = r.at("shoulder_springs");
  shoulder.allowKeys({"kpe", "b", "suspension_kpe"});
  g.shoulder.kpe = shoulder.at("kpe").numberIn(0.0, 1e9);
  g.shoulder.damping = shoulder.at("b").numberIn(0.0, 1e9);
  g.shoulderSuspension =
      shoulder.has("suspension_kpe") ? shoulder.at("suspension_kpe").numberIn(0.0, 1e9) : g.shoulder.kpe;
  // optional: the accessory muscles are passive shoulder springs when absent
  if (r.has("accessory_muscles")) {
    const Reader acc = r.at("accessory_muscles");
    acc.allowKeys({"description", "kac", "recruitment"});
    g.accessory.kac = acc.at("kac").numberIn(0.0, 1e9);
    g.accessory.recruitment = acc.at("recruitment").numberIn(0.0, 0.99);
  }
  // optional: no scapulothoracic springs when absent
  if (r.has("scapulothoracic")) {
    const Reader st = r.at("scapulothoracic");
    st.allowKeys({"description", "kpe", "b"});
    g.scapulothoracic.kpe = st.at("kpe").numberIn(0.0, 1e9);
    g.scapulothoracic.damping = st.at("b").numberIn(0.0, 1e9);
  }
  // optional: no tissue bodies when absent
  if (r.has("tissue_bodies")) {
    const Reader t = r.at("tissue_bodies");
    t.allowKeys({"description", "kappa_pa", "density_kg_per_m3", "surface", "tie", "pectoral_thickness_mm",
                 "deltoid_thickness_mm"});
    TissueGains& tg = g.tissue;
    tg.kappa = t.at("kappa_pa").positiveAtMost(1e9);
    tg.density = t.at("density_kg_per_m3").numberIn(100.0, 3000.0);
    for (const auto& [key, gains] :
         {std::pair<const char*, GroupGains*>{"surface", &tg.surface}, {"tie", &tg.tie}}) {
      const Reader s = t.at(key);
      s.allowKeys({"kpe", "b"});
      gains->kpe = s.at("kpe").positiveAtMost(1e9);
      gains->damping = s.at("b").numberIn(0.0, 1e9);
    }
    tg.pectoralThickness = t.at("pectoral_thickness_mm").numberIn(2.0, 60.0) * 1e-3;
    tg.deltoidThickness = t.at("deltoid_thickness_mm").numberIn(2.0, 60.0) * 1e-3;
  }
  return g;
}

GirdleParams readGirdle(const Reader& r) {
  r.allowKeys({"body_mass_kg", "clavicle_length_mm", "upper_arm_length_mm", "forearm_length_mm",
               "hand_length_mm", "upper_arm_mass_fraction", "forearm_mass_fraction", "hand_mass_fraction",
               "abduction_deg", "elbow_flexion_deg"});
  GirdleParams g;
  g.bodyMass = r.at("body_mass_kg").numberIn(20.0, 300.0);
  g.clavicleLength = mm(r.at("clavicle_length_mm"), 60.0, 300.0);
  g.upperArmLength = mm(r.at("upper_arm_length_mm"), 100.0, 600.0);
  g.forearmLength = mm(r.at("forearm_length_mm"), 100.0, 600.0);
  g.handLength = mm(r.at("hand_length_mm"), 50.0, 400.0);
  g.upperArmMassFraction = r.at("upper_arm_mass_fraction").numberIn(0.001, 0.2);
  g.forearmMassFraction = r.at("forearm_mass_fraction").numberIn(0.001, 0.2);
  g.handMassFraction = r.at("hand_mass_fraction").numberIn(0.001, 0.2);
  g.abduction = r.at("abduction_deg").numberIn(0.0, 90.0) * kDeg;
  g.elbowFlexion = r.at("elbow_flexion_deg").numberIn(0.0, 120.0) * kDeg;
  return g;
}

std::string directoryOf(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? std::string(".") : path.substr(0, slash);
}

}  // namespace

AnatomyParams parseAnatomy(const std::string& anatomyText, const std::string& gainsText,
                           const std::string& sourceName, const std::string& gainsName) {
  const sim::JsonDocument doc = sim::JsonDocument::parse(anatomyText, sourceName);
  const Reader r = doc.root();
  r.allowKeys({"name", "description", "gains", "bone_density_kg_m3", "floating_ribs_moving",
               "rib_joint_friction_scale", "ribs", "spine", "sternum", "pelvis", "abdomen", "resolution",
               "shoulder_girdle", "girdle"});
  AnatomyParams a;
  a.source = sourceName;
  a.name = r.at("name").string();
  if (a.name.empty()) r.at("name").fail("must be a non-empty string");
  a.boneDensity = r.at("bone_density_kg_m3").numberIn(100.0, 5000.0);
  a.areFloatingRibsMoving = r.at("floating_ribs_moving").boolean();
  // optional: the shared friction when absent
  if (r.has("rib_joint_friction_scale"))
    a.ribJointFrictionScale = r.at("rib_joint_friction_scale").numberIn(0.1, 10.0);

  // rib levels 1..12, in order
  const Reader ribs = r.at("ribs");
  if (!ribs.isArray() || ribs.size() != 12)
    ribs.fail("must list 12 rib levels, got " + std::to_string(ribs.isArray() ? ribs.size() : 0));
  for (std::size_t i = 0; i < ribs.size(); ++i) a.ribs.push_back(readRib(ribs[i], i));
  a.spine = readSpine(r.at("spine"));
  a.sternum = readSternum(r.at("sternum"));
  a.pelvis = readPelvis(r.at("pelvis"));
  a.abdomen = readAbdomen(r.at("abdomen"));
  a.resolution = readResolution(r.at("resolution"));
  a.gains = readGains(sim::JsonDocument::parse(gainsText, gainsName).root());
  // optional: no shoulder girdle when absent
  if (r.has("shoulder_girdle")) a.hasShoulderGirdle = r.at("shoulder_girdle").boolean();
  if (r.has("girdle") || a.hasShoulderGirdle) a.girdle = readGirdle(r.at("girdle"));
  return a;
}

AnatomyParams loadAnatomy(const std::string& path) {
  const std::string text = readText(path);
  const sim::JsonDocument doc = sim::JsonDocument::parse(text, path);
  const Reader gains = doc.root().at("gains");
  if (!gains.isString()) gains.fail("must name the gains file");
  const std::string gainsPath = directoryOf(path) + "/" + gains.string();
  return parseAnatomy(text, readText(gainsPath), path, gainsPath);
}

}  // namespace pneuma::meshing
