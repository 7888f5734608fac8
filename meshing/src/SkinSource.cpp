// All assimp code of pneuma::meshing.
#include "SkinSource.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cmath>
#include <filesystem>
#include <map>
#include <numeric>
#include <vector>

#include "pneuma/sim/Error.h"

namespace pneuma::meshing {

namespace {

constexpr double kWeldTolerance = 1e-6;  // [-] of the bounding-box diagonal

int findRoot(std::vector<int>& parent, int i) {
  while (parent[static_cast<std::size_t>(i)] != i) {
    parent[static_cast<std::size_t>(i)] =
        parent[static_cast<std::size_t>(parent[static_cast<std::size_t>(i)])];
    i = parent[static_cast<std::size_t>(i)];
  }
  return i;
}

}  // namespace

TriangleMesh readSkinSource(const std::string& path) {
  auto fail = [&](const std::string& what) { throw sim::Error(path + ": " + what); };
  if (!std::filesystem::is_regular_file(path)) fail("no such file");
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(
      path, aiProcess_Triangulate | aiProcess_PreTransformVertices | aiProcess_JoinIdenticalVertices);
  if (scene == nullptr) fail(std::string("assimp cannot read it: ") + importer.GetErrorString());

  // every triangle of every mesh, in world axes (-X, +Z, +Y)
  std::vector<Eigen::Vector3d> points;
  std::vector<Eigen::Vector3i> faces;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* mesh = scene->mMeshes[m];
    const int base = static_cast<int>(points.size());
    for (unsigned i = 0; i < mesh->mNumVertices; ++i) {
      const aiVector3D& v = mesh->mVertices[i];
      points.emplace_back(-static_cast<double>(v.x), static_cast<double>(v.z), static_cast<double>(v.y));
    }
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines
      faces.emplace_back(base + static_cast<int>(face.mIndices[0]), base + static_cast<int>(face.mIndices[1]),
                         base + static_cast<int>(face.mIndices[2]));
    }
  }
  if (faces.empty()) fail("holds no triangles");
  for (const auto& p : points)
    if (!p.allFinite()) fail("has a vertex that is not finite");

  // weld vertices closer than the tolerance (a grid of that size, then exact keys)
  Eigen::Vector3d lo = points.front(), hi = points.front();
  for (const auto& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  const double grid = std::max(kWeldTolerance * (hi - lo).norm(), 1e-300);
  std::map<std::array<long long, 3>, int> key;
  std::vector<int> weld(points.size());
  std::vector<Eigen::Vector3d> welded;
  for (std::size_t i = 0; i < points.size(); ++i) {
    const std::array<long long, 3> k{std::llround((points[i].x() - lo.x()) / grid),
                                     std::llround((points[i].y() - lo.y()) / grid),
                                     std::llround((points[i].z() - lo.z()) / grid)};
    const auto [it, isNew] = key.emplace(k, static_cast<int>(welded.size()));
    if (isNew) welded.push_back(points[i]);
    weld[i] = it->second;
  }
  std::vector<Eigen::Vector3i> tris;
  for (const auto& f : faces) {
    const Eigen::Vector3i t(weld[static_cast<std::size_t>(f[0])], weld[static_cast<std::size_t>(f[1])],
                            weld[static_cast<std::size_t>(f[2])]);
    if (t[0] != t[1] && t[1] != t[2] && t[0] != t[2]) tris.push_back(t);
  }
  if (tris.empty()) fail("holds only degenerate triangles");

  // keep the largest connected piece (by triangles)
  std::vector<int> parent(welded.size());
  std::iota(parent.begin(), parent.end(), 0);
  for (const auto& t : tris)
    for (int k = 1; k < 3; ++k)
      parent[static_cast<std::size_t>(findRoot(parent, t[k]))] = findRoot(parent, t[0]);
  std::map<int, int> size;
  for (const auto& t : tris) ++size[findRoot(parent, t[0])];
  const int root = std::max_element(size.begin(), size.end(), [](const auto& a, const auto& b) {
                     return a.second < b.second;
                   })->first;
  std::vector<int> index(welded.size(), -1);
  TriangleMesh out;
  std::vector<Eigen::Vector3i> kept;
  int n = 0;
  for (const auto& t : tris) {
    if (findRoot(parent, t[0]) != root) continue;
    for (int k = 0; k < 3; ++k)
      if (index[static_cast<std::size_t>(t[k])] < 0) index[static_cast<std::size_t>(t[k])] = n++;
    kept.emplace_back(index[static_cast<std::size_t>(t[0])], index[static_cast<std::size_t>(t[1])],
                      index[static_cast<std::size_t>(t[2])]);
  }
  out.vertices.resize(3, n);
  for (std::size_t i = 0; i < welded.size(); ++i)
    if (index[i] >= 0) out.vertices.col(index[i]) = welded[i];
  out.triangles.resize(3, static_cast<Eigen::Index>(kept.size()));
  for (std::size_t f = 0; f < kept.size(); ++f) out.triangles.col(static_cast<Eigen::Index>(f)) = kept[f];

  // closed and consistently oriented: every directed edge once, with its reverse present
  std::map<std::pair<int, int>, int> directed;
  for (const auto& t : kept)
    for (int k = 0; k < 3; ++k) ++directed[{t[k], t[(k + 1) % 3]}];
  int border = 0, repeated = 0;
  for (const auto& [e, count] : directed) {
    if (count > 1) ++repeated;
    if (directed.count({e.second, e.first}) == 0) ++border;
  }
  if (border > 0)
    fail("the body surface is not closed (" + std::to_string(border) +
         " edges without a neighbouring triangle)");
  if (repeated > 0)
    fail("the body surface is not consistently oriented or not manifold (" + std::to_string(repeated) +
         " edges shared the same way by two triangles)");
  if (enclosedVolume(out.vertices, out.triangles) < 0.0) out.triangles.row(1).swap(out.triangles.row(2));
  return out;
}

}  // namespace pneuma::meshing
