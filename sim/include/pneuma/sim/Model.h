#pragma once
/// @file Model.h
/// The immutable simulation model: everything that does not change while Pneuma steps.
///
/// A Model is what `meshing/` builds and writes as `model.json` (see docs/model-format.md) and what
/// `sim/` reads back. It follows MuJoCo's mjModel: topology, rest geometry, masses and gains only;
/// all time-varying quantities live in State.
///
/// Conventions (all SI, radians):
///  - world frame is RAS: +x toward the subject's right, +y anterior, +z superior; gravity is -z upright
///    (StepOptions::posture turns it).
///  - each rigid body's frame has its origin at the body's centre of mass and, at rest, axes parallel
///    to the world axes. Body-frame points are therefore `restWorldPoint - com`.
///  - structures of arrays: one column (or entry) per item, Eigen::Matrix3X* for 3-vectors.

#include <Eigen/Core>
#include <algorithm>
#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace pneuma::sim {

/// Muscle and spring groups (Zordan et al. 2004, Table 1). Cartilage is not a muscle: it is the
/// structurally stable set of two-sided linear springs of Section 5 that links ribs to the sternum.
enum class ElementGroup : int {
  IntercostalExternal = 0,  ///< outer intercostals: down and forward from rib above to rib below; inhale
  IntercostalInternal,      ///< inner intercostals: down and backward; exhale
  Diaphragm,                ///< radial strands, central tendon to costal margin, xiphoid and crura
  Rectus,                   ///< vertical strands on the anterior abdominal wall
  TransversusObliques,      ///< horizontal and diagonal strands around the abdominal wall
  Cartilage,                ///< structural springs: costal cartilage and attachments (two-sided)
  Count
};
constexpr int kElementGroupCount = static_cast<int>(ElementGroup::Count);

/// Stable snake_case name of a group as used in model.json, presets and CSV headers
/// ("intercostal_external", "intercostal_internal", "diaphragm", "rectus", "transversus_obliques",
/// "cartilage").
const char* groupName(ElementGroup g);
/// Inverse of groupName(); returns false when the name is unknown.
bool groupFromName(const std::string& name, ElementGroup& out);
/// True for the groups that follow the one-sided muscle law (Eq. 2); false for structural springs.
inline bool isMuscleGroup(ElementGroup g) { return g != ElementGroup::Cartilage; }

/// A set of points, each bound either to a rigid body (a fixed point in that body's frame) or to up to
/// three gut nodes (barycentric weights). Used for element endpoints, cavity vertices and landmarks.
struct AnchorSet {
  std::vector<int> body;     ///< rigid-body index, or -1 when the point is bound to nodes   (#P)
  Eigen::Matrix3Xd local;    ///< [m] point in the body frame, used when body >= 0            (3 x #P)
  Eigen::Matrix3Xi nodes;    ///< gut node indices, -1 marks an unused slot; used when body < 0 (3 x #P)
  Eigen::Matrix3Xd weights;  ///< [-] barycentric weights of `nodes`, summing to 1             (3 x #P)

  int size() const { return static_cast<int>(body.size()); }
  /// Appends a point fixed in body `b` at body-frame position `p` [m].
  void addBodyPoint(int b, const Eigen::Vector3d& p);
  /// Appends a point bound to nodes `n` with weights `w` (unused slots: node -1, weight 0).
  void addNodePoint(const Eigen::Vector3i& n, const Eigen::Vector3d& w);
};

/// Rigid bodies: bones. Fixed bodies (lumbar spine, pelvis) never move.
struct Bodies {
  std::vector<std::string> name;         ///< unique names, e.g. "rib3_left", "sternum", "thoracic_1" (#B)
  std::vector<std::uint8_t> isFixed;     ///< 1 when the body never moves                            (#B)
  Eigen::VectorXd mass;                  ///< [kg]                                                    (#B)
  Eigen::Matrix3Xd com;                  ///< [m] rest-pose centre of mass in world = frame origin    (3 x #B)
  std::vector<Eigen::Matrix3d> inertia;  ///< [kg m^2] inertia tensor about the com, body frame       (#B)
  std::vector<std::string>
      mesh;  ///< render mesh (.vtp, body-frame coordinates [m]) relative to the model dir; may be empty (#B)
  /// 1 when a postural support holds the body against gravity (#B, or empty: none). The shoulder girdle and
  /// arms hang from the neck and the back by the tone of the trapezius, levator scapulae and rhomboids, not
  /// from the rib cage: a support carries each such body's weight in every posture, f = -m g
  /// (postureGravity()), so that the breathing rib cage does not carry the arms (postureSupport(), Step.h).
  std::vector<std::uint8_t> isSupported;
  /// [m] h_b >= 0, the height above its centre of mass, against gravity in the rest pose, at which the
  /// support carries a supported body's weight (#B, or empty: 0 for every body; 0 where not supported). At
  /// h = 0 the body is weightless; at h > 0 it hangs: the support's force at p = -h g/|g| (body frame) and
  /// the weight at the centre of mass make a couple that turns the body back to its rest orientation as a
  /// pendulum of length h would, m |g| h sin(angle), while its translation stays carried. The arms have
  /// the height of their centre of mass below the shoulder joint, so they hang in the skin's pose from the
  /// blades, which can turn and lift under them (postureSupportPoint(), Step.h).
  Eigen::VectorXd supportHeight;

  int size() const { return static_cast<int>(name.size()); }
  /// Whether body `b` has a postural support.
  bool supported(int b) const {
    return !isSupported.empty() && isSupported[static_cast<std::size_t>(b)] != 0;
  }
  /// Whether any body has a postural support (a model with a shoulder girdle).
  bool anySupported() const {
    return std::find(isSupported.begin(), isSupported.end(), std::uint8_t{1}) != isSupported.end();
  }
  /// [m] supportHeight of body `b` (0 when the model has none).
  double supportHeightOf(int b) const { return supportHeight.size() == 0 ? 0.0 : supportHeight(b); }
};

/// Ball joints (Zordan et al. 2004, Section 5): rib-spine costovertebral joints and the joints
/// between thoracic segments. Joint friction follows Eq. 3, tau = -mu * relative angular velocity.
/// A passive rotational spring acts on the rotation vector theta of the child relative to the parent (world):
///   tau = -K theta,  K = k I + k_lock (I - a a^T),  a = R_parent axis,
/// so k holds every direction (the spine) and k_lock adds a resistance to turning off the axis: a rib whose
/// head (costovertebral joint) and tubercle (costotransverse joint) both articulate turns about its neck
/// axis, the line through the two (De Troyer & Boriek 2011, Compr Physiol 1:1273; Jordanoglou 1969, Thorax
/// 24:407). k_lock = 0 is a plain ball joint.
struct Joints {
  std::vector<std::string> name;  ///< e.g. "costovertebral_rib3_left"        (#J)
  std::vector<int> parent;        ///< body index of the parent (may be fixed) (#J)
  std::vector<int> child;         ///< body index of the child                 (#J)
  Eigen::Matrix3Xd anchor;        ///< [m] rest-pose joint centre, world       (3 x #J)
  Eigen::VectorXd friction;       ///< [N m s/rad] mu of Eq. 3                 (#J)
  Eigen::VectorXd stiffness;      ///< [N m/rad] passive rotational stiffness k, every direction (#J)
  Eigen::Matrix3Xd axis;          ///< [-] unit hinge axis a in the parent frame (= world at rest)   (3 x #J)
  Eigen::VectorXd lockStiffness;  ///< [N m/rad] k_lock against rotation off the axis, 0 = ball joint (#J)

  int size() const { return static_cast<int>(parent.size()); }
};

/// Role of a gut node on the sealed gut surface (Section 6).
enum class NodeRegion : std::uint8_t {
  Wall = 0,       ///< anterior and lateral abdominal wall (moving)
  Diaphragm = 1,  ///< the diaphragm dome (moving)
  Fixed = 2,      ///< the fixed back and bottom, and the dome rim's posterior (crural) arc
  Tissue = 3      ///< a node of a soft-tissue volume body (VolumeBodies: pectoral, shoulder), not of the gut
};

/// Point masses of the deformable bodies: the gut surface (Section 6.1) and the soft-tissue volume bodies
/// (VolumeBodies, region Tissue), which share these arrays.
struct Nodes {
  Eigen::Matrix3Xd rest;           ///< [m] rest positions, world   (3 x #N)
  Eigen::VectorXd mass;            ///< [kg] point masses; moving wall masses add up to 8 kg (#N)
  std::vector<NodeRegion> region;  ///< role of each node           (#N)

  int size() const { return static_cast<int>(rest.cols()); }
  bool isFixed(int i) const { return region[static_cast<std::size_t>(i)] == NodeRegion::Fixed; }
};

/// The sealed, volume-preserving gut (Section 6.2): P = kappa (V0/V - 1) (Eq. 4), with V0 the volume
/// enclosed by `triangles` at the nodes' rest positions.
struct Gut {
  Eigen::Matrix3Xi
      triangles;       ///< node indices, counter-clockwise seen from outside (outward normals) (3 x #F)
  double kappa = 0.0;  ///< [Pa] bulk "volumetric" modulus of Eq. 4
  /// [1/s] beta of the visceral drag f_n = -beta m_n v_n on every free node: the viscosity of the viscera and
  /// abdominal tissue, which the paper's model lacks (our addition, docs/model-format.md). Without it the
  /// gut and the relaxing diaphragm bounce at the end of each inhale (calm: a 120 mL rebound). >= 0.
  double drag = 0.0;
  /// [-] postural tone of the abdominal wall: in the upright posture the transversus and obliques
  /// (ElementGroup::TransversusObliques) work at a set-point shortened by this fraction, l0' = (1 - tone) l0;
  /// lying down they are at rest (effectiveRestLength(), Step.h). Abdominal muscles are silent supine and
  /// tonically active upright (De Troyer 1983, Respir Physiol 53:341; Loring & Mead 1982, J Appl Physiol
  /// 52:700), which stiffens the wall and shifts breathing toward the rib cage. Our addition, in [0, 0.5].
  double wallToneUpright = 0.0;
};

/// Further sealed deformable bodies that keep their volume as the gut does (Section 6.2, Eq. 4, 5): the soft
/// tissue of the pectorals and the shoulders (Zordan et al. 2004, Section 7: "volume-preserving bodies ...
/// attached with a number of strategically placed, zero-length springs"). Each body k is a closed surface
/// over the shared Nodes (region Tissue) with
///   P_k = kappa_k (V0_k / V_k - 1)  (Eq. 4),  f_j = sum_i max[0, P_k A_i n_i / 3]  (Eq. 5),
/// V0_k the volume its triangles enclose at the nodes' rest positions. The springs that shape and carry it
/// (Cartilage elements between its nodes, and from its deep nodes to the bones) are ordinary Elements. The
/// gut is not in this list: it keeps its own block (Gut), and the step treats it by the same kernel. An empty
/// list is a model without them (models written before them).
struct VolumeBodies {
  std::vector<std::string> name;            ///< unique names, e.g. "pectoral_left" (#K)
  std::vector<Eigen::Matrix3Xi> triangles;  ///< node indices, outward normals, one closed surface each (#K)
  Eigen::VectorXd kappa;                    ///< [Pa] bulk modulus kappa_k of Eq. 4, > 0 (#K)

  int size() const { return static_cast<int>(name.size()); }
};

/// Spring elements: muscles (Eq. 2) and structural springs (cartilage).
///   muscle:     F = min[-alpha kac (l - r l0) - kpe (l - l0) - b dl/dt, 0]   (tension only)
///   structural: F = -kpe (l - l0) - b dl/dt                                    (two-sided)
/// F is the signed scalar force along the element (negative = pulling the endpoints together).
struct Elements {
  std::vector<ElementGroup> group;  ///< (#E)
  AnchorSet endA;                   ///< first endpoint  (#E points)
  AnchorSet endB;                   ///< second endpoint (#E points)
  Eigen::VectorXd restLength;       ///< [m] l0 > 0            (#E)
  Eigen::VectorXd kac;              ///< [N/m] active gain      (#E)
  Eigen::VectorXd kpe;              ///< [N/m] passive gain     (#E)
  Eigen::VectorXd damping;          ///< [N s/m] b              (#E)
  /// [-] recruitment threshold c0 in [0, 1) of a muscle recruited only above a level of its group's drive
  /// (#E, or empty: none; 0 = an ordinary element). The group's command is its active tension at rest length
  /// per kac l0, c = alpha (1 - r); a recruited element works at the command left above its threshold, max(0,
  /// c - c0) (recruitedActivation(), Elements.h). The shoulder girdle's accessory inspiratory muscles use it
  /// (docs/model-format.md).
  Eigen::VectorXd recruitment;
  /// 1 for a gliding spring (#E, or empty: none): a cartilage spring that holds one bone on another while
  /// letting it slide, like the scapulothoracic springs that hold the shoulder blade on the ribs. Its far end
  /// is a virtual anchor deep inside the other bone's side, on the spring's line (a slide s lengthens it by
  /// about s^2 / 2 l), so views draw no line for it (isDrawn(), Ties.h).
  std::vector<std::uint8_t> isGliding;

  int size() const { return static_cast<int>(group.size()); }
  /// [-] recruitment threshold c0 of element `e` (0 when the model has none).
  double recruitmentOf(int e) const { return recruitment.size() == 0 ? 0.0 : recruitment(e); }
  /// Whether element `e` is a gliding spring.
  bool glides(int e) const { return !isGliding.empty() && isGliding[static_cast<std::size_t>(e)] != 0; }
};

/// Closed lung-cavity surface (Figure 6): its vertices are anchors, so its volume can be recomputed
/// from the current bone poses and diaphragm nodes at every step.
///
/// The lungs' elastic recoil acts on the cavity's walls as a pleural pressure (our addition; the paper has
/// none):
///   Ppl = min(0, -(P0 + (V - Vr) / C)),  f_i = Ppl dV/dx_i  (suction: the walls are pulled inward),
/// with V the cavity volume, Vr its rest volume, P0 = recoilPressure the recoil at rest and C = compliance
/// the lung compliance. It holds the diaphragm's dome up against the weight it carries (upright, resting Pdi
/// is about 3 cmH2O) and is the force of passive expiration. Relaxed FRC: lung recoil +5 cmH2O (Ppl -5
/// cmH2O); lung compliance about 0.2 L/cmH2O (Naimark & Cherniack 1960, J Appl Physiol 15:377; Guyton &
/// Hall). compliance 0 turns it off (models written before it).
struct Cavity {
  AnchorSet vertices;           ///< (#C points)
  Eigen::Matrix3Xi triangles;   ///< vertex indices, outward normals (3 x #T)
  double recoilPressure = 0.0;  ///< [Pa] P0, the lungs' elastic recoil at the rest volume, >= 0
  double compliance = 0.0;      ///< [m^3/Pa] C, the lung compliance; 0 = no pleural pressure
};

constexpr int kLungVertexSlots = 6;  ///< cavity vertices one lung vertex may combine (LungSurface)

/// One lung's closed surface, embedded in the lung cavity (ArtiSynth-style embedding): each vertex is a
/// convex combination of up to six cavity vertices, x_v = sum_k w_k c_{i_k}, with c the posed cavity vertices
/// (Cavity). A vertex on a cavity wall takes the three corners of the cavity triangle it lies on, so the
/// lung's costal and diaphragmatic faces move with the walls exactly; a vertex on the mediastinal face takes
/// the two cavity points at the ends of a chord through it in the face's plane (three corners each), the
/// chord that meets a wall soonest, so that the face follows the walls nearest to each of its points.
struct LungSurface {
  Eigen::Matrix<int, 6, Eigen::Dynamic>
      cavityVertex;  ///< cavity vertex indices, -1 marks an unused slot (6 x #V)
  Eigen::Matrix<double, 6, Eigen::Dynamic>
      weights;                 ///< [-] >= 0, summing to 1; 0 in unused slots     (6 x #V)
  Eigen::Matrix3Xi triangles;  ///< vertex indices, outward normals             (3 x #T)

  int vertexCount() const { return static_cast<int>(cavityVertex.cols()); }
};

/// The two lungs: the lung cavity minus the mediastinum (heart, great vessels, trachea, oesophagus, the
/// vertebral bodies' bulge), split at the midline. The heart and the mediastinum are incompressible, so the
/// lungs' volume is the cavity's volume minus a constant:
///   V_lungs = V_cavity - V_med,  V_right = V_lungs s_R,  V_left = V_lungs (1 - s_R),
/// with s_R = V(right surface) / (V(right surface) + V(left surface)) of the posed surfaces, about 0.535 at
/// rest (right 53.5 %, left 46.5 %: Yamada et al. 2020, "Lung volumes on CT, upright and supine", Sci Rep
/// 10:19434). The tidal swing of V_lungs is thus exactly the cavity's. The surfaces are for display, export
/// and the split. An empty Lungs (no surfaces, V_med = 0) makes the lungs the cavity (in-memory test models).
struct Lungs {
  LungSurface right;  ///< the right lung (x > 0: world RAS, +x toward the subject's right)
  LungSurface left;   ///< the left lung
  double mediastinumVolume =
      0.0;  ///< [m^3] V_med, the part of the cavity's rest volume the lungs do not fill, >= 0
};

constexpr int kSkinVertexSlots = 4;  ///< anchors one skin vertex may combine (Skin)

/// The body surface (skin), bound to the bones and the gut through the soft tissue between them (built by
/// meshing/src/Skin.cpp, docs/model-format.md "skin"). Each vertex is a fixed affine combination of anchor
/// points, so posing it is pure data:
///   x_v = c_v + sum_k w_vk a_{i_vk},   sum_k w_vk = 1,
/// with a the posed anchors (anchorPositions() of `anchors`: bone-frame points and gut-node points) and c_v a
/// constant offset [m]. A vertex that follows one bone rigidly has a single anchor, a point of that bone at
/// the vertex itself (c_v = 0). A vertex of the soft tissue over moving parts blends the displacements of the
/// anchors nearest it through the tissue (c_v = rest position minus the anchors' weighted rest positions).
/// The weights come from a TetGen tetrahedralisation of the volume inside the skin (`tetrahedra` counts it).
/// An empty Skin (no vertices) is a model without a skin.
struct Skin {
  AnchorSet anchors;  ///< points the skin is bound to: bone-frame points and gut nodes (#A points)
  Eigen::Matrix<int, kSkinVertexSlots, Eigen::Dynamic>
      anchor;  ///< indices into `anchors`, -1 marks an unused slot (4 x #V)
  Eigen::Matrix<double, kSkinVertexSlots, Eigen::Dynamic>
      weights;                 ///< [-] w_vk >= 0, summing to 1; 0 in unused slots (4 x #V)
  Eigen::Matrix3Xd offset;     ///< [m] c_v (3 x #V)
  Eigen::Matrix3Xi triangles;  ///< vertex indices, outward normals (3 x #T)
  int tetrahedra = 0;          ///< [-] TetGen tetrahedra of the soft tissue the weights were computed on

  int vertexCount() const { return static_cast<int>(anchor.cols()); }
};

/// Named points for measurement, bound like cavity vertices.
/// Required names: "xiphoid", "umbilicus", "diaphragm_apex", "rib8_lateral_left", "rib8_lateral_right".
struct Landmarks {
  std::vector<std::string> name;  ///< (#L)
  AnchorSet points;               ///< (#L points)

  /// Index of a landmark by name, or -1.
  int find(const std::string& n) const;
};

/// The whole immutable model.
struct Model {
  std::string name;                          ///< e.g. "adult_male"
  std::string anatomy;                       ///< anatomy preset it was built from
  Eigen::Vector3d gravity{0.0, 0.0, -9.81};  ///< [m/s^2] upright (postureGravity() turns it)
  Bodies bodies;
  Joints joints;
  Nodes nodes;
  Gut gut;
  VolumeBodies volumes;  ///< may be empty (models written before the soft-tissue volume bodies)
  Elements elements;
  Cavity cavity;
  Lungs lungs;
  Landmarks landmarks;
  Skin skin;  ///< may be empty (models written before the skin)
};

}  // namespace pneuma::sim
