/// @file GltfWriter.cpp
/// The .glb export (GltfWriter.h): one binary buffer, one buffer view per accessor, 4-byte aligned.

#include "viz/GltfWriter.h"

#include <tiny_gltf.h>
#include <vtkCellArray.h>
#include <vtkDataArray.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <sstream>

#include "pneuma/sim/Error.h"
#include "viz/AtomicFile.h"
#include "viz/ModelScene.h"

namespace pneuma::viz {

const Eigen::Matrix3d& modelToGltf() {
  // (X, Y, Z) = (-x, z, y): the subject's left is +X, superior +Y, anterior +Z; det = +1
  static const Eigen::Matrix3d c = (Eigen::Matrix3d() << -1, 0, 0, 0, 0, 1, 0, 1, 0).finished();
  return c;
}

namespace {

/// Builds the buffer, views and accessors of one glTF model.
class GltfBuilder {
 public:
  explicit GltfBuilder(tinygltf::Model& gltf) : m_gltf(gltf) { m_gltf.buffers.emplace_back(); }

  /// A FLOAT accessor of `columns` (rows = components: 1, 3 or 4) with its min and max when `bounds`.
  int floats(const Eigen::MatrixXf& columns, bool bounds, int target = 0) {
    const int type = columns.rows() == 1   ? TINYGLTF_TYPE_SCALAR
                     : columns.rows() == 3 ? TINYGLTF_TYPE_VEC3
                                           : TINYGLTF_TYPE_VEC4;
    tinygltf::Accessor a;
    a.bufferView = view(columns.data(), sizeof(float) * static_cast<std::size_t>(columns.size()), target);
    a.componentType = TINYGLTF_COMPONENT_TYPE_FLOAT;
    a.count = static_cast<std::size_t>(columns.cols());
    a.type = type;
    if (bounds && columns.cols() > 0) {
      for (Eigen::Index r = 0; r < columns.rows(); ++r) {
        a.minValues.push_back(columns.row(r).minCoeff());
        a.maxValues.push_back(columns.row(r).maxCoeff());
      }
    }
    m_gltf.accessors.push_back(a);
    return static_cast<int>(m_gltf.accessors.size()) - 1;
  }

  /// An UNSIGNED_INT index accessor of triangles (3 x #T).
  int indices(const Eigen::Matrix<std::uint32_t, 3, Eigen::Dynamic>& triangles) {
    tinygltf::Accessor a;
    a.bufferView = view(triangles.data(), sizeof(std::uint32_t) * static_cast<std::size_t>(triangles.size()),
                        TINYGLTF_TARGET_ELEMENT_ARRAY_BUFFER);
    a.componentType = TINYGLTF_COMPONENT_TYPE_UNSIGNED_INT;
    a.count = static_cast<std::size_t>(triangles.size());
    a.type = TINYGLTF_TYPE_SCALAR;
    m_gltf.accessors.push_back(a);
    return static_cast<int>(m_gltf.accessors.size()) - 1;
  }

  /// A triangle primitive of positions `x` (with bounds), normals `n` (3 x #V) and `triangles` (3 x #T).
  tinygltf::Primitive triangleMesh(const Eigen::Matrix3Xf& x, const Eigen::Matrix3Xf& n,
                                   const Eigen::Matrix<std::uint32_t, 3, Eigen::Dynamic>& triangles,
                                   int material) {
    tinygltf::Primitive p;
    p.mode = TINYGLTF_MODE_TRIANGLES;
    p.material = material;
    p.attributes["POSITION"] = floats(x, true, TINYGLTF_TARGET_ARRAY_BUFFER);
    p.attributes["NORMAL"] = floats(n, false, TINYGLTF_TARGET_ARRAY_BUFFER);
    p.indices = indices(triangles);
    return p;
  }

 private:
  int view(const void* data, std::size_t bytes, int target) {
    std::vector<unsigned char>& buffer = m_gltf.buffers.front().data;
    tinygltf::BufferView v;
    v.buffer = 0;
    v.byteOffset = buffer.size();
    v.byteLength = bytes;
    v.target = target;
    buffer.resize(buffer.size() + ((bytes + 3) / 4) * 4, 0);
    std::memcpy(buffer.data() + v.byteOffset, data, bytes);
    m_gltf.bufferViews.push_back(v);
    return static_cast<int>(m_gltf.bufferViews.size()) - 1;
  }
  tinygltf::Model& m_gltf;
};

using Triangles = Eigen::Matrix<std::uint32_t, 3, Eigen::Dynamic>;

/// [-] area-weighted vertex normals of a triangle mesh, unit length (+Y where a vertex has no area) (3 x #V).
Eigen::Matrix3Xf vertexNormals(const Eigen::Matrix3Xf& x, const Triangles& triangles) {
  Eigen::Matrix3Xf n = Eigen::Matrix3Xf::Zero(3, x.cols());
  for (Eigen::Index t = 0; t < triangles.cols(); ++t) {
    const Eigen::Vector3f a = x.col(triangles(0, t)), b = x.col(triangles(1, t)), c = x.col(triangles(2, t));
    const Eigen::Vector3f area = (b - a).cross(c - a);
    for (int k = 0; k < 3; ++k) n.col(triangles(k, t)) += area;
  }
  for (Eigen::Index v = 0; v < n.cols(); ++v) {
    const float length = n.col(v).norm();
    n.col(v) = length > 1e-12f ? Eigen::Vector3f(n.col(v) / length) : Eigen::Vector3f::UnitY();
  }
  return n;
}

/// Model-frame points [m] to glTF floats.
Eigen::Matrix3Xf toGltf(const Eigen::Matrix3Xd& x) { return (modelToGltf() * x).cast<float>(); }

/// Bone poses (or their displacements) as 7 numbers per bone in the glTF frame: the translation C t and the
/// quaternion of C R C^T, which is (C v, w) for q = (v, w) since C is a proper rotation; linear in both, so
/// displacements convert alike.
tinygltf::Value bonesToGltf(const sim::BonePoses& p) {
  const Eigen::Matrix3d& c = modelToGltf();
  std::vector<tinygltf::Value> flat;
  for (Eigen::Index b = 0; b < p.size(); ++b) {
    const Eigen::Vector3d t = c * p.translation.col(b), v = c * p.rotation.col(b).head<3>();
    for (double x : {t.x(), t.y(), t.z(), v.x(), v.y(), v.z(), p.rotation(3, b)}) flat.emplace_back(x);
  }
  return tinygltf::Value(flat);
}

/// The inverse of bonesToGltf() for `count` bones; false when `value` is not 7 numbers per bone.
bool bonesFromGltf(const tinygltf::Value& value, std::size_t count, sim::BonePoses& p) {
  if (!value.IsArray() || value.ArrayLen() != 7 * count) return false;
  const Eigen::Matrix3d& c = modelToGltf();
  const auto n = static_cast<Eigen::Index>(count);
  p = {Eigen::Matrix3Xd(3, n), Eigen::Matrix4Xd(4, n)};
  for (Eigen::Index b = 0; b < n; ++b) {
    double x[7];
    for (int i = 0; i < 7; ++i) {
      const tinygltf::Value& number = value.Get(static_cast<int>(7 * b + i));
      if (!number.IsNumber()) return false;
      x[i] = number.GetNumberAsDouble();
    }
    p.translation.col(b) = c.transpose() * Eigen::Vector3d(x[0], x[1], x[2]);
    p.rotation.col(b) << c.transpose() * Eigen::Vector3d(x[3], x[4], x[5]), x[6];
  }
  return true;
}

int addMaterial(tinygltf::Model& gltf, const std::string& name, std::vector<double> colour,
                double roughness) {
  tinygltf::Material m;
  m.name = name;
  m.pbrMetallicRoughness.baseColorFactor = std::move(colour);
  m.pbrMetallicRoughness.metallicFactor = 0.0;
  m.pbrMetallicRoughness.roughnessFactor = roughness;
  gltf.materials.push_back(m);
  return static_cast<int>(gltf.materials.size()) - 1;
}

/// A body's render mesh in glTF coordinates: positions, normals and triangles (polygons fanned).
void boneMesh(const std::string& path, const std::string& name, Eigen::Matrix3Xf& x, Eigen::Matrix3Xf& n,
              Triangles& triangles) {
  vtkSmartPointer<vtkPolyData> data = readBodyMesh(path, name);
  const vtkIdType count = data->GetNumberOfPoints();
  Eigen::Matrix3Xd points(3, count);
  for (vtkIdType i = 0; i < count; ++i) data->GetPoint(i, points.col(i).data());
  x = toGltf(points);
  std::vector<std::uint32_t> flat;
  vtkCellArray* polys = data->GetPolys();
  polys->InitTraversal();
  vtkIdType size = 0;
  const vtkIdType* ids = nullptr;
  while (polys->GetNextCell(size, ids)) {
    for (vtkIdType k = 1; k + 1 < size; ++k)
      for (vtkIdType id : {ids[0], ids[k], ids[k + 1]}) flat.push_back(static_cast<std::uint32_t>(id));
  }
  triangles = Eigen::Map<const Triangles>(flat.data(), 3, static_cast<Eigen::Index>(flat.size() / 3));
  n = vertexNormals(x, triangles);
}

}  // namespace

GltfAnimationBuilder::GltfAnimationBuilder(const sim::Model& model, const sim::MorphTargets& targets)
    : m_model(model), m_targets(targets), m_fit(targets), m_tips(sim::boneTips(model)) {}

void GltfAnimationBuilder::add(double time, const sim::State& state) {
  if (!m_time.empty() && !(time > m_time.back())) return;
  sim::poseGeometry(m_model, state, m_posed);
  m_weights.push_back(m_fit.weights(m_posed.skin));
  if (!m_targets.bones.empty()) {
    const sim::BoneBlendError b =
        sim::boneBlendError(m_model, m_tips, sim::blendBones(m_targets, m_weights.back()), m_posed.body);
    m_bone.tipRms += b.tipRms * b.tipRms;
    m_bone.angleRms += b.angleRms * b.angleRms;
    m_bone.tipMax = std::max(m_bone.tipMax, b.tipMax);
    m_bone.angleMax = std::max(m_bone.angleMax, b.angleMax);
  }
  const sim::BlendError e = m_fit.error(m_posed.skin);
  m_squares += e.rms * e.rms;
  m_max = std::max(m_max, e.max);
  m_time.push_back(time);
  m_bodies.push_back(m_posed.body);
}

GltfAnimation GltfAnimationBuilder::animation(const std::string& name) const {
  GltfAnimation a;
  a.name = name;
  a.time = m_time;
  a.bodies = m_bodies;
  a.weights.resize(m_weights.empty() ? 0 : m_weights.front().size(),
                   static_cast<Eigen::Index>(m_weights.size()));
  for (std::size_t f = 0; f < m_weights.size(); ++f)
    a.weights.col(static_cast<Eigen::Index>(f)) = m_weights[f];
  return a;
}

sim::BlendError GltfAnimationBuilder::error() const {
  if (m_time.empty()) return {};
  return {std::sqrt(m_squares / static_cast<double>(m_time.size())), m_max};
}

sim::BoneBlendError GltfAnimationBuilder::boneError() const {
  if (m_time.empty()) return {};
  const double frames = static_cast<double>(m_time.size());
  sim::BoneBlendError e = m_bone;
  e.tipRms = std::sqrt(m_bone.tipRms / frames);
  e.angleRms = std::sqrt(m_bone.angleRms / frames);
  return e;
}

GltfAnimation breathingDemo(const sim::MorphTargets& targets) {
  GltfAnimation a;
  a.name = "breathing";
  a.time = {0.0, 2.0, 5.0};
  a.weights = Eigen::MatrixXd::Zero(static_cast<Eigen::Index>(targets.targets.size()), 3);
  if (a.weights.rows() > 0) a.weights(0, 1) = 1.0;
  if (!targets.bones.empty())
    for (Eigen::Index f = 0; f < a.weights.cols(); ++f)
      a.bodies.push_back(sim::blendBones(targets, a.weights.col(f)));
  return a;
}

void writeGltf(const std::string& path, const sim::Model& model, const std::string& modelDir,
               const sim::MorphTargets& targets, const std::vector<GltfAnimation>& animations) {
  const sim::Skin& skin = model.skin;
  if (skin.vertexCount() == 0)
    throw sim::Error("model '" + model.name + "' has no skin: rebuild it with pneuma-cli model build");
  if (targets.vertexCount() != skin.vertexCount())
    throw sim::Error("morph targets have " + std::to_string(targets.vertexCount()) + " vertices, the skin " +
                     std::to_string(skin.vertexCount()));
  if (!targets.bones.empty() && targets.bones != model.bodies.name)
    throw sim::Error("the morph targets' bones are not model '" + model.name +
                     "''s bodies (bake them again)");
  const Eigen::Matrix3d& c = modelToGltf();

  tinygltf::Model gltf;
  gltf.asset.version = "2.0";
  gltf.asset.generator = std::string("Pneuma ") + PNEUMA_VERSION;
  GltfBuilder build(gltf);
  const int skinMaterial = addMaterial(gltf, "skin", {0.87, 0.70, 0.60, 1.0}, 0.6);
  const int boneMaterial = addMaterial(gltf, "bone", {0.93, 0.90, 0.82, 1.0}, 0.8);

  // the skin: base positions and normals, one morph target per baked shape (positions and normals)
  const Triangles skinTriangles = skin.triangles.cast<std::uint32_t>();
  const Eigen::Matrix3Xf base = toGltf(targets.base);
  const Eigen::Matrix3Xf baseNormals = vertexNormals(base, skinTriangles);
  tinygltf::Primitive skinPrimitive = build.triangleMesh(base, baseNormals, skinTriangles, skinMaterial);
  std::vector<tinygltf::Value> targetNames;
  tinygltf::Mesh skinMesh;
  skinMesh.name = "skin";
  for (const sim::MorphTarget& t : targets.targets) {
    const Eigen::Matrix3Xf d = toGltf(t.displacement);
    const Eigen::Matrix3Xf dn = vertexNormals(base + d, skinTriangles) - baseNormals;
    skinPrimitive.targets.push_back({{"POSITION", build.floats(d, true, TINYGLTF_TARGET_ARRAY_BUFFER)},
                                     {"NORMAL", build.floats(dn, false, TINYGLTF_TARGET_ARRAY_BUFFER)}});
    targetNames.emplace_back(t.name);
    skinMesh.weights.push_back(0.0);
  }
  skinMesh.primitives.push_back(skinPrimitive);
  std::vector<tinygltf::Value> shares, onsets;
  for (const sim::MorphTarget& t : targets.targets) {
    shares.emplace_back(t.ribCageShare);
    onsets.emplace_back(t.onsetVolume);
  }
  tinygltf::Value::Object calibration{{"rest_volume_m3", tinygltf::Value(targets.restVolume)},
                                      {"base_volume_m3", tinygltf::Value(targets.baseVolume)},
                                      {"target_volume_m3", tinygltf::Value(targets.targetVolume)},
                                      {"volume_per_fraction_m3", tinygltf::Value(targets.volumePerFraction)},
                                      {"weight_per_volume_per_m3", tinygltf::Value(targets.weightPerVolume)},
                                      {"rib_cage_share", tinygltf::Value(shares)},
                                      {"onset_volume_m3", tinygltf::Value(onsets)}};
  if (!targets.bones.empty()) {
    std::vector<tinygltf::Value> names(targets.bones.begin(), targets.bones.end()), displacements;
    for (const sim::MorphTarget& t : targets.targets)
      displacements.push_back(bonesToGltf(t.boneDisplacement));
    calibration["bones"] =
        tinygltf::Value(tinygltf::Value::Object{{"names", tinygltf::Value(names)},
                                                {"base", bonesToGltf(targets.boneBase)},
                                                {"targets", tinygltf::Value(displacements)}});
  }
  skinMesh.extras = tinygltf::Value(tinygltf::Value::Object{{"targetNames", tinygltf::Value(targetNames)},
                                                            {"pneuma", tinygltf::Value(calibration)}});
  gltf.meshes.push_back(skinMesh);
  tinygltf::Node skinNode;
  skinNode.name = "skin";
  skinNode.mesh = 0;
  gltf.nodes.push_back(skinNode);

  // the bones: a node per body at its rest pose (frame origin at the com, axes along the world's)
  tinygltf::Node bones;
  bones.name = "bones";
  const int bonesIndex = 1;
  gltf.nodes.push_back(bones);
  std::vector<int> bodyNode(static_cast<std::size_t>(model.bodies.size()), -1);
  for (int b = 0; b < model.bodies.size(); ++b) {
    const std::string& name = model.bodies.name[static_cast<std::size_t>(b)];
    const std::string& file = model.bodies.mesh[static_cast<std::size_t>(b)];
    tinygltf::Node node;
    node.name = name;
    const Eigen::Vector3d t = c * model.bodies.com.col(b);
    node.translation = {t.x(), t.y(), t.z()};
    if (!file.empty()) {
      Eigen::Matrix3Xf x, n;
      Triangles triangles;
      boneMesh((std::filesystem::path(modelDir) / file).string(), name, x, n, triangles);
      const tinygltf::Primitive p = build.triangleMesh(x, n, triangles, boneMaterial);
      tinygltf::Mesh mesh;
      mesh.name = name;
      mesh.primitives.push_back(p);
      gltf.meshes.push_back(mesh);
      node.mesh = static_cast<int>(gltf.meshes.size()) - 1;
    }
    gltf.nodes.push_back(node);
    bodyNode[static_cast<std::size_t>(b)] = static_cast<int>(gltf.nodes.size()) - 1;
    gltf.nodes[bonesIndex].children.push_back(bodyNode[static_cast<std::size_t>(b)]);
  }
  tinygltf::Scene scene;
  scene.name = "pneuma";
  scene.nodes = {0, bonesIndex};
  gltf.scenes.push_back(scene);
  gltf.defaultScene = 0;

  // animations: weights of the skin, translation and rotation of each moving body
  for (const GltfAnimation& a : animations) {
    const Eigen::Index frames = static_cast<Eigen::Index>(a.time.size());
    if (frames < 2 || a.weights.cols() != frames ||
        a.weights.rows() != static_cast<Eigen::Index>(targets.targets.size()))
      throw sim::Error("animation '" + a.name + "': needs at least two frames and one weight per target");
    for (const std::vector<Eigen::Isometry3d>& poses : a.bodies)
      if (poses.size() != model.bodies.name.size())
        throw sim::Error("animation '" + a.name + "': bone poses are not one per body of the model");
    tinygltf::Animation animation;
    animation.name = a.name;
    const Eigen::MatrixXf time =
        Eigen::Map<const Eigen::VectorXd>(a.time.data(), frames).transpose().cast<float>();
    const int input = build.floats(time, true);
    auto channel = [&](const Eigen::MatrixXf& values, int node, const char* pathName) {
      tinygltf::AnimationSampler s;
      s.input = input;
      s.output = build.floats(values, false);
      s.interpolation = "LINEAR";
      animation.samplers.push_back(s);
      tinygltf::AnimationChannel ch;
      ch.sampler = static_cast<int>(animation.samplers.size()) - 1;
      ch.target_node = node;
      ch.target_path = pathName;
      animation.channels.push_back(ch);
    };
    // weights: #K values per frame, frame after frame (a scalar accessor of #F #K values)
    channel(a.weights.cast<float>().reshaped(1, a.weights.size()), 0, "weights");
    if (!a.bodies.empty()) {
      for (int b = 0; b < model.bodies.size(); ++b) {
        if (model.bodies.isFixed[static_cast<std::size_t>(b)] != 0) continue;
        Eigen::MatrixXf translation(3, frames), rotation(4, frames);
        Eigen::Quaterniond previous = Eigen::Quaterniond::Identity();
        for (Eigen::Index f = 0; f < frames; ++f) {
          const Eigen::Isometry3d& pose = a.bodies[static_cast<std::size_t>(f)][static_cast<std::size_t>(b)];
          translation.col(f) = (c * pose.translation()).cast<float>();
          Eigen::Quaterniond q(Eigen::Matrix3d(c * pose.linear() * c.transpose()));
          q.normalize();
          if (q.dot(previous) < 0.0) q.coeffs() = -q.coeffs();  // the short way between frames
          previous = q;
          rotation.col(f) = q.coeffs().cast<float>();  // x, y, z, w as glTF stores them
        }
        channel(translation, bodyNode[static_cast<std::size_t>(b)], "translation");
        channel(rotation, bodyNode[static_cast<std::size_t>(b)], "rotation");
      }
    }
    gltf.animations.push_back(animation);
  }

  // one binary file, through a temporary file and a rename
  gltf.buffers.front().name = "pneuma";
  std::ostringstream out;
  tinygltf::TinyGLTF writer;
  if (!writer.WriteGltfSceneToStream(&gltf, out, false, true))
    throw std::runtime_error("cannot write " + path + ": glTF serialisation failed");
  writeFileAtomically(path, out.str());
}

sim::MorphTargets readGltfMorphTargets(const std::string& path) {
  tinygltf::Model gltf;
  tinygltf::TinyGLTF loader;
  std::string error, warning;
  if (!loader.LoadBinaryFromFile(&gltf, &error, &warning, path))
    throw sim::Error(path + ": not a readable .glb: " + error.substr(0, error.find('\n')));
  auto fail = [&](const std::string& why) {
    return sim::Error(path + ": " + why + " (write it with pneuma-cli bake)");
  };
  const auto mesh = std::find_if(gltf.meshes.begin(), gltf.meshes.end(),
                                 [](const tinygltf::Mesh& m) { return m.name == "skin"; });
  if (mesh == gltf.meshes.end() || mesh->primitives.empty() || !mesh->extras.Has("pneuma"))
    throw fail("no Pneuma skin mesh");
  const tinygltf::Primitive& p = mesh->primitives.front();
  // a tightly packed FLOAT VEC3 accessor as the model frame's (3 x count) [m]
  auto points = [&](int index) -> Eigen::Matrix3Xd {
    if (index < 0 || index >= static_cast<int>(gltf.accessors.size())) throw fail("bad accessor");
    const tinygltf::Accessor& a = gltf.accessors[static_cast<std::size_t>(index)];
    if (a.componentType != TINYGLTF_COMPONENT_TYPE_FLOAT || a.type != TINYGLTF_TYPE_VEC3 || a.bufferView < 0)
      throw fail("skin positions are not float triples");
    const tinygltf::BufferView& v = gltf.bufferViews[static_cast<std::size_t>(a.bufferView)];
    const std::vector<unsigned char>& data = gltf.buffers[static_cast<std::size_t>(v.buffer)].data;
    const std::size_t offset = v.byteOffset + a.byteOffset, bytes = a.count * 3 * sizeof(float);
    if ((v.byteStride != 0 && v.byteStride != 3 * sizeof(float)) || offset + bytes > data.size())
      throw fail("skin positions out of their buffer");
    Eigen::Matrix3Xf x(3, static_cast<Eigen::Index>(a.count));
    std::memcpy(x.data(), data.data() + offset, bytes);
    return modelToGltf().transpose() * x.cast<double>();
  };
  sim::MorphTargets m;
  m.base = points(p.attributes.count("POSITION") != 0 ? p.attributes.at("POSITION") : -1);
  const tinygltf::Value& names = mesh->extras.Get("targetNames");
  const tinygltf::Value& c = mesh->extras.Get("pneuma");
  const tinygltf::Value& shares = c.Get("rib_cage_share");
  if (!names.IsArray() || names.ArrayLen() != p.targets.size() || !shares.IsArray() ||
      shares.ArrayLen() != p.targets.size())
    throw fail("target names or rib-cage shares do not match the targets");
  auto number = [&](const tinygltf::Value& value, const char* key) {
    if (!value.IsNumber()) throw fail(std::string("extras.pneuma.") + key + " is not a number");
    return value.GetNumberAsDouble();
  };
  for (std::size_t k = 0; k < p.targets.size(); ++k) {
    const auto position = p.targets[k].find("POSITION");
    m.targets.push_back({names.Get(static_cast<int>(k)).Get<std::string>(),
                         points(position != p.targets[k].end() ? position->second : -1),
                         number(shares.Get(static_cast<int>(k)), "rib_cage_share"),
                         {}});
    if (m.targets.back().displacement.cols() != m.base.cols())
      throw fail("a target's size differs from the skin's");
  }
  m.restVolume = number(c.Get("rest_volume_m3"), "rest_volume_m3");
  m.baseVolume = number(c.Get("base_volume_m3"), "base_volume_m3");
  m.targetVolume = number(c.Get("target_volume_m3"), "target_volume_m3");
  m.volumePerFraction = number(c.Get("volume_per_fraction_m3"), "volume_per_fraction_m3");
  m.weightPerVolume = number(c.Get("weight_per_volume_per_m3"), "weight_per_volume_per_m3");
  // the recruited shapes' onsets (absent in files baked before them: none recruited)
  if (c.Has("onset_volume_m3")) {
    const tinygltf::Value& onsets = c.Get("onset_volume_m3");
    if (!onsets.IsArray() || onsets.ArrayLen() != m.targets.size())
      throw fail("extras.pneuma.onset_volume_m3 does not match the targets");
    for (std::size_t k = 0; k < m.targets.size(); ++k)
      m.targets[k].onsetVolume = number(onsets.Get(static_cast<int>(k)), "onset_volume_m3");
  }

  // the bones, when baked with them
  if (c.Has("bones")) {
    const tinygltf::Value& bones = c.Get("bones");
    const tinygltf::Value& boneNames = bones.Get("names");
    const tinygltf::Value& displacements = bones.Get("targets");
    if (!boneNames.IsArray() || !displacements.IsArray() || displacements.ArrayLen() != m.targets.size())
      throw fail("extras.pneuma.bones: names or targets missing");
    for (std::size_t b = 0; b < boneNames.ArrayLen(); ++b) {
      const tinygltf::Value& name = boneNames.Get(static_cast<int>(b));
      if (!name.IsString()) throw fail("extras.pneuma.bones.names: not a string");
      m.bones.push_back(name.Get<std::string>());
    }
    bool isValid = bonesFromGltf(bones.Get("base"), m.bones.size(), m.boneBase);
    for (std::size_t k = 0; k < m.targets.size(); ++k)
      isValid = isValid && bonesFromGltf(displacements.Get(static_cast<int>(k)), m.bones.size(),
                                         m.targets[k].boneDisplacement);
    if (!isValid) throw fail("extras.pneuma.bones: not 7 numbers per bone");
  }
  return m;
}

}  // namespace pneuma::viz
