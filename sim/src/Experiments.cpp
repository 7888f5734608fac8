#include "pneuma/sim/Experiments.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <sstream>

#include "pneuma/sim/Error.h"
#include "pneuma/sim/PosedGeometry.h"
#include "pneuma/sim/Scenario.h"
#include "pneuma/sim/Silhouette.h"
#include "pneuma/sim/State.h"
#include "pneuma/sim/Step.h"

namespace pneuma::sim {

namespace {

constexpr double kMl = 1e6;   // [mL/m^3]
constexpr double kMm = 1e3;   // [mm/m]
constexpr double kPct = 1e2;  // [%/1]
constexpr double kBig = std::numeric_limits<double>::infinity();
const std::string kZordan = "Zordan et al. 2004";

Check check(std::string id, std::string what, std::string target, std::string source, std::string unit,
            double measured, double lower, double upper) {
  Check c;
  c.id = std::move(id);
  c.what = std::move(what);
  c.target = std::move(target);
  c.source = std::move(source);
  c.unit = std::move(unit);
  c.measured = measured;
  c.lower = lower;
  c.upper = upper;
  return c;
}

// the highest moving thoracic body, or -1
int spineTopBody(const Model& model) {
  int spine = -1;
  for (int b = 0; b < model.bodies.size(); ++b) {
    if (model.bodies.isFixed[static_cast<std::size_t>(b)] ||
        model.bodies.name[static_cast<std::size_t>(b)].rfind("thoracic", 0) != 0)
      continue;
    if (spine < 0 || model.bodies.com(2, b) > model.bodies.com(2, spine)) spine = b;
  }
  return spine;
}

// index of the last frame of the settling phase
std::size_t settledFrame(const StyleRun& r) {
  std::size_t ref = 0;
  while (ref + 1 < r.trace.size() && r.trace.time[ref + 1] <= r.settleTime) ++ref;
  return ref;
}

// a controller holding every muscle relaxed
class RelaxedController : public Controller {
 public:
  Activations activations(double, const Metrics&) override { return relaxedActivations(); }
  std::string describe() const override { return "relaxed"; }
  std::unique_ptr<Controller> clone() const override { return std::make_unique<RelaxedController>(*this); }
};

}  // namespace

StyleRun runBreathStyle(std::shared_ptr<const Model> model, const BreathStyle& style,
                        const ExperimentSettings& settings, double frictionScale) {
  StyleRun r;
  r.style = style;
  r.frictionScale = frictionScale;
  r.settleTime = settings.simulation.settleTime;
  r.umbilicus = model->landmarks.find("umbilicus");
  r.xiphoid = model->landmarks.find("xiphoid");
  const int spine = spineTopBody(*model);
  if (spine >= 0) r.spineBody = model->bodies.name[static_cast<std::size_t>(spine)];
  // the rib joints' friction (Eq. 3) scaled in a copy of the model; the shoulder girdle's joints keep theirs
  if (frictionScale != 1.0) {
    auto scaled = std::make_shared<Model>(*model);
    for (int j = 0; j < scaled->joints.size(); ++j)
      if (scaled->joints.name[static_cast<std::size_t>(j)].rfind("costovertebral", 0) == 0)
        scaled->joints.friction(j) *= frictionScale;
    model = std::move(scaled);
  }
  r.model = model;
  const SimulationOptions& o = settings.simulation;
  Simulation sim(std::move(model), std::make_unique<BreathStyleController>(style), o);
  const double duration = style.cycles > 0 ? settings.forcedExhaleDuration : settings.styleDuration;
  // the last full cycle after settling, [first, last] [s], whose end-inspiration and end-expiration are kept
  const double period = 60.0 / style.breathsPerMinute;  // [s]
  int cycles = static_cast<int>(std::floor(duration / period + 1e-9));
  if (style.cycles > 0) cycles = std::min(cycles, style.cycles);
  const double first = o.settleTime + (cycles - 1) * period, last = o.settleTime + cycles * period;
  double high = -kBig, low = kBig;  // [m^3]
  sim.advance(o.settleTime + duration, [&](const Simulation& s) {
    r.spineTop.push_back(spine >= 0 ? Eigen::Vector3d(s.state().bodyPosition.col(spine))
                                    : Eigen::Vector3d::Zero());
    const double t = s.state().time, v = s.latestMetrics().lungVolume;
    if (cycles > 0 && t >= first - 1e-9 && t <= last + 1e-9) {
      // the largest volume, then the smallest after it
      if (v > high) {
        high = v;
        low = kBig;
        r.endInspiration = s.state();
      } else if (v < low) {
        low = v;
        r.endExpiration = s.state();
      }
    }
    return true;
  });
  r.hasBreathPoses = high > -kBig && low < kBig;
  r.endInspirationVolume = high;
  r.endExpirationVolume = low;
  r.summary = sim.summary();
  r.trace = sim.trace();
  // the trace may hold a frame at t = 0 that precedes the first callback
  while (r.spineTop.size() < r.trace.size())
    r.spineTop.insert(r.spineTop.begin(), r.spineTop.empty() ? Eigen::Vector3d::Zero() : r.spineTop.front());
  return r;
}

std::vector<Check> breathStyleChecks(const std::vector<StyleRun>& runs) {
  std::map<std::string, const StyleRun*> byName;
  for (const StyleRun& r : runs)
    if (r.frictionScale == 1.0) byName[r.style.name] = &r;
  auto find = [&](const char* name) { return byName.count(name) ? byName[name] : nullptr; };
  const StyleRun* calm = find("calm");
  const StyleRun* deep = find("deep");
  const StyleRun* panting = find("panting");
  const StyleRun* forced = find("forced-exhale");
  std::vector<Check> out;

  // Section 6.2 / Figure 4 caption: "a tolerable error less than 2 percent during our results for breathing"
  for (const StyleRun* r : {calm, deep, panting, forced})
    if (r)
      out.push_back(check(r->style.name + ".gut_volume_error", "max gut volume error, " + r->style.name,
                          "< 2 %", kZordan + ", Sec. 6.2, Fig. 4 caption", "%",
                          r->summary.maxGutVolumeError * kPct, 0.0, 2.0));

  // Figure 6: calm tidal volume "almost perfectly on the 500 mL average"; Table 2: 15 b/m
  if (calm) {
    out.push_back(check("calm.tidal_volume", "tidal volume, calm", "500 +/- 50 mL",
                        kZordan + ", Sec. 8.1, Fig. 6", "mL", calm->summary.tidalVolume * kMl, 450.0, 550.0));
    out.push_back(check("calm.rate", "breathing rate, calm", "15 +/- 0.5 b/m", kZordan + ", Table 2", "b/m",
                        calm->summary.breathsPerMinute, 14.5, 15.5));
    // quiet expiration is the passive recoil of lungs and chest wall, damped by the airways: the volume falls
    // without bouncing back (West, Respiratory Physiology, ch. 7). Our bound: 2 % of the calm breath
    out.push_back(check("calm.expiration_rebound",
                        "largest rise of the lung volume during an exhale, after its peak, calm",
                        "< 10 mL (the volume falls without bouncing)", "West, Respiratory Physiology, ch. 7",
                        "mL", expirationRebound(*calm) * kMl, 0.0, 10.0));
  }

  // Table 2 slow/deep: 12 b/m; between 600 mL (clearly above the 500 mL calm breath; the paper's own deep
  // breath in Fig. 6 lies between 500 mL and the plot's 800 mL top) and 3 L, the inspiratory capacity of
  // a healthy adult (West, Respiratory Physiology, ch. 2), the largest breath that can be drawn
  if (deep) {
    out.push_back(
        check("deep.tidal_volume", "tidal volume, deep",
              "600 - 3000 mL (above calm, up to the inspiratory capacity)",
              kZordan + ", Sec. 8.1 'slow deep breath', Fig. 6; West, Respiratory Physiology, ch. 2", "mL",
              deep->summary.tidalVolume * kMl, 600.0, 3000.0));
    out.push_back(check("deep.rate", "breathing rate, deep", "12 +/- 0.5 b/m", kZordan + ", Table 2", "b/m",
                        deep->summary.breathsPerMinute, 11.5, 12.5));
    if (calm)
      out.push_back(check("deep.above_calm", "tidal volume deep minus calm", "> 0 mL",
                          kZordan + ", Sec. 8.1, Fig. 6", "mL",
                          (deep->summary.tidalVolume - calm->summary.tidalVolume) * kMl, 1e-9, kBig));
  }

  // Section 8.1 panting: 60 b/m, "small rapid inhales and exhales where most of the motion is seen in the
  // chest"
  if (panting) {
    out.push_back(check("panting.rate", "breathing rate, panting", "60 +/- 1 b/m", kZordan + ", Table 2",
                        "b/m", panting->summary.breathsPerMinute, 59.0, 61.0));
    if (calm) {
      out.push_back(check("panting.below_calm", "tidal volume calm minus panting", "> 0 mL (small breaths)",
                          kZordan + ", Sec. 8.1 'panting breathing'", "mL",
                          (calm->summary.tidalVolume - panting->summary.tidalVolume) * kMl, 1e-9, kBig));
      // the motion seen from the side (Fig. 5's silhouette): the breath's anterior excursions of chest and
      // belly, end-inspiration minus end-expiration over the full cycles (Motion), not ranges over the run,
      // which would count the slow drift after settling as breathing
      const auto apRatio = [](const StyleRun& r) {
        const Motion& m = r.summary.motion;
        return m.xiphoidAnterior / std::max(m.umbilicusAnterior, 1e-12);
      };
      const double pantRatio = apRatio(*panting), calmRatio = apRatio(*calm);
      out.push_back(check("panting.chest_dominant",
                          "xiphoid/umbilicus anterior-posterior excursion ratio, panting minus calm",
                          "> 0 (motion mostly in the chest)", kZordan + ", Sec. 8.1 'panting breathing'", "-",
                          pantRatio - calmRatio, 1e-12, kBig));
    }
  }

  // Section 8.1 / Figure 5 forced exhale: below calm end-expiration; the rectus pulls the abdomen in
  // (umbilicus posterior by >= 1 cm) and the lower ribcage down (xiphoid down), from the settled pose
  if (forced && !forced->trace.time.empty() && forced->umbilicus >= 0 && forced->xiphoid >= 0) {
    const Trace& t = forced->trace;
    const std::size_t ref = settledFrame(*forced);
    double minVolume = t.lungVolume[ref], minUmbY = 0.0, minXiphZ = 0.0;
    for (std::size_t i = ref; i < t.size(); ++i) {
      minVolume = std::min(minVolume, t.lungVolume[i]);
      minUmbY =
          std::min(minUmbY, t.landmarks[i](1, forced->umbilicus) - t.landmarks[ref](1, forced->umbilicus));
      minXiphZ =
          std::min(minXiphZ, t.landmarks[i](2, forced->xiphoid) - t.landmarks[ref](2, forced->xiphoid));
    }
    const std::string fig5 = kZordan + ", Sec. 8.1 'forced exhale', Fig. 5";
    if (calm)
      out.push_back(check("forced_exhale.below_calm",
                          "calm end-expiratory volume minus lowest forced-exhale volume", "> 0 mL", fig5,
                          "mL", (calm->summary.endExpiratoryVolume - minVolume) * kMl, 1e-9, kBig));
    out.push_back(check("forced_exhale.umbilicus", "umbilicus anterior displacement (most posterior)",
                        "<= -10 mm", fig5, "mm", minUmbY * kMm, -kBig, -10.0));
    out.push_back(check("forced_exhale.xiphoid", "xiphoid vertical displacement (lowest)",
                        "< -1 mm (ribcage pulled down)", fig5, "mm", minXiphZ * kMm, -kBig, -1.0));
  }
  return out;
}

std::vector<RibMotion> ribMotions(const StyleRun& r) {
  std::vector<RibMotion> out;
  if (!r.hasBreathPoses || !r.model) return out;
  const Model& m = *r.model;
  const State& a = r.endExpiration;
  const State& b = r.endInspiration;
  for (int j = 0; j < m.joints.size(); ++j) {
    const auto jj = static_cast<std::size_t>(j);
    RibMotion rm;
    if (std::sscanf(m.joints.name[jj].c_str(), "costovertebral_rib%d_", &rm.level) != 1) continue;
    const int c = m.joints.child[jj], p = m.joints.parent[jj];
    rm.rib = m.bodies.name[static_cast<std::size_t>(c)];
    const Eigen::AngleAxisd turn(b.bodyOrientation[static_cast<std::size_t>(c)] *
                                 a.bodyOrientation[static_cast<std::size_t>(c)].inverse());
    rm.turn = turn.angle();
    rm.axisFromMidsagittal = std::asin(std::min(1.0, std::abs(turn.axis().x())));
    // the neck axis, signed so that turning about it lifts the rib's centre of mass (in front of the joint)
    Eigen::Vector3d neck = a.bodyOrientation[static_cast<std::size_t>(p)] * m.joints.axis.col(j);
    if (neck.cross(a.bodyPosition.col(c) - m.joints.anchor.col(j)).z() < 0.0) neck = -neck;
    rm.aboutNeck = turn.angle() * turn.axis().dot(neck);
    rm.comMotion = b.bodyPosition.col(c) - a.bodyPosition.col(c);
    out.push_back(rm);
  }
  return out;
}

std::vector<Check> physiologyChecks(const std::vector<StyleRun>& runs) {
  const StyleRun* calm = nullptr;
  const StyleRun* deep = nullptr;
  for (const StyleRun& r : runs)
    if (r.frictionScale == 1.0) {
      if (r.style.name == "calm") calm = &r;
      if (r.style.name == "deep") deep = &r;
    }
  const std::string boussuges =
      "M-mode ultrasound, quiet breathing 18 +/- 3 mm and deep breathing 70 +/- 11 mm in men "
      "(Boussuges, Gole & Blanc 2009, Chest 135:391)";
  const std::string wilson =
      "bucket-handle widening of the lower ribs (Wilson et al. 1987, J Appl Physiol 62:1872; "
      "De Troyer & Boriek 2011, Compr Physiol 1:1273)";
  std::vector<Check> out;
  if (calm) {
    const Motion& m = calm->summary.motion;
    out.push_back(check("physiology.calm.dome_descent", "dome descent (central tendon, craniocaudal), calm",
                        "12 - 25 mm", boussuges, "mm", m.domeDescent * kMm, 12.0, 25.0));
    out.push_back(check(
        "physiology.calm.umbilicus_forward", "umbilicus anterior motion, smallest over the calm breaths",
        "> 0 mm (the belly moves out on every inhale)", "Konno & Mead 1967, J Appl Physiol 22:407", "mm",
        m.umbilicusAnteriorMin * kMm, 1e-9, kBig));
    out.push_back(check("physiology.calm.lower_rib_expansion", "rib-8 lateral distance, change, calm",
                        ">= 2 mm", wilson, "mm", m.lowerRibExpansion * kMm, 2.0, kBig));
    out.push_back(check(
        "physiology.calm.rib_cage_share", "rib-cage share of the tidal volume, calm, upright", "55 - 85 %",
        "seated at rest the abdomen gives about a quarter (J Appl Physiol 1968, 24:159); rib cage dominant "
        "upright (Sharp et al. 1975, J Appl Physiol 39:608)",
        "%", kPct * m.ribCageShare(), 55.0, 85.0));
    out.push_back(check("physiology.calm.phase", "rib-cage / abdomen phase angle, calm", "< 30 deg",
                        "12-23 deg in healthy young adults (Chen et al. 2015)", "deg",
                        m.phaseAngle * 180.0 / M_PI, 0.0, 30.0));
    // the sternum moves forward and up at both ends (pump handle), the ribs turn about axes near their necks,
    // and rib 1 rises with them instead of being pulled down by the first space's intercostals
    out.push_back(check("physiology.calm.sternum_forward_up",
                        "sternum motion, calm: the smallest of the jugular notch's and the xiphoid's "
                        "anterior and cranial motion",
                        "> 0 mm (forward and up at both ends)",
                        "the pump-handle motion: ribs 2-9 rotate up, out and forward about their neck axes "
                        "(Jordanoglou 1969, "
                        "Thorax 24:407)",
                        "mm",
                        kMm * std::min(std::min(m.sternumAnterior, m.sternumCranial),
                                       std::min(m.xiphoidAnterior, m.xiphoidCranial)),
                        1e-9, kBig));
    // rib 1's cranial motion, and the mean axis of ribs 3-7 (about 35 deg by CT)
    double firstRibCranial = 0.0, axisAngle = 0.0;
    int nFirst = 0, nAxis = 0;
    for (const RibMotion& rm : ribMotions(*calm)) {
      if (rm.level == 1) firstRibCranial += rm.comMotion.z(), ++nFirst;
      if (rm.level >= 3 && rm.level <= 7) axisAngle += rm.axisFromMidsagittal, ++nAxis;
    }
    if (nFirst > 0)
      out.push_back(check("physiology.calm.first_rib_cranial",
                          "rib 1's cranial motion (centre of mass, mean of both sides), calm",
                          "> 0 mm (rises; no paradoxical motion)",
                          "the scalenes fire with every quiet breath; without them the upper rib cage moves "
                          "paradoxically (De Troyer & Estenne 1984, J Appl Physiol 57:899)",
                          "mm", firstRibCranial / nFirst * kMm, 1e-9, kBig));
    if (nAxis > 0)
      out.push_back(check("physiology.calm.rib_axis_angle",
                          "ribs 3-7: angle of their rotation axes from the midsagittal plane, mean, calm",
                          "20 - 50 deg",
                          "about 35 deg for ribs 3-7 (CT, Wilson et al. 1987, J Appl Physiol 62:1872)", "deg",
                          axisAngle / nAxis * 180.0 / M_PI, 20.0, 50.0));
    out.push_back(check("physiology.calm.flow_reversals", "flow (dV/dt) sign changes per breath, calm", "2",
                        "a spirogram: one inspiration, one expiration", "-", m.flowSignChanges, 2.0, 2.0));
    out.push_back(check("physiology.calm.flow_jump", "largest frame-to-frame flow change, calm",
                        "<= 20 % of peak flow",
                        "smooth tidal airflow profiles (Benchetrit 2000, Respir Physiol 122:123)",
                        "% of peak", m.maxFlowJump * kPct, 0.0, 20.0));
  }
  // the other periodic styles' flow: smooth and near-sinusoidal (panting at about 1 Hz too). A pure sinusoid
  // of frequency f sampled at fs changes by up to 2 pi f / fs of its peak from one frame to the next (at 60
  // b/m and validate's 30 frames/s: 21 %), so the bound is twice that or calm's 20 %, whichever is larger
  for (const StyleRun& r : runs) {
    if (r.frictionScale != 1.0 || r.style.cycles > 0 || &r == calm || r.trace.size() < 2) continue;
    const Motion& m = r.summary.motion;
    const std::string& n = r.style.name;
    const double fs = static_cast<double>(r.trace.size() - 1) /
                      (r.trace.time.back() - r.trace.time.front());  // [1/s] frame rate
    const double bound = std::max(20.0, 2.0 * kPct * 2.0 * M_PI * r.style.breathsPerMinute / 60.0 / fs);
    std::ostringstream target;
    target << "<= " << std::lround(bound) << " % of peak flow (2 x a sinusoid's, at least 20 %)";
    out.push_back(check("physiology." + n + ".flow_reversals", "flow (dV/dt) sign changes per breath, " + n,
                        "2", "a spirogram: one inspiration, one expiration", "-", m.flowSignChanges, 2.0,
                        2.0));
    out.push_back(check("physiology." + n + ".flow_jump", "largest frame-to-frame flow change, " + n,
                        target.str(),
                        "smooth tidal airflow profiles (Benchetrit 2000, Respir Physiol 122:123)",
                        "% of peak", m.maxFlowJump * kPct, 0.0, bound));
  }
  if (deep) {
    const Motion& m = deep->summary.motion;
    if (calm)
      out.push_back(check("physiology.deep.dome_over_calm", "dome descent, deep over calm", ">= 2", boussuges,
                          "-", m.domeDescent / calm->summary.motion.domeDescent, 2.0, kBig));
    out.push_back(check("physiology.deep.dome_per_litre", "dome descent per litre inspired, deep",
                        "20 - 35 mm/L", "derived: " + boussuges + " over an inspiratory capacity of 2-3.5 L",
                        "mm/L", m.domeDescent * kMm / (deep->summary.tidalVolume * 1e3), 20.0, 35.0));
    out.push_back(check("physiology.deep.lower_rib_expansion", "rib-8 lateral distance, change, deep",
                        ">= 10 mm", wilson, "mm", m.lowerRibExpansion * kMm, 10.0, kBig));
    // the shoulders (a model with a shoulder girdle only): a deep breath lifts them visibly, a calm one
    // barely
    if (calm && std::isfinite(m.acromionCranial) && std::isfinite(calm->summary.motion.acromionCranial))
      out.push_back(check(
          "physiology.deep.shoulder_lift_over_calm", "acromion cranial motion, deep minus calm", ">= 10 mm",
          "the accessory muscles (sternocleidomastoids, scalenes, upper trapezius) are recruited in deep "
          "breathing and raise the shoulder girdle (De Troyer & Boriek 2011, Compr Physiol 1:1273); a "
          "visible "
          "lift of 1-2 cm is issue 16's target",
          "mm", (m.acromionCranial - calm->summary.motion.acromionCranial) * kMm, 10.0, kBig));
  }
  return out;
}

namespace {

// the trace's frame ranges [first, last) of the controller's inhale (or exhale) windows of the full cycles
// after settling: [settle + k T, settle + (k + f) T) (or [settle + (k + f) T, settle + (k + 1) T)),
// T = 60 / rate, f the inhale fraction (BreathStyleController)
std::vector<std::pair<std::size_t, std::size_t>> phaseFrames(const StyleRun& r, bool inhale) {
  const Trace& t = r.trace;
  std::vector<std::pair<std::size_t, std::size_t>> out;
  if (t.size() == 0) return out;
  const double period = 60.0 / r.style.breathsPerMinute;  // [s]
  const double split = r.style.inhaleFraction * period;   // [s]
  const int cycles = r.style.cycles > 0 ? r.style.cycles : std::numeric_limits<int>::max();
  for (int k = 0; k < cycles; ++k) {
    const double cycle = r.settleTime + k * period;
    const double begin = inhale ? cycle : cycle + split, end = inhale ? cycle + split : cycle + period;
    if (end > t.time.back()) break;
    std::size_t i = 0;
    while (i < t.size() && t.time[i] < begin) ++i;
    std::size_t j = i;
    while (j < t.size() && t.time[j] < end) ++j;
    if (j > i) out.emplace_back(i, j);
  }
  return out;
}

}  // namespace

double spineSway(const StyleRun& r) {
  if (r.spineTop.size() != r.trace.size()) return 0.0;
  double sum = 0.0;
  int count = 0;
  for (const auto& [first, last] : phaseFrames(r, true)) {
    // the most posterior spine-top position during this inhale, from its start
    double back = 0.0;
    for (std::size_t i = first; i < last; ++i)
      back = std::min(back, r.spineTop[i].y() - r.spineTop[first].y());
    sum += back;
    ++count;
  }
  return count > 0 ? sum / count : 0.0;
}

double expirationRebound(const StyleRun& r) {
  const std::vector<double>& v = r.trace.lungVolume;
  double rebound = 0.0;
  for (const auto& [first, last] : phaseFrames(r, false)) {
    // from the exhale's highest volume on, the largest rise above the running minimum
    const auto peak = std::max_element(v.begin() + static_cast<std::ptrdiff_t>(first),
                                       v.begin() + static_cast<std::ptrdiff_t>(last));
    double low = *peak;
    for (auto it = peak; it != v.begin() + static_cast<std::ptrdiff_t>(last); ++it) {
      low = std::min(low, *it);
      rebound = std::max(rebound, *it - low);
    }
  }
  return rebound;
}

std::vector<Check> swayChecks(const StyleRun& withFriction, const StyleRun& frictionless) {
  const std::string sec5 = kZordan + ", Sec. 5, Eq. 3";
  const double a = spineSway(withFriction), b = spineSway(frictionless);
  return {check("sway.backward",
                "spine-top (" + withFriction.spineBody +
                    ") most posterior displacement during an inhale, mean over inhales, deep, with friction",
                "< -0.1 mm (spine moves backward on inhale)", sec5, "mm", a * kMm, -kBig, -0.1),
          check("sway.friction_ratio", "spine sway frictionless / with friction", "< 0.5", sec5, "-",
                std::abs(b) / std::max(std::abs(a), 1e-12), 0.0, 0.5)};
}

double settleDrift(const StyleRun& r, double window) {
  if (r.trace.size() == 0) return 0.0;
  const std::size_t end = settledFrame(r);
  std::size_t start = end;
  while (start > 0 && r.trace.time[start] > r.settleTime - window) --start;
  if (r.trace.time[start] > r.settleTime - window + 1e-9) return 0.0;
  return r.trace.lungVolume[end] - r.trace.lungVolume[start];
}

std::vector<Check> postureChecks(const StyleRun& upright, const StyleRun& supine) {
  const auto share = [](const StyleRun& r) { return r.summary.motion.ribCageShare(); };
  const std::string name = upright.style.name;
  const double eev = upright.summary.endExpiratoryVolume;
  const double bound = 0.02 * supine.summary.tidalVolume;  // [m^3] settling drift
  return {
      check("posture.rib_cage_share",
            "rib-cage share of the tidal volume, " + name + ", supine minus upright",
            "<= -1 percentage point (more abdominal supine)",
            "Sharp et al. 1975, J Appl Physiol 39:608; Konno & Mead 1967", "%",
            (share(supine) - share(upright)) * kPct, -kBig, -1.0),
      check("posture.end_expiratory_volume",
            "end-expiratory lung volume, " + name + ", supine relative to upright",
            "<= -1 % (lung volumes 5.3-14.7 % larger upright)",
            "Yamada et al. 2020, Sci Rep, doi:10.1038/s41598-020-73240-8", "%",
            (supine.summary.endExpiratoryVolume - eev) / eev * kPct, -kBig, -1.0),
      check("posture.settled_supine", "lung-volume drift in the last 0.5 s of settling, " + name + ", supine",
            "within 2 % of the tidal volume", "pneuma (the settling reaches the posture's rest)", "mL",
            settleDrift(supine) * kMl, -bound * kMl, bound * kMl)};
}

SilhouetteBreath silhouetteBreath(const StyleRun& run) {
  if (!run.hasBreathPoses || !run.model)
    throw Error("silhouette: the '" + run.style.name + "' run holds no end-inspiration and end-expiration");
  const Model& model = *run.model;
  if (model.skin.vertexCount() == 0) throw Error("silhouette: the model '" + model.name + "' has no skin");
  const int jugular = model.landmarks.find("jugular_notch"), xiphoid = model.landmarks.find("xiphoid"),
            umbilicus = model.landmarks.find("umbilicus"),
            rib8Right = model.landmarks.find("rib8_lateral_right"),
            rib8Left = model.landmarks.find("rib8_lateral_left");
  if (jugular < 0 || xiphoid < 0 || umbilicus < 0 || rib8Right < 0 || rib8Left < 0)
    throw Error("silhouette: the model '" + model.name +
                "' lacks one of the landmarks jugular_notch, xiphoid, umbilicus, rib8_lateral_right, "
                "rib8_lateral_left");
  SilhouetteBreath b;
  b.style = run.style.name;
  PosedGeometry g;
  poseGeometry(model, run.endExpiration, g);
  b.skinExpiration = g.skin;
  // the lines' heights in a pose, from its landmarks
  const auto chestLine = [&] {
    return g.landmarks(2, jugular) +
           kChestLineOnSternum * (g.landmarks(2, xiphoid) - g.landmarks(2, jugular));
  };
  b.chestHeight = chestLine();
  b.bellyHeight = g.landmarks(2, umbilicus);
  b.trunkBand = 0.5 * std::abs(g.landmarks(0, rib8Right) - g.landmarks(0, rib8Left));
  poseGeometry(model, run.endInspiration, g);
  b.skinInspiration = g.skin;
  b.chestLift = chestLine() - b.chestHeight;
  b.bellyLift = g.landmarks(2, umbilicus) - b.bellyHeight;
  const Eigen::Matrix3Xi& t = model.skin.triangles;
  const auto depth = [&](const Eigen::Matrix3Xd& x, double z) {
    return silhouetteWidth(x, t, SilhouetteView::Lateral, z, b.trunkBand);
  };
  b.chestChange = depth(b.skinInspiration, b.chestHeight) - depth(b.skinExpiration, b.chestHeight);
  // a marker on the skin: the material point where the midline meets the front of the skin at the chest line
  // (the front-most crossing of the line x = 0, z = chest line with a triangle, in barycentric coordinates)
  double front = -std::numeric_limits<double>::infinity();
  for (Eigen::Index f = 0; f < t.cols(); ++f) {
    const Eigen::Vector3d a = b.skinExpiration.col(t(0, f)), e1 = b.skinExpiration.col(t(1, f)) - a,
                          e2 = b.skinExpiration.col(t(2, f)) - a;
    // solve (0, chest) = a + u e1 + v e2 in the frontal (x, z) plane
    const double det = e1.x() * e2.z() - e2.x() * e1.z();
    if (det == 0.0) continue;
    const double px = -a.x(), pz = b.chestHeight - a.z();
    const double u = (px * e2.z() - e2.x() * pz) / det, v = (e1.x() * pz - px * e1.z()) / det;
    if (u < 0.0 || v < 0.0 || u + v > 1.0) continue;
    const double y = a.y() + u * e1.y() + v * e2.y();
    if (y <= front) continue;
    front = y;
    const auto moved = [&](int k) { return b.skinInspiration.col(t(k, f)) - b.skinExpiration.col(t(k, f)); };
    b.chestMarker = (1.0 - u - v) * moved(0) + u * moved(1) + v * moved(2);
  }
  b.bellyChange = depth(b.skinInspiration, b.bellyHeight) - depth(b.skinExpiration, b.bellyHeight);
  b.lungChange = run.endInspirationVolume - run.endExpirationVolume;
  return b;
}

std::vector<Check> silhouetteChecks(const std::vector<SilhouetteBreath>& breaths) {
  std::map<std::string, const SilhouetteBreath*> byName;
  for (const SilhouetteBreath& b : breaths) byName[b.style] = &b;
  auto find = [&](const char* name) { return byName.count(name) ? byName[name] : nullptr; };
  const SilhouetteBreath* calm = find("calm");
  const SilhouetteBreath* deep = find("deep");
  const SilhouetteBreath* panting = find("panting");
  const SilhouetteBreath* forced = find("forced-exhale");
  const std::string deGroote =
      "seated tidal breathing, optoelectronic markers (De Groote et al. 1997, J Appl Physiol 83:1531)";
  const std::string kaneko =
      "3D motion capture of 100 adults, sitting and supine (Kaneko & Horie 2012, Respir Care "
      "57:1442)";
  const std::string sharp =
      "fast manoeuvres are mostly rib cage (Sharp et al. 1975, J Appl Physiol 39:608); " + kZordan +
      ", Sec. 8.1 'panting breathing'";
  const std::string fig5 = kZordan + ", Sec. 8.1 'forced exhale', Fig. 5";
  const auto what = [](const SilhouetteBreath& b, const char* line) {
    return std::string("silhouette AP depth at the ") + line + ", end-inspiration minus end-expiration, " +
           b.style;
  };
  std::vector<Check> out;
  const auto add = [&](const SilhouetteBreath& b, bool isChest, std::string target, std::string source,
                       double lower, double upper) {
    out.push_back(check("silhouette." + b.style + (isChest ? ".chest" : ".belly"),
                        what(b, isChest ? "chest (4th intercostal space)" : "belly (umbilicus)"),
                        std::move(target), std::move(source), "mm",
                        (isChest ? b.chestChange : b.bellyChange) * kMm, lower, upper));
  };
  if (calm) {
    add(*calm, true, "3 - 5 mm published; 1.5 - 10 mm accepted", deGroote, 1.5, 10.0);
    const Eigen::Vector3d& m = calm->chestMarker;
    out.push_back(check("silhouette.calm.chest_marker",
                        "displacement of a skin marker at the front of the chest line (midline), calm",
                        "3 - 5 mm published; 1.5 - 10 mm accepted", deGroote, "mm", m.norm() * kMm, 1.5,
                        10.0));
    add(*calm, false, "> 0 mm (the umbilical section moves ventrally)", deGroote + "; Konno & Mead 1967",
        1e-9, kBig);
  }
  if (deep && calm) {
    // their deep breaths were fuller than the deep style's (about twice calm's volume): the direction only
    const std::string target = "> calm's (subjects' quiet-breathing motion < 1/3 of their deep breathing's)";
    add(*deep, true, target, kaneko, calm->chestChange * kMm + 1e-9, kBig);
    add(*deep, false, target, kaneko, calm->bellyChange * kMm + 1e-9, kBig);
  }
  if (panting && calm) {
    add(*panting, true, "> 0 mm", sharp, 1e-9, kBig);
    const double calmRatio = calm->bellyChange / std::max(calm->chestChange, 1e-12);
    add(*panting, false, "< panting chest x calm's belly/chest ratio (chest-dominant)", sharp, -kBig,
        panting->chestChange * calmRatio * kMm);
  }
  if (forced) {
    add(*forced, true, "> 0 mm (the rib cage falls)", fig5, 1e-9, kBig);
    add(*forced, false, ">= 10 mm (the rectus pulls the belly in)", fig5, 10.0, kBig);
  }
  return out;
}

ImpactRun runHeavyImpact(std::shared_ptr<const Model> modelPtr, const ExperimentSettings& settings) {
  const Model& model = *modelPtr;
  const int umbilicus = model.landmarks.find("umbilicus");
  if (umbilicus < 0) throw Error("heavy impact: the model has no 'umbilicus' landmark");

  // settle the relaxed torso
  SimulationOptions o = settings.simulation;
  o.settleTime = 0.0;
  Simulation sim(modelPtr, std::make_unique<RelaxedController>(), o);
  sim.advance(settings.impactSettle);
  State s = sim.state();
  const Eigen::Vector3d umb = sim.latestMetrics().landmarks.col(umbilicus);

  // the blow: wall nodes around the umbilicus move posteriorly (-y)
  ImpactRun run;
  for (int n = 0; n < model.nodes.size(); ++n) {
    if (model.nodes.isFixed(n) || model.nodes.region[static_cast<std::size_t>(n)] != NodeRegion::Wall)
      continue;
    if ((s.nodePosition.col(n) - umb).norm() > settings.impactRadius) continue;
    s.nodeVelocity(1, n) -= settings.impactSpeed;
    ++run.struckNodes;
  }
  if (run.struckNodes == 0)
    throw Error("heavy impact: no abdominal wall node within the impact radius of the umbilicus");

  // follow the deformation step by step
  StepWork w = makeStepWork(model);
  Metrics m;
  const Activations relaxed = relaxedActivations();
  const double dt = sim.dt();
  const long long steps = static_cast<long long>(std::llround(settings.impactDuration / dt));
  for (long long k = 1; k <= steps; ++k) {
    step(model, s, dt, relaxed, o.step, w);
    checkState(model, s, w, dt);
    computeMetrics(model, s, relaxed, o.step, w, m);
    run.time.push_back(k * dt);
    run.gutVolumeError.push_back(m.gutVolumeError);
    run.maxVolumeError = std::max(run.maxVolumeError, std::abs(m.gutVolumeError));
    run.maxDent = std::max(run.maxDent, umb.y() - m.landmarks(1, umbilicus));
  }
  return run;
}

std::vector<Check> impactChecks(const ImpactRun& run) {
  const std::string fig4 = kZordan + ", Sec. 6.2, Fig. 4";
  return {check("impact.gut_volume_error", "max gut volume error after a heavy impact", "< 0.5 %", fig4, "%",
                run.maxVolumeError * kPct, 0.0, 0.5),
          check("impact.dent", "largest posterior displacement of the umbilicus after the impact",
                "> 5 mm (the wall visibly dents)", fig4, "mm", run.maxDent * kMm, 5.0, kBig)};
}

namespace {

// the gut nodes that hold a diaphragm element of one side ({left, right}); midline strands belong to both
// halves and are left out
std::array<std::vector<int>, 2> hemidiaphragmNodes(const Model& m, const StepWork& w) {
  std::array<std::vector<int>, 2> out;
  std::vector<char> seen(static_cast<std::size_t>(m.nodes.size()) * 2, 0);
  for (int e = 0; e < m.elements.size(); ++e) {
    if (m.elements.group[static_cast<std::size_t>(e)] != ElementGroup::Diaphragm) continue;
    const double share = w.constants.elementRightShare(e);
    if (share != 0.0 && share != 1.0) continue;
    const int side = share == 1.0 ? 1 : 0;
    for (const AnchorSet* a : {&m.elements.endA, &m.elements.endB})
      for (int k = 0; k < 3; ++k) {
        const int n = a->nodes(k, e);
        if (a->body[static_cast<std::size_t>(e)] >= 0 || n < 0 || m.nodes.isFixed(n)) continue;
        char& mark = seen[static_cast<std::size_t>(2 * n + side)];
        if (!mark) out[static_cast<std::size_t>(side)].push_back(n);
        mark = 1;
      }
  }
  return out;
}

// least-squares slope of y against x
double slope(const std::vector<double>& x, const std::vector<double>& y) {
  double mx = 0.0, my = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i) mx += x[i], my += y[i];
  mx /= static_cast<double>(x.size());
  my /= static_cast<double>(y.size());
  double sxy = 0.0, sxx = 0.0;
  for (std::size_t i = 0; i < x.size(); ++i)
    sxy += (x[i] - mx) * (y[i] - my), sxx += (x[i] - mx) * (x[i] - mx);
  return sxx > 0.0 ? sxy / sxx : 0.0;
}

}  // namespace

std::vector<std::string> teachingScenarios() {
  return {"calm.json",
          "teaching/paralysed-left-hemidiaphragm.json",
          "teaching/paralysed-right-hemidiaphragm.json",
          "teaching/weak-intercostals.json",
          "teaching/stiff-chest-wall.json",
          "teaching/abdominal-binding.json",
          "teaching/supine.json"};
}

TeachingRun runTeachingScenario(std::shared_ptr<const Model> model, const std::string& scenario,
                                const std::string& resourceDir) {
  const Scenario s = loadScenario(resourceDir + "/scenarios/" + scenario);
  SimulationOptions o = s.options;
  o.outputRate = 30.0;
  o.recordSeconds = kTraceOnlyRecordSeconds;
  Simulation sim(model, makeController(s, model, resourceDir), o);
  const auto nodes = hemidiaphragmNodes(*model, sim.stepWork());
  std::vector<double> volume;               // [L]
  std::array<std::vector<double>, 2> dome;  // [mm]
  sim.advance(o.settleTime + kTeachingSeconds, [&](const Simulation& sm) {
    if (sm.state().time < o.settleTime) return true;
    volume.push_back(sm.latestMetrics().lungVolume * 1e3);
    for (std::size_t side = 0; side < 2; ++side) {
      double z = 0.0;
      for (int n : nodes[side]) z += sm.state().nodePosition(2, n);
      dome[side].push_back(nodes[side].empty() ? 0.0 : z / static_cast<double>(nodes[side].size()) * kMm);
    }
    return true;
  });
  TeachingRun r;
  r.scenario = scenario;
  r.summary = sim.summary();
  for (std::size_t side = 0; side < 2; ++side) r.domeRisePerLitre[side] = slope(volume, dome[side]);
  return r;
}

std::vector<Check> teachingChecks(const std::vector<TeachingRun>& runs) {
  const auto find = [&](const std::string& scenario) -> const TeachingRun* {
    for (const TeachingRun& r : runs)
      if (r.scenario == scenario) return &r;
    return nullptr;
  };
  const TeachingRun* calm = find("calm.json");
  std::vector<Check> out;
  if (!calm) return out;
  const double calmTidal = calm->summary.tidalVolume * kMl;
  const double calmShare = kPct * calm->summary.motion.ribCageShare();
  const char* sides[2] = {"left", "right"};
  for (std::size_t side = 0; side < 2; ++side)
    out.push_back(check(std::string("teaching.calm.") + sides[side] + "_dome_rise",
                        std::string(sides[side]) + " hemidiaphragm height per litre inhaled, calm",
                        "< -1 mm/L (descends)", "both domes descend on inspiration (Boussuges et al. 2009)",
                        "mm/L", calm->domeRisePerLitre[side], -kBig, -1.0));
  // the tidal volume as a fraction of calm's, below `upper`
  const auto tidal = [&](const std::string& id, const TeachingRun& r, double upper,
                         const std::string& source) {
    out.push_back(check("teaching." + id + ".tidal_volume", "tidal volume against calm, " + id,
                        "< " + std::to_string(static_cast<int>(std::lround(upper * 100))) + " % of calm",
                        source, "% of calm", kPct * r.summary.tidalVolume * kMl / calmTidal, -kBig,
                        kPct * upper * (1.0 - 1e-12)));
  };
  // the rib-cage share against calm's, shifted by at least `shift` points (down when negative)
  const auto share = [&](const std::string& id, const TeachingRun& r, double shift,
                         const std::string& source) {
    const double d = kPct * r.summary.motion.ribCageShare() - calmShare;
    const std::string target =
        (shift < 0 ? "< " : "> ") + std::to_string(static_cast<int>(shift)) + " points";
    out.push_back(check("teaching." + id + ".rib_cage_share", "rib-cage share minus calm's, " + id, target,
                        source, "points", d, shift < 0 ? -kBig : shift, shift < 0 ? shift : kBig));
  };
  for (std::size_t paralysed = 0; paralysed < 2; ++paralysed) {
    const std::string id = std::string("paralysed-") + sides[paralysed] + "-hemidiaphragm";
    const TeachingRun* r = find("teaching/" + id + ".json");
    if (!r) continue;
    tidal(id, *r, 0.9,
          "unilateral paralysis costs about a quarter of the vital capacity (Laroche et al. 1988, Thorax "
          "43:170)");
    const std::string sniff = "paradoxical rise of the paralysed dome (Alexander 1966, Clin Radiol 17:79)";
    out.push_back(
        check("teaching." + id + ".paralysed_dome_rise",
              std::string("paralysed (") + sides[paralysed] + ") hemidiaphragm height per litre inhaled",
              "> 0 mm/L (rises)", sniff, "mm/L", r->domeRisePerLitre[paralysed], 0.0, kBig));
    out.push_back(
        check("teaching." + id + ".other_dome_rise",
              std::string("working (") + sides[1 - paralysed] + ") hemidiaphragm height per litre inhaled",
              "< -1 mm/L (descends)", sniff, "mm/L", r->domeRisePerLitre[1 - paralysed], -kBig, -1.0));
  }
  if (const TeachingRun* r = find("teaching/weak-intercostals.json")) {
    const std::string src =
        "intercostal paralysis: abdominal breathing (De Troyer & Estenne 1984, J Appl Physiol 57:899; Urmey "
        "et al. 1986, J Appl Physiol 60:618)";
    share("weak-intercostals", *r, -5.0, src);
    tidal("weak-intercostals", *r, 0.9, src);
  }
  if (const TeachingRun* r = find("teaching/stiff-chest-wall.json")) {
    const std::string src = "ankylosing spondylitis (Romagnoli et al. 2004, Eur Respir J 24:453)";
    share("stiff-chest-wall", *r, -20.0, src);
    out.push_back(check("teaching.stiff-chest-wall.lower_rib_expansion", "rib-8 widening against calm",
                        "< 50 % of calm", src, "% of calm",
                        kPct * r->summary.motion.lowerRibExpansion / calm->summary.motion.lowerRibExpansion,
                        -kBig, 50.0));
    out.push_back(check(
        "teaching.stiff-chest-wall.umbilicus_forward", "umbilicus anterior motion minus calm's",
        "> 0 mm (the abdomen takes over)", src, "mm",
        (r->summary.motion.umbilicusAnterior - calm->summary.motion.umbilicusAnterior) * kMm, 1e-9, kBig));
    tidal("stiff-chest-wall", *r, 0.9, src);
  }
  if (const TeachingRun* r = find("teaching/abdominal-binding.json")) {
    const std::string src =
        "Hussain et al. 1985, J Appl Physiol 58:2020; Konno & Mead 1967, J Appl Physiol 22:407";
    share("abdominal-binding", *r, 5.0, src);
    tidal("abdominal-binding", *r, 1.0, src);
  }
  if (const TeachingRun* r = find("teaching/supine.json")) {
    share("supine", *r, -5.0,
          "supine breathing is more abdominal (Sharp et al. 1975, J Appl Physiol 39:608)");
    out.push_back(check("teaching.supine.end_expiratory_volume", "end-expiratory lung volume against upright",
                        "< 99 % of upright",
                        "lung volumes 5-15 % larger upright (Yamada et al. 2020, Sci Rep)", "% of upright",
                        kPct * r->summary.endExpiratoryVolume / calm->summary.endExpiratoryVolume, -kBig,
                        99.0));
  }
  return out;
}

}  // namespace pneuma::sim
