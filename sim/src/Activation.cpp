#include "pneuma/sim/Activation.h"

#include <cmath>
#include <sstream>

#include "pneuma/sim/Error.h"

namespace pneuma::sim {

Activations relaxedActivations() { return Activations{}; }

void validateActivations(const Activations& a) {
  for (int g = 0; g < kElementGroupCount; ++g) {
    const GroupActivation& ga = a[static_cast<std::size_t>(g)];
    const char* name = groupName(static_cast<ElementGroup>(g));
    if (!std::isfinite(ga.r) || ga.r <= 0.0 || ga.r > 1.5) {
      std::ostringstream os;
      os << "activations." << name << ".r: must be in (0, 1.5], got " << ga.r;
      throw Error(os.str());
    }
    if (!std::isfinite(ga.alpha) || ga.alpha < 0.0 || ga.alpha > 1.0) {
      std::ostringstream os;
      os << "activations." << name << ".alpha: must be in [0, 1], got " << ga.alpha;
      throw Error(os.str());
    }
  }
}

}  // namespace pneuma::sim
