#include "pneuma/sim/Limits.h"

#include <cmath>
#include <sstream>

#include "pneuma/sim/Error.h"

namespace pneuma::sim {

bool Range::contains(double v) const { return std::isfinite(v) && v >= lo && v <= hi; }

std::string Range::problem(double v) const {
  if (contains(v)) return {};
  std::ostringstream os;
  os << "must be in [" << lo << ", " << hi << "] " << unit << ", got " << v;
  return os.str();
}

void Range::check(const std::string& field, double v) const {
  if (!contains(v)) throw Error(field + ": " + problem(v));
}

void checkStepCount(const std::string& field, double seconds, double dt) {
  const double steps = seconds / dt;
  if (steps <= kMaxStepsPerRun) return;
  std::ostringstream os;
  os << field << ": " << seconds << " s at dt " << dt << " s needs more than the " << kMaxStepsPerRun
     << " steps a run may take";
  throw Error(os.str());
}

}  // namespace pneuma::sim
