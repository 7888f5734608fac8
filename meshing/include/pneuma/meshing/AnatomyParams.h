#pragma once
/// @file AnatomyParams.h
/// The measurements a torso is built from (resources/anatomy/*.json, sources in resources/anatomy/README.md),
/// and the gains of its spring elements (resources/anatomy/muscle_gains.json, the single source of gains).
///
/// Files store millimetres and degrees; AnatomyParams holds SI units (metres, radians) after loading.
/// World frame (RAS): +x right, +y anterior, +z superior; z = 0 at the L5/S1 disc, y = 0 at the
/// vertebral body centres of the lumbar spine.

#include <array>
#include <string>
#include <vector>

#include "pneuma/sim/Model.h"

namespace pneuma::meshing {

/// One rib level (Kindig & Kent 2013; Holcombe et al. 2016). The centreline lies in a plane through the
/// costovertebral joint. In that plane it is a "half-egg" curve: from the head it runs posterolaterally
/// round the rib angle (posterior semi-axis), laterally (lateral semi-axis) and anteriorly (anterior
/// semi-axis) to the costochondral junction at `endAngle`. The lateral semi-axis is solved so that the
/// centreline has `arcLength`. The plane is then pitched down anteriorly by `inclination` (the
/// complement of the rib-spine angle) and tilted down laterally by `lateralTilt` (bucket handle).
struct RibLevel {
  double arcLength = 0.0;       ///< [m] centreline length, head to costochondral junction
  double posteriorRatio = 0.0;  ///< [-] posterior semi-axis / lateral semi-axis
  double anteriorRatio = 0.0;   ///< [-] anterior semi-axis / lateral semi-axis
  double endAngle = 0.0;  ///< [rad] curve parameter of the costochondral junction (3 pi / 2 = most anterior)
  double inclination = 0.0;  ///< [rad] anterior descent of the rib plane below horizontal
  double lateralTilt = 0.0;  ///< [rad] lateral descent of the rib plane below horizontal
  double height = 0.0;       ///< [m] cross-section height (superior-inferior)
  double thickness = 0.0;    ///< [m] cross-section thickness (inner-outer)
  /// [rad] direction of the rib-neck axis (head to tubercle, the axis the rib turns about) in the horizontal
  /// plane, measured from the left-right axis toward posterior: 0 = transverse (pure pump handle), 90 deg =
  /// anteroposterior (pure bucket handle). resources/anatomy/README.md has the values and their sources.
  double neckAxis = 0.0;
};

/// Vertebral column: bodies stacked upward from z = 0 (L5 bottom).
struct SpineParams {
  std::vector<double> lumbarHeights;           ///< [m] vertebral body heights L5..L1 (5)
  std::vector<double> thoracicHeights;         ///< [m] vertebral body heights T12..T1 (12)
  double lumbarDisc = 0.0;                     ///< [m] lumbar disc height
  double thoracicDisc = 0.0;                   ///< [m] thoracic disc height
  std::array<double, 2> lumbarBody{};          ///< [m] lumbar body width and depth
  std::array<double, 2> thoracicBodyTop{};     ///< [m] T1 body width and depth
  std::array<double, 2> thoracicBodyBottom{};  ///< [m] T12 body width and depth
  double kyphosis = 0.0;                       ///< [m] posterior bulge of the thoracic curve at its middle
  double spinousLength = 0.0;                  ///< [m] posterior reach of a spinous process behind its body
  std::vector<std::array<int, 2>>
      thoracicSegments;  ///< first and last vertebra (1..12) of each articulated segment
};

/// Sternum (Selthofer et al. 2006): a plate running down and forward from the jugular notch.
struct SternumParams {
  double manubriumLength = 0.0;  ///< [m]
  double bodyLength = 0.0;       ///< [m]
  double xiphoidLength = 0.0;    ///< [m]
  double manubriumWidth = 0.0;   ///< [m]
  double bodyWidth = 0.0;        ///< [m]
  double thickness = 0.0;        ///< [m]
  double notchLevel = 0.0;       ///< [-] thoracic vertebra (1..12, fractional) level with the jugular notch
  double notchDepth = 0.0;       ///< [m] anterior distance from the T1-T12 body centres to the notch
  double inclination = 0.0;      ///< [rad] angle of the sternum to the vertical (lower end forward)
};

/// Pelvis: fixed, drawn as two iliac wings and the sacrum.
struct PelvisParams {
  double width = 0.0;   ///< [m] bi-iliac (crest) breadth
  double depth = 0.0;   ///< [m] anterior reach of the anterior superior iliac spines from the spine
  double height = 0.0;  ///< [m] iliac wing height
};

/// Abdominal cavity (the gut body of Section 6) and the diaphragm dome on top of it.
struct AbdomenParams {
  double floorLevel = 0.0;      ///< [m] z of the pelvic floor (below L5/S1, negative)
  double width = 0.0;           ///< [m] inner transverse diameter of the cavity at the umbilicus
  double anteriorDepth = 0.0;   ///< [m] reach of the anterior wall in front of the lumbar body centre
  double posteriorDepth = 0.0;  ///< [m] reach of the posterior wall (beside the spine) behind it
  double domeHeight = 0.0;      ///< [m] rise of the diaphragm apex above the costal margin's mean level
  /// [m] craniocaudal extent of the zone of apposition: a dome node at most this far above the costal margin
  /// below it (the dome rim at the same angle) lies on the inner face of the lower rib cage and is held there
  /// (MuscleNetwork's apposition springs). Mead 1979: a quarter to a third of the rib cage's inner surface in
  /// quiet upright breathing; resources/anatomy/README.md has the values and their derivation.
  double appositionHeight = 0.0;
  /// [m] farthest a dome node in the zone of apposition may lie from the rib face it is held on
  double appositionReach = 0.0;
  double umbilicusLevel = 0.0;  ///< [m] z of the umbilicus
};

/// Sampling resolution of the generated meshes and networks.
struct Resolution {
  double boneEdge = 0.0;       ///< [m] isotropic remeshing target edge length of the bones
  int wallRings = 0;           ///< rings of gut nodes from the pelvic floor to the costal margin
  int ringNodes = 0;           ///< nodes per wall ring
  int domeRings = 0;           ///< rings of the diaphragm dome between the central tendon and the rim
  int domeRimNodes = 0;        ///< nodes on the rim of the dome (costal margin)
  int intercostalSamples = 0;  ///< elements per rib pair, side and intercostal layer
};

/// Muscle and spring gains of one group. Each element gets k = gain * referenceLength / restLength
/// (springs in series: a chain of elements behaves like one muscle of stiffness `gain` over referenceLength).
struct GroupGains {
  double kac = 0.0;      ///< [N/m] active gain at the reference length
  double kpe = 0.0;      ///< [N/m] passive gain at the reference length
  double damping = 0.0;  ///< [N s/m] at the reference length
};

/// The neck's accessory inspiratory muscles with the shoulder girdle (muscle_gains.json `accessory_muscles`):
/// the sternocleidomastoids and the upper trapezius, recruited above calm demand
/// (sim::recruitedActivation()).
struct AccessoryGains {
  double kac = 0.0;          ///< [N/m] active gain at the reference length (0: passive, as without the block)
  double recruitment = 0.0;  ///< [-] recruitment threshold c0 on the external intercostals' command, [0, 1)
};

/// Gains of one kind of joint (muscle_gains.json `joints.<kind>`; sim::Joints has the law).
struct JointGains {
  double friction = 0.0;       ///< [N m s/rad] mu of Eq. 3
  double stiffness = 0.0;      ///< [N m/rad] k, every direction
  double lockStiffness = 0.0;  ///< [N m/rad] k_lock against turning off the joint's axis (0: a ball joint)
};

/// The kinds of joint, each one row of muscle_gains.json `joints`: "spine" (between thoracic segments),
/// "costovertebral" (rib heads; its lock stands for the costotransverse joint), and the shoulder girdle's
/// "sternoclavicular", "acromioclavicular", "glenohumeral" and "elbow" (a hinge: its lock holds the flexion
/// axis).
enum JointKind : int {
  kSpineJoint = 0,
  kCostovertebralJoint,
  kSternoclavicularJoint,
  kAcromioclavicularJoint,
  kGlenohumeralJoint,
  kElbowJoint
};
constexpr std::array<const char*, 6> kJointKinds = {
    "spine", "costovertebral", "sternoclavicular", "acromioclavicular", "glenohumeral", "elbow"};

/// The soft-tissue volume bodies over the chest and shoulders (sim::VolumeBodies, built by TissueBodies.cpp),
/// muscle_gains.json `tissue_bodies` (optional: none when absent).
struct TissueGains {
  double kappa = 0.0;    ///< [Pa] bulk modulus of Eq. 4 of every tissue body; 0: no tissue bodies
  double density = 0.0;  ///< [kg/m^3] a body's mass is density x its rest volume, shared equally by its nodes
  /// [N/m], [N s/m] kpe and b (kac unused) of the springs along the surface edges and through the thickness,
  /// at the reference length
  GroupGains surface{};
  /// [N/m], [N s/m] kpe and b of each of the three springs tying a deep node to its bone (20 mm arms, the
  /// reference length's scaling applied to them)
  GroupGains tie{};
  double pectoralThickness = 0.0;  ///< [m] largest thickness of a pectoral lens over the chest wall
  double deltoidThickness = 0.0;   ///< [m] largest thickness of a shoulder (deltoid) cap
};

/// Everything of resources/anatomy/muscle_gains.json.
struct Gains {
  double referenceLength = 0.0;  ///< [m] element length at which the group gains apply unscaled
  std::array<GroupGains, sim::kElementGroupCount> group{};  ///< indexed by sim::ElementGroup
  double gutKappa = 0.0;                                    ///< [Pa] bulk modulus of Eq. 4
  double gutDrag = 0.0;  ///< [1/s] visceral drag rate beta (sim::Gut::drag)
  double wallToneUpright =
      0.0;                  ///< [-] abdominal wall's upright set-point shortening (sim::Gut::wallToneUpright)
  double lungRecoil = 0.0;  ///< [Pa] lung recoil at the rest volume (sim::Cavity::recoilPressure)
  double lungCompliance = 0.0;  ///< [m^3/Pa] lung compliance (sim::Cavity::compliance)
  /// [-] stiffness and damping of the apposition springs (the outer dome held on the lower ribs' inner face)
  /// as a fraction of the cartilage group's
  double appositionFraction = 0.0;
  /// [-] scale of the external intercostals' kac in space k (between ribs k and k+1), k = 1..11, entry k - 1:
  /// the neural drive of the external intercostals falls from the rostral to the caudal spaces, matching
  /// their inspiratory mechanical advantage, and the caudal spaces are nearly silent in quiet breathing (De
  /// Troyer, Kirkwood & Wilson 2005, Physiol Rev 85:717; De Troyer, Gorman & Gandevia 2002, J Physiol
  /// 546:943)
  std::array<double, 11> externalIntercostalSpaceScale{1, 1, 1, 1, 1, 1, 1, 1, 1, 1, 1};
  /// [-] stiffness of rib 1's costal cartilage as a multiple of the cartilage group's: the first sternocostal
  /// joint is a synchondrosis, rib 1 and the manubrium move as one, while joints 2-7 are synovial (Gray's
  /// Anatomy, the sternocostal joints). muscle_gains.json `first_costal_cartilage_stiffness_scale`
  /// (optional, 1 when absent)
  double firstCartilageScale = 1.0;
  /// [N/m], [N s/m] kac, kpe and b of the scalenes (rib 1 to the neck) at the reference length. They are
  /// inspiratory muscles driven with the external intercostals: they fire with every quiet breath and hold
  /// rib 1 up against the pull of the first space's external intercostals; without them the upper rib cage
  /// moves paradoxically (De Troyer & Estenne 1984, J Appl Physiol 57:899). muscle_gains.json `scalenes`
  /// (optional: passive springs with the cartilage group's kpe and b when absent)
  GroupGains scalenes{};
  /// gains per kind of joint, indexed by JointKind
  std::array<JointGains, kJointKinds.size()> joints{};
  /// [N/m], [N s/m] kpe and damping (kac unused) of the shoulder girdle's passive springs at the reference
  /// length: Zordan et al. 2004, Table 1, the 52 shoulder elements (kpe 10, b 1), and the
  /// sternocleidomastoids
  GroupGains shoulder{};
  /// [N/m] kpe of the shoulder springs that hang the girdle from the neck (levator scapulae, the rhomboid
  /// from C7, and the passive part of the upper trapezius): the postural tone that holds the shoulders'
  /// height (muscle_gains.json `shoulder_springs.suspension_kpe`; optional, the shoulder kpe when absent)
  double shoulderSuspension = 0.0;
  AccessoryGains accessory{};  ///< the sternocleidomastoids' and upper trapezius' drive
  /// [N/m], [N s/m] kpe and b (kac unused) of the scapulothoracic gliding springs that hold each scapula's
  /// front face off the ribs under it (muscle_gains.json `scapulothoracic`; optional, kpe 0 and none when
  /// absent)
  GroupGains scapulothoracic{};
  TissueGains tissue{};        ///< the pectoral and shoulder volume bodies
  double wallMass = 0.0;       ///< [kg] total mass of the moving abdominal-wall nodes (8 kg, Section 6.1)
  double diaphragmMass = 0.0;  ///< [kg] total mass of the diaphragm dome nodes
};

/// The shoulder girdle, arms and neck (anatomy option `shoulder_girdle`): segment lengths and masses of the
/// arms after de Leva 1996 (J Biomech 29:1223, Table 4), the arms in the A-pose of the skin mesh.
struct GirdleParams {
  double bodyMass = 0.0;              ///< [kg] whole-body mass the arm segments are a fraction of
  double clavicleLength = 0.0;        ///< [m] sternoclavicular to acromioclavicular joint
  double upperArmLength = 0.0;        ///< [m] shoulder to elbow joint centre
  double forearmLength = 0.0;         ///< [m] elbow to wrist joint centre
  double handLength = 0.0;            ///< [m] wrist to the tip of the middle finger
  double upperArmMassFraction = 0.0;  ///< [-] of bodyMass
  double forearmMassFraction = 0.0;   ///< [-] of bodyMass
  double handMassFraction = 0.0;      ///< [-] of bodyMass (carried by the forearm's body)
  double abduction = 0.0;             ///< [rad] the upper arm's angle from the vertical in the frontal plane
  double elbowFlexion = 0.0;          ///< [rad] the forearm's angle forward from the upper arm's line
};

/// A whole anatomy preset.
struct AnatomyParams {
  std::string name;                    ///< preset name, e.g. "adult_male"
  std::string source;                  ///< file it was read from
  double boneDensity = 0.0;            ///< [kg/m^3] uniform bone density for mass properties
  bool areFloatingRibsMoving = false;  ///< ribs 11-12: moving bodies (true) or fixed (false)
  /// [-] scale of the costovertebral joints' friction (muscle_gains.json `joints.costovertebral.friction`, mu
  /// of Eq. 3) in this preset: mu = scale x the shared value (optional, 1 when absent). The rib cage's
  /// resistance to motion, the one preset-specific term of the rib-cage share: women breathe with a larger
  /// rib-cage contribution than men (Bellemare, Jeanneret & Couture 2003, Am J Respir Crit Care Med 168:305;
  /// Romei et al. 2010, Respir Physiol Neurobiol 172:184), so the female preset's value is the round value
  /// that gives it at least the male preset's rib-cage share in calm and deep breathing.
  /// resources/anatomy/README.md has the measurements and why it is not the rib-cage muscles' strength.
  double ribJointFrictionScale = 1.0;
  std::vector<RibLevel> ribs;  ///< rib levels 1..12 (index 0 = rib 1)
  SpineParams spine;
  SternumParams sternum;
  PelvisParams pelvis;
  AbdomenParams abdomen;
  Resolution resolution;
  Gains gains;
  /// build the shoulder girdle, arms, neck and head (`shoulder_girdle`, default false): clavicles, scapulae,
  /// humeri and forearms as moving bodies, the cervical spine and head fixed
  bool hasShoulderGirdle = false;
  GirdleParams girdle;  ///< read when present; required when hasShoulderGirdle
};

/// Reads and validates an anatomy preset and the gains file it names ("gains", relative to the preset).
/// @throws sim::Error naming the file and field, e.g. "male.json: ribs[3].arc_length_mm: must be > 0, got
/// -5".
AnatomyParams loadAnatomy(const std::string& path);

/// Parses an anatomy preset from JSON text; `gainsText` is the text of its gains file. The names are
/// used in error messages only. @throws sim::Error as loadAnatomy().
AnatomyParams parseAnatomy(const std::string& anatomyText, const std::string& gainsText,
                           const std::string& sourceName = "anatomy.json",
                           const std::string& gainsName = "muscle_gains.json");

}  // namespace pneuma::meshing
