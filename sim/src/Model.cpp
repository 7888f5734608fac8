#include "pneuma/sim/Model.h"

namespace pneuma::sim {

namespace {
constexpr std::array<const char*, kElementGroupCount> kGroupNames = {"intercostal_external",
                                                                     "intercostal_internal",
                                                                     "diaphragm",
                                                                     "rectus",
                                                                     "transversus_obliques",
                                                                     "cartilage"};

// append one column to a 3 x n matrix
template <typename M, typename V>
void appendColumn(M& m, const V& v) {
  m.conservativeResize(3, m.cols() + 1);
  m.col(m.cols() - 1) = v;
}
}  // namespace

const char* groupName(ElementGroup g) {
  const int i = static_cast<int>(g);
  return (i >= 0 && i < kElementGroupCount) ? kGroupNames[static_cast<std::size_t>(i)] : "unknown";
}

bool groupFromName(const std::string& name, ElementGroup& out) {
  for (int i = 0; i < kElementGroupCount; ++i) {
    if (name == kGroupNames[static_cast<std::size_t>(i)]) {
      out = static_cast<ElementGroup>(i);
      return true;
    }
  }
  return false;
}

void AnchorSet::addBodyPoint(int b, const Eigen::Vector3d& p) {
  body.push_back(b);
  appendColumn(local, p);
  appendColumn(nodes, Eigen::Vector3i(-1, -1, -1));
  appendColumn(weights, Eigen::Vector3d::Zero());
}

void AnchorSet::addNodePoint(const Eigen::Vector3i& n, const Eigen::Vector3d& w) {
  body.push_back(-1);
  appendColumn(local, Eigen::Vector3d::Zero());
  appendColumn(nodes, n);
  appendColumn(weights, w);
}

int Landmarks::find(const std::string& n) const {
  for (std::size_t i = 0; i < name.size(); ++i) {
    if (name[i] == n) return static_cast<int>(i);
  }
  return -1;
}

}  // namespace pneuma::sim
