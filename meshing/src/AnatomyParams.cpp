#include "pneuma/meshing/AnatomyParams.h"

#include "pneuma/sim/Error.h"

#include <nlohmann/json.hpp>

#include <cmath>
#include <fstream>
#include <sstream>

namespace pneuma::meshing {

namespace {

using nlohmann::json;
constexpr double kMm = 1e-3;                 // [m/mm]
constexpr double kDeg = 3.14159265358979323846 / 180.0;  // [rad/deg]

/// Reads numbers and sub-objects of one JSON object, naming "<file>: <path>.<key>" in every error.
class Reader {
 public:
  Reader(const json& j, std::string path) : m_j(j), m_path(std::move(path)) {
    if (!m_j.is_object()) fail(m_path, "must be an object");
  }

  [[noreturn]] static void fail(const std::string& field, const std::string& why) {
    throw sim::Error(field + ": " + why);
  }
  std::string field(const std::string& key) const { return m_path + "." + key; }

  const json& get(const std::string& key) const {
    auto it = m_j.find(key);
    if (it == m_j.end()) fail(field(key), "missing");
    return *it;
  }
  Reader child(const std::string& key) const { return Reader(get(key), field(key)); }

  /// a finite number in [lo, hi]
  double number(const std::string& key, double lo, double hi) const {
    const json& v = get(key);
    if (!v.is_number()) fail(field(key), "must be a number");
    const double x = v.get<double>();
    if (!std::isfinite(x) || x < lo || x > hi) {
      std::ostringstream s;
      s << "must be in [" << lo << ", " << hi << "], got " << x;
      fail(field(key), s.str());
    }
    return x;
  }
  /// a finite number > 0 (and <= hi)
  double positive(const std::string& key, double hi) const {
    const double x = number(key, -1e300, hi);
    if (!(x > 0.0)) {
      std::ostringstream s;
      s << "must be > 0, got " << x;
      fail(field(key), s.str());
    }
    return x;
  }
  int integer(const std::string& key, int lo, int hi) const {
    const json& v = get(key);
    if (!v.is_number_integer()) fail(field(key), "must be an integer");
    const long long x = v.get<long long>();
    if (x < lo || x > hi) {
      fail(field(key), "must be in [" + std::to_string(lo) + ", " + std::to_string(hi) + "], got " +
                           std::to_string(x));
    }
    return static_cast<int>(x);
  }
  bool boolean(const std::string& key) const {
    const json& v = get(key);
    if (!v.is_boolean()) fail(field(key), "must be true or false");
    return v.get<bool>();
  }
  /// an array of `count` positive lengths in mm, returned in m
  std::vector<double> lengthsMm(const std::string& key, std::size_t count, double hiMm) const {
    const json& v = get(key);
    if (!v.is_array() || v.size() != count) {
      fail(field(key), "must be an array of " + std::to_string(count) + " numbers");
    }
    std::vector<double> out;
    for (std::size_t i = 0; i < count; ++i) {
      const json wrapper = {{"v", v[i]}};
      out.push_back(Reader(wrapper, field(key) + "[" + std::to_string(i) + "]").positive("v", hiMm) * kMm);
    }
    return out;
  }
  std::array<double, 2> pairMm(const std::string& key, double hiMm) const {
    const std::vector<double> v = lengthsMm(key, 2, hiMm);
    return {v[0], v[1]};
  }

 private:
  const json& m_j;
  std::string m_path;
};

json parseJson(const std::string& text, const std::string& source) {
  try {
    return json::parse(text);
  } catch (const json::parse_error& e) {
    throw sim::Error(source + ": not valid JSON: " + e.what());
  }
}

std::string readText(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw sim::Error(path + ": cannot open file");
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

RibLevel readRib(const Reader& r) {
  RibLevel rib;
  rib.arcLength = r.positive("arc_length_mm", 600.0) * kMm;
  rib.posteriorRatio = r.positive("posterior_ratio", 5.0);
  rib.anteriorRatio = r.positive("anterior_ratio", 5.0);
  rib.endAngle = r.number("end_angle_deg", 180.0, 330.0) * kDeg;
  rib.inclination = r.number("inclination_deg", -10.0, 80.0) * kDeg;
  rib.lateralTilt = r.number("lateral_tilt_deg", -30.0, 60.0) * kDeg;
  rib.height = r.positive("height_mm", 40.0) * kMm;
  rib.thickness = r.positive("thickness_mm", 20.0) * kMm;
  if (rib.thickness > rib.height) Reader::fail(r.field("thickness_mm"), "must not exceed height_mm");
  return rib;
}

SpineParams readSpine(const Reader& r) {
  SpineParams s;
  s.lumbarHeights = r.lengthsMm("lumbar_body_heights_mm", 5, 60.0);
  s.thoracicHeights = r.lengthsMm("thoracic_body_heights_mm", 12, 40.0);
  s.lumbarDisc = r.positive("lumbar_disc_mm", 20.0) * kMm;
  s.thoracicDisc = r.positive("thoracic_disc_mm", 15.0) * kMm;
  s.lumbarBody = r.pairMm("lumbar_body_width_depth_mm", 80.0);
  s.thoracicBodyTop = r.pairMm("t1_body_width_depth_mm", 80.0);
  s.thoracicBodyBottom = r.pairMm("t12_body_width_depth_mm", 80.0);
  s.kyphosis = r.number("kyphosis_mm", 0.0, 80.0) * kMm;
  s.spinousLength = r.positive("spinous_process_mm", 100.0) * kMm;
  const json& segs = r.get("thoracic_segments");
  const std::string segField = r.field("thoracic_segments");
  if (!segs.is_array() || segs.size() < 3) Reader::fail(segField, "needs at least 3 articulated segments");
  int expected = 1;
  for (std::size_t i = 0; i < segs.size(); ++i) {
    const std::string f = segField + "[" + std::to_string(i) + "]";
    if (!segs[i].is_array() || segs[i].size() != 2 || !segs[i][0].is_number_integer() ||
        !segs[i][1].is_number_integer()) {
      Reader::fail(f, "must be [first, last] vertebra numbers");
    }
    const int first = segs[i][0].get<int>();
    const int last = segs[i][1].get<int>();
    if (first != expected || last < first || last > 12) {
      Reader::fail(f, "must continue at T" + std::to_string(expected) + " and end at or before T12");
    }
    s.thoracicSegments.push_back({first, last});
    expected = last + 1;
  }
  if (expected != 13) Reader::fail(segField, "must cover T1..T12");
  return s;
}

SternumParams readSternum(const Reader& r) {
  SternumParams s;
  s.manubriumLength = r.positive("manubrium_length_mm", 120.0) * kMm;
  s.bodyLength = r.positive("body_length_mm", 200.0) * kMm;
  s.xiphoidLength = r.positive("xiphoid_length_mm", 100.0) * kMm;
  s.manubriumWidth = r.positive("manubrium_width_mm", 120.0) * kMm;
  s.bodyWidth = r.positive("body_width_mm", 80.0) * kMm;
  s.thickness = r.positive("thickness_mm", 30.0) * kMm;
  s.notchLevel = r.number("jugular_notch_vertebra", 1.0, 5.0);
  s.notchDepth = r.positive("jugular_notch_depth_mm", 300.0) * kMm;
  s.inclination = r.number("inclination_deg", 0.0, 60.0) * kDeg;
  return s;
}

PelvisParams readPelvis(const Reader& r) {
  PelvisParams p;
  p.width = r.positive("bi_iliac_breadth_mm", 500.0) * kMm;
  p.depth = r.positive("asis_depth_mm", 300.0) * kMm;
  p.height = r.positive("iliac_height_mm", 250.0) * kMm;
  return p;
}

AbdomenParams readAbdomen(const Reader& r) {
  AbdomenParams a;
  a.floorLevel = r.number("pelvic_floor_z_mm", -300.0, 0.0) * kMm;
  a.width = r.positive("inner_width_mm", 600.0) * kMm;
  a.anteriorDepth = r.positive("anterior_depth_mm", 400.0) * kMm;
  a.posteriorDepth = r.positive("posterior_depth_mm", 200.0) * kMm;
  a.domeHeight = r.positive("dome_height_mm", 200.0) * kMm;
  a.tendonFraction = r.number("central_tendon_fraction", 0.05, 0.8);
  a.umbilicusLevel = r.number("umbilicus_z_mm", 0.0, 400.0) * kMm;
  return a;
}

Resolution readResolution(const Reader& r) {
  Resolution res;
  res.boneEdge = r.number("bone_edge_mm", 1.0, 30.0) * kMm;
  res.wallRings = r.integer("wall_rings", 3, 40);
  res.ringNodes = r.integer("ring_nodes", 8, 96);
  res.domeRings = r.integer("dome_rings", 2, 30);
  res.domeRimNodes = r.integer("dome_rim_nodes", 8, 128);
  res.intercostalSamples = r.integer("intercostal_samples", 1, 60);
  return res;
}

Gains readGains(const json& j, const std::string& source) {
  const Reader r(j, source);
  Gains g;
  g.referenceLength = r.positive("reference_length_m", 1.0);
  const Reader groups = r.child("groups");
  for (int i = 0; i < sim::kElementGroupCount; ++i) {
    const Reader gr = groups.child(sim::groupName(static_cast<sim::ElementGroup>(i)));
    GroupGains& gg = g.group[static_cast<std::size_t>(i)];
    gg.kac = gr.number("kac", 0.0, 1e9);
    gg.kpe = gr.number("kpe", 0.0, 1e9);
    gg.damping = gr.number("b", 0.0, 1e9);
  }
  if (g.group[static_cast<std::size_t>(sim::ElementGroup::Cartilage)].kpe <= 0.0) {
    Reader::fail(groups.field("cartilage.kpe"), "must be > 0 (cartilage holds the ribs to the sternum)");
  }
  g.gutKappa = r.positive("gut_kappa_pa", 1e9);
  g.gutDrag = r.number("gut_drag_per_s", 0.0, 1e3);
  g.wallMass = r.positive("gut_wall_mass_kg", 100.0);
  g.diaphragmMass = r.positive("diaphragm_mass_kg", 10.0);
  const Reader joints = r.child("joints");
  g.costovertebralFriction = joints.number("costovertebral_friction", 0.0, 1e6);
  g.costovertebralStiffness = joints.number("costovertebral_stiffness", 0.0, 1e6);
  g.spineFriction = joints.number("spine_friction", 0.0, 1e6);
  g.spineStiffness = joints.number("spine_stiffness", 0.0, 1e6);
  return g;
}

std::string directoryOf(const std::string& path) {
  const std::size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? std::string(".") : path.substr(0, slash);
}

}  // namespace

AnatomyParams parseAnatomy(const std::string& anatomyText, const std::string& gainsText,
                           const std::string& sourceName, const std::string& gainsName) {
  const json j = parseJson(anatomyText, sourceName);
  const Reader r(j, sourceName);
  AnatomyParams a;
  a.source = sourceName;
  const json& name = r.get("name");
  if (!name.is_string() || name.get<std::string>().empty()) Reader::fail(r.field("name"), "must be a non-empty string");
  a.name = name.get<std::string>();
  a.boneDensity = r.number("bone_density_kg_m3", 100.0, 5000.0);
  a.areFloatingRibsMoving = r.boolean("floating_ribs_moving");

  // rib levels 1..12, in order
  const json& ribs = r.get("ribs");
  if (!ribs.is_array() || ribs.size() != 12) {
    Reader::fail(r.field("ribs"), "must list 12 rib levels, got " +
                                      std::to_string(ribs.is_array() ? ribs.size() : 0));
  }
  for (std::size_t i = 0; i < ribs.size(); ++i) {
    a.ribs.push_back(readRib(Reader(ribs[i], r.field("ribs") + "[" + std::to_string(i) + "]")));
  }
  a.spine = readSpine(r.child("spine"));
  a.sternum = readSternum(r.child("sternum"));
  a.pelvis = readPelvis(r.child("pelvis"));
  a.abdomen = readAbdomen(r.child("abdomen"));
  a.resolution = readResolution(r.child("resolution"));
  a.gains = readGains(parseJson(gainsText, gainsName), gainsName);
  return a;
}

AnatomyParams loadAnatomy(const std::string& path) {
  const std::string text = readText(path);
  const json j = parseJson(text, path);
  auto it = j.find("gains");
  if (it == j.end() || !it->is_string()) throw sim::Error(path + ".gains: must name the gains file");
  const std::string gainsPath = directoryOf(path) + "/" + it->get<std::string>();
  return parseAnatomy(text, readText(gainsPath), path, gainsPath);
}

}  // namespace pneuma::meshing
