#pragma once
/// @file Ties.h
/// The two kinds of tie, a Cartilage element between a node and a rigid body (isTie()): an apposition spring,
/// whose node is the gut's (the dome in the zone of apposition, held on a rib: it stands for the pleural
/// fluid that holds the dome on the rib cage while letting it slide), and a soft-tissue volume body's tie,
/// whose node (region Tissue) is a deep node of the body held on its bone (VolumeBodies). The body end of
/// either lies off the bone's surface, on the line from the node (docs/model-format.md), so views draw no
/// line for it.

#include <cstddef>
#include <vector>

#include "pneuma/sim/Model.h"

namespace pneuma::sim {

/// True for a tie: a Cartilage element between a node and a rigid body.
inline bool isTie(const Elements& e, int i) {
  const std::size_t k = static_cast<std::size_t>(i);
  return e.group[k] == ElementGroup::Cartilage && (e.endA.body[k] < 0) != (e.endB.body[k] < 0);
}

/// The node of tie `i` (isTie(e, i) true).
inline int tiedNode(const Elements& e, int i) {
  return e.endA.body[static_cast<std::size_t>(i)] < 0 ? e.endA.nodes(0, i) : e.endB.nodes(0, i);
}

/// Per node (#N): 1 when a tie holds it (a dome node in the zone of apposition, a volume body's deep node).
inline std::vector<char> tiedNodes(const Model& m) {
  std::vector<char> tied(static_cast<std::size_t>(m.nodes.size()), 0);
  for (int e = 0; e < m.elements.size(); ++e)
    if (isTie(m.elements, e)) tied[static_cast<std::size_t>(tiedNode(m.elements, e))] = 1;
  return tied;
}

/// True for an apposition spring: a tie whose node is the gut's, not a volume body's.
inline bool isApposition(const Model& m, int i) {
  return isTie(m.elements, i) &&
         m.nodes.region[static_cast<std::size_t>(tiedNode(m.elements, i))] != NodeRegion::Tissue;
}

/// True for an element that views draw as a line: every element but the ties (apposition springs and the
/// volume bodies' ties), the volume bodies' own springs (a node of region Tissue at an end: the body is drawn
/// as its surface) and the gliding springs (Elements::isGliding), whose far ends are virtual anchors off the
/// bones.
inline bool isDrawn(const Model& m, int i) {
  const auto tissueEnd = [&](const AnchorSet& a) {
    const std::size_t k = static_cast<std::size_t>(i);
    return a.body[k] < 0 && m.nodes.region[static_cast<std::size_t>(a.nodes(0, i))] == NodeRegion::Tissue;
  };
  return !isApposition(m, i) && !tissueEnd(m.elements.endA) && !tissueEnd(m.elements.endB) &&
         !m.elements.glides(i);
}

}  // namespace pneuma::sim
