// The step's options: integrator names, default time steps, validation.
#include <cmath>
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
}  // namespace

const char* integratorName(IntegratorKind k) {
  for (const auto& [kind, name] : kIntegratorNames)
    if (kind == k) return name;
  return "?";
}

std::string integratorNames() {
  std::string out;
  for (const auto& [kind, name] : kIntegratorNames) out += (out.empty() ? "" : ", ") + std::string(name);
  return out;
}

bool integratorFromName(const std::string& name, IntegratorKind& out) {
  for (const auto& [kind, n] : kIntegratorNames)
    if (name == n) {
      out = kind;
      return true;
    }
  return false;
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
  if (o.jointIterations < 1) fail("jointIterations", o.jointIterations, "must be >= 1");
  if (!(o.jointTolerance > 0.0)) fail("jointTolerance", o.jointTolerance, "must be > 0");
  if (o.cgMaxIterations < 1) fail("cgMaxIterations", o.cgMaxIterations, "must be >= 1");
  if (o.preconditionerRefresh < 1) fail("preconditionerRefresh", o.preconditionerRefresh, "must be >= 1");
  if (o.refactorIterations < 0) fail("refactorIterations", o.refactorIterations, "must be >= 0");
  if (o.refactorElementChanges < 0) fail("refactorElementChanges", o.refactorElementChanges, "must be >= 0");
  if (!(o.cgTolerance > 0.0)) fail("cgTolerance", o.cgTolerance, "must be > 0");
}

}  // namespace pneuma::sim
