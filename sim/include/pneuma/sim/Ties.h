#pragma once
/// @file Ties.h
/// The two kinds of tie, a Cartilage element between a node and a rigid body (isApposition(const Elements&,
/// int) in Model.h is true for both): an apposition spring, whose node is the gut's (the dome in the zone of
/// apposition, held on a rib), and a soft-tissue volume body's tie, whose node (region Tissue) is a deep node
/// of the body held on its bone (VolumeBodies). The body end of either lies off the bone's surface.

#include <cstddef>
#include <vector>

#include "pneuma/sim/Model.h"

namespace pneuma::sim {

/// The node of tie `i` (isApposition(e, i) true).
inline int tiedNode(const Elements& e, int i) {
  return e.endA.body[static_cast<std::size_t>(i)] < 0 ? e.endA.nodes(0, i) : e.endB.nodes(0, i);
}

/// Per node (#N): 1 when a tie holds it (a dome node in the zone of apposition, a volume body's deep node).
inline std::vector<char> tiedNodes(const Model& m) {
  std::vector<char> tied(static_cast<std::size_t>(m.nodes.size()), 0);
  for (int e = 0; e < m.elements.size(); ++e)
    if (isApposition(m.elements, e)) tied[static_cast<std::size_t>(tiedNode(m.elements, e))] = 1;
  return tied;
}

/// True for an apposition spring proper: a tie whose node is the gut's, not a volume body's
/// (docs/model-format.md; views draw no line for it).
inline bool isApposition(const Model& m, int i) {
  return isApposition(m.elements, i) &&
         m.nodes.region[static_cast<std::size_t>(tiedNode(m.elements, i))] != NodeRegion::Tissue;
}

}  // namespace pneuma::sim
