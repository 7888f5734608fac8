// The step's options: integrator and posture names, the posture's gravity, default time steps, validation.
#include <cmath>
#include <cstddef>
#include <sstream>
#include <utility>

#include "StepInternal.h"
#include "pneuma/sim/Error.h"

namespace pneuma::sim {

using detail::at;

namespace {
const std::pair<IntegratorKind, const char*> kIntegratorNames[] = {
    {IntegratorKind::SymplecticEuler, "symplectic-euler"},
    {IntegratorKind::ImplicitEulerJoints, "implicit-euler-joints"}};

const std::pair<Posture, const char*> kPostureNames[] = {{Posture::Upright, "upright"},
                                                         {Posture::Supine, "supine"},
                                                         {Posture::Prone, "prone"},
                                                         {Posture::LeftLateral, "left-lateral"},
                                                         {Posture::RightLateral, "right-lateral"}};

// lookups in a table of (value, name) pairs
template <typename E, std::size_t N>
const char* nameIn(const std::pair<E, const char*> (&table)[N], E value) {
  for (const auto& [v, name] : table)
    if (v == value) return name;
  return "?";
}

template <typename E, std::size_t N>
std::string namesIn(const std::pair<E, const char*> (&table)[N]) {
  std::string out;
  for (const auto& entry : table) out += (out.empty() ? "" : ", ") + std::string(entry.second);
  return out;
}

template <typename E, std::size_t N>
bool valueIn(const std::pair<E, const char*> (&table)[N], const std::string& name, E& out) {
  for (const auto& [v, n] : table)
    if (name == n) {
      out = v;
      return true;
    }
  return false;
}
}  // namespace

const char* integratorName(IntegratorKind k) { return nameIn(kIntegratorNames, k); }
std::string integratorNames() { return namesIn(kIntegratorNames); }
bool integratorFromName(const std::string& name, IntegratorKind& out) {
  return valueIn(kIntegratorNames, name, out);
}

const char* postureName(Posture p) { return nameIn(kPostureNames, p); }
std::string postureNames() { return namesIn(kPostureNames); }
bool postureFromName(const std::string& name, Posture& out) { return valueIn(kPostureNames, name, out); }

double effectiveRestLength(const Model& model, int e, const StepOptions& o) {
  const double l0 = model.elements.restLength(e);
  const bool isToned = o.posture == Posture::Upright &&
                       model.elements.group[static_cast<std::size_t>(e)] == ElementGroup::TransversusObliques;
  return isToned ? (1.0 - model.gut.wallToneUpright) * l0 : l0;
}

Eigen::Vector3d postureGravity(const Model& model, const StepOptions& o) {
  if (!o.gravity) return Eigen::Vector3d::Zero();
  // the upright gravity turned into the body frame: quarter turns, exact in floating point
  const Eigen::Vector3d& g = model.gravity;
  switch (o.posture) {
    case Posture::Upright:
      return g;
    case Posture::Supine:
      return {g.x(), g.z(), -g.y()};  // R_x(-90 deg): -z -> -y
    case Posture::Prone:
      return {g.x(), -g.z(), g.y()};  // R_x(+90 deg): -z -> +y
    case Posture::LeftLateral:
      return {g.z(), g.y(), -g.x()};  // R_y(+90 deg): -z -> -x
    case Posture::RightLateral:
      return {-g.z(), g.y(), g.x()};  // R_y(-90 deg): -z -> +x
  }
  return g;
}

Eigen::Vector3d postureSupport(const Model& model, int b, const StepOptions& o) {
  if (!model.bodies.supported(b)) return Eigen::Vector3d::Zero();
  return -model.bodies.mass(b) * postureGravity(model, o);
}

Eigen::Vector3d postureSupportPoint(const Model& model, int b, const StepOptions& o) {
  const Eigen::Vector3d g = postureGravity(model, o);
  const double h = model.bodies.supportHeightOf(b);
  if (!model.bodies.supported(b) || h == 0.0 || g.norm() == 0.0) return Eigen::Vector3d::Zero();
  return -h * g.normalized();
}

double defaultTimeStep(IntegratorKind k) { return k == IntegratorKind::SymplecticEuler ? 1e-5 : 1.0 / 60.0; }

void validateStepOptions(const StepOptions& o) {
  auto fail = [](const std::string& field, double v, const char* rule) {
    std::ostringstream os;
    os << field << ": " << rule << ", got " << v;
    throw Error(os.str());
  };
  if (!std::isfinite(o.jointFrictionScale) || o.jointFrictionScale < 0.0)
    fail("jointFrictionScale", o.jointFrictionScale, "must be finite and >= 0");
  if (!std::isfinite(o.gutDragScale) || o.gutDragScale < 0.0)
    fail("gutDragScale", o.gutDragScale, "must be finite and >= 0");
  if (o.kappa && !(std::isfinite(*o.kappa) && *o.kappa > 0.0))
    fail("kappa", *o.kappa, "must be finite and > 0 (unset selects the model's value)");
  for (int g = 0; g < kElementGroupCount; ++g) {
    const std::string name = groupName(static_cast<ElementGroup>(g));
    if (!std::isfinite(o.activeGainScale[at(g)]) || o.activeGainScale[at(g)] < 0.0)
      fail("activeGainScale." + name, o.activeGainScale[at(g)], "must be finite and >= 0");
    if (!std::isfinite(o.passiveGainScale[at(g)]) || o.passiveGainScale[at(g)] < 0.0)
      fail("passiveGainScale." + name, o.passiveGainScale[at(g)], "must be finite and >= 0");
  }
  for (int side = 0; side < 2; ++side) {
    const double v = o.hemidiaphragmActiveScale[at(side)];
    if (!std::isfinite(v) || v < 0.0)
      fail(side == 0 ? "hemidiaphragmActiveScale.left" : "hemidiaphragmActiveScale.right", v,
           "must be finite and >= 0");
  }
  if (o.jointIterations < 1) fail("jointIterations", o.jointIterations, "must be >= 1");
  if (!(o.jointTolerance > 0.0)) fail("jointTolerance", o.jointTolerance, "must be > 0");
  if (o.cgMaxIterations < 1) fail("cgMaxIterations", o.cgMaxIterations, "must be >= 1");
  if (o.preconditionerRefresh < 1) fail("preconditionerRefresh", o.preconditionerRefresh, "must be >= 1");
  if (o.refactorIterations < 0) fail("refactorIterations", o.refactorIterations, "must be >= 0");
  if (o.refactorElementChanges < 0) fail("refactorElementChanges", o.refactorElementChanges, "must be >= 0");
  if (!(o.cgTolerance > 0.0)) fail("cgTolerance", o.cgTolerance, "must be > 0");
}

}  // namespace pneuma::sim
