#pragma once
/// @file ModelScene.h
/// The 3D scene of a Pneuma model (Zordan et al. 2004, Figures 2 and 3): shaded bones, muscle
/// elements drawn as tube-shaded lines coloured by contractive force (slack ones grey) or by group,
/// the gut surface coloured by pressure or displacement, the lung cavity, landmarks and teaching labels,
/// on a ParaView-like backdrop with an RAS orientation marker. Qt-free: the GUI puts renderer() into a
/// QVTKOpenGLNativeWidget, the CLI into an off-screen window.

#include <vtkSmartPointer.h>

#include <array>
#include <memory>
#include <string>
#include <vector>

#include "pneuma/sim/Metrics.h"
#include "pneuma/sim/Model.h"
#include "pneuma/sim/MorphTargets.h"
#include "pneuma/sim/PosedGeometry.h"
#include "pneuma/sim/State.h"

class vtkPolyData;
class vtkRenderer;
class vtkRenderWindowInteractor;

namespace pneuma::viz {

/// How muscle elements are coloured: by the tension of each element [N], by its group's activation alpha
/// [0, 1] (Eq. 2), or by group (Figure 2).
enum class MuscleColouring { Force, Activation, Group };
/// How the gut surface is coloured.
enum class GutColouring { Plain, Pressure, Displacement };
/// How the skin is shown.
enum class SkinDisplay { Hidden, Translucent, Opaque };
/// How the skin is coloured: plain skin tone, or its displacement from the breath's end-expiratory pose in mm
/// (a breathing heat map: calm breathing moves the chest and belly 1-4 mm, a deep breath 5-15 mm).
enum class SkinColouring { Plain, Displacement };

/// Fixed colour scales: one range per quantity on every frame of every run, so that a colour always means the
/// same value and the legend never jumps (DisplayOptions::isAutoRange trades this for a range fitted to the
/// run). Displacements are the real ones (never magnified), from the breath's end-expiratory pose.
constexpr double kTensionTop =
    20.0;  ///< [N] per-element tension: about the largest force of the strip of muscle
           ///< one element stands for (11-19 N, resources/anatomy/README.md)
constexpr double kActivationTop = 1.0;         ///< [-] activation alpha, Eq. 2: [0, 1]
constexpr double kGutDisplacementTop = 20.0;   ///< [mm] gut: a deep breath's dome descent
constexpr double kSkinDisplacementTop = 10.0;  ///< [mm] skin: a deep breath's chest-wall motion
constexpr double kGutPressureTop = 20.0;  ///< [cmH2O] gut pressure, on [-top, top] (calm upright: 5-10 cmH2O)
/// [-] the percentile of the values whose rounded-up value tops an auto-ranged scale
constexpr double kAutoRangePercentile = 0.95;

/// The labels of a colour legend over [lo, hi], as the legend shows them: the plots' ticks (viz::niceTicks(),
/// a step of 1, 2 or 5 x 10^n) written without trailing zeros or exponents ("0", "5", ..., "20"; "0", "0.2",
/// ..., "1").
std::vector<std::string> legendLabels(double lo, double hi);
/// The smallest of 1, 2, 5 x 10^n not below `v` (1 for v <= 0): the top of an auto-ranged scale.
double niceCeil(double v);
constexpr double kSkinTranslucency = 0.3;  ///< [-] opacity of the translucent skin

/// Motion magnification (display only): the view draws every displacement from the end-expiratory pose
/// (bones, muscles, gut, lungs, skin) this many times larger (sim::magnifyMotion()), so that calm breathing,
/// a few millimetres at the chest wall, is visible; the view says so ("motion x5"). Plots, read-outs and
/// exported numbers are never magnified.
constexpr double kMinMagnification = 1.0;      ///< [-]
constexpr double kMaxMagnification = 20.0;     ///< [-]
constexpr double kDefaultMagnification = 5.0;  ///< [-] makes a calm breath visible across a lecture hall
/// Empty when `factor` is a valid magnification, else the one-line reason ("motion magnification: 25 is
/// outside [1, 20]").
std::string magnificationError(double factor);

/// Camera presets, looking at the whole model: from the front, the left side, above, behind, and obliquely
/// from the front left.
enum class CameraPreset { Anterior, Lateral, Superior, Posterior, Oblique };
/// Every camera preset with its lowercase name ("anterior", ...), in the order the app lists them.
const std::vector<std::pair<std::string, CameraPreset>>& cameraPresets();

/// Human-readable name of an element group for legends and labels ("External intercostals", ...).
const char* groupLabel(sim::ElementGroup g);
/// Display colour (RGB in [0, 1]) of an element group, after Figure 2 of Zordan et al. 2004.
std::array<double, 3> groupColour(sim::ElementGroup g);
/// Display colour (RGB in [0, 1]) of the accessory inspiratory muscles (elements with a recruitment
/// threshold, sim::Elements::recruitment: the sternocleidomastoids and upper trapezius of a model with the
/// shoulder girdle), which the external intercostals' drive recruits: amber, apart from that group's green.
constexpr std::array<double, 3> kAccessoryColour{0.96, 0.72, 0.16};

/// What is drawn and how. Defaults: the teaching view of Figure 3 (force-coloured muscles, slack grey).
/// Reads a body's render mesh (.vtp, body-frame coordinates [m]) with point normals for shading.
/// @throws sim::Error naming the body ("bodies.<name>.mesh: ...") when the file is missing or unreadable.
vtkSmartPointer<vtkPolyData> readBodyMesh(const std::string& path, const std::string& bodyName);

struct DisplayOptions {
  MuscleColouring muscleColouring = MuscleColouring::Force;
  GutColouring gutColouring = GutColouring::Displacement;
  bool isGutTranslucent = true;
  bool showBones = true;
  bool showGut = true;
  /// the soft-tissue volume bodies (Model::volumes: the pectorals and shoulders), muscle-red
  bool showTissue = true;
  bool showCavity = false;
  bool showLungs = true;  ///< the right and left lungs, translucent (Model::lungs)
  bool showLandmarks = true;
  bool showLabels = false;
  /// the skin (Model::skin): translucent by default, so that a lecturer sees the body's outline and the rib
  /// cage, muscles and gut breathing inside it
  SkinDisplay skin = SkinDisplay::Translucent;
  SkinColouring skinColouring = SkinColouring::Plain;
  std::array<bool, sim::kElementGroupCount> showGroup{true, true, true, true, true, true};
  /// each colour scale topped at the kAutoRangePercentile of its values so far in the run (rounded up by
  /// niceCeil(), never shrinking until the model or this option changes) instead of its fixed range
  bool isAutoRange = false;
  double magnification = kDefaultMagnification;  ///< [-] motion magnification, in [kMinMagnification,
                                                 ///< kMaxMagnification]
  /// the ghost of a compared run (ModelScene::setGhost()), when there is one
  bool showGhost = true;
};

/// What a pick in the view hit.
struct Pick {
  enum class Kind { None, Element, Body } kind = Kind::None;
  int index = -1;  ///< element or body index
};

/// Owns the renderer of one 3D view and the actors of one model.
class ModelScene {
 public:
  ModelScene();
  ~ModelScene();
  ModelScene(const ModelScene&) = delete;
  ModelScene& operator=(const ModelScene&) = delete;

  /// The renderer to add to a render window.
  vtkRenderer* renderer() const;

  /// Shows the RAS axes (x right, y anterior, z superior) in the lower-left corner of the view
  /// driven by `interactor` (the marker is a widget, so it needs the window's interactor).
  void installOrientationMarker(vtkRenderWindowInteractor* interactor);

  /// Replaces the drawn model. Body meshes (.vtp, body frame [m]) are read relative to `modelDir`;
  /// bodies without a mesh are drawn as a small sphere at their centre of mass.
  /// @throws sim::Error when a body mesh cannot be read (naming the body and file).
  void setModel(const sim::Model& model, const std::string& modelDir);

  /// Moves everything to `state` and colours it from `metrics` (elementForce [N], gutPressure [Pa]).
  /// `state` and `metrics` must belong to the model given to setModel(). With `endExpiration` (the
  /// end-expiratory state of the breath, Snapshot::endExpiration) the motion from it is drawn magnified
  /// DisplayOptions::magnification times; without it the state is drawn as it is.
  void update(const sim::State& state, const sim::Metrics& metrics,
              const sim::State* endExpiration = nullptr);

  /// The ghost of a second run (runs side by side, e.g. calm breathing beside a paralysed hemidiaphragm): its
  /// gut and lungs drawn light grey and translucent over this run, posed from `state` (a state of the same
  /// model) with the motion from `endExpiration` magnified as update() magnifies this run's. A null `state`
  /// removes it; DisplayOptions::showGhost hides it.
  void setGhost(const sim::State* state, const sim::State* endExpiration = nullptr);
  /// Whether a ghost is drawn now.
  bool isGhostShown() const;

  /// The geometry as drawn by the last update() (magnified) [m].
  const sim::PosedGeometry& posed() const;
  /// The caption the view shows: the morph playback, if on, and the magnification ("morph playback: panic, no
  /// physics \u00b7 motion \u00d75"; "motion \u00d75"; empty at 1x without playback).
  std::string motionCaption() const;

  /// Morph playback (de Melo et al. 2010, docs/app.md): with a non-empty `affect` the view shows the skin,
  /// plain (no colouring), and the baked bones (MorphTargets::bones, posed by the same weights), and hides
  /// the muscles, gut, lungs, landmarks, labels and colour bars (the playback does not move them); the
  /// caption names the affect. Empty: back to the physics view (the next update() moves everything back).
  void setMorphPlayback(const std::string& affect);
  /// The affect of the morph playback on show; empty when the physics is shown.
  const std::string& morphPlayback() const;
  /// Poses the playback from morph weights w (#K): the skin at base + m sum_k w_k D_k and the baked bones at
  /// sim::blendBones(targets, m w), m the magnification, so that skin and bones move together (posed() holds
  /// the bones' poses). Ignored when `targets` do not fit the model's skin.
  void updateMorphPlayback(const sim::MorphTargets& targets, const Eigen::VectorXd& weights);

  /// Applies display options (visibility, colouring, translucency).
  void setOptions(const DisplayOptions& options);
  const DisplayOptions& options() const;

  /// Points the camera at the whole model from a preset direction.
  void setCamera(CameraPreset preset);

  /// The element or body under display pixel (x, y) (VTK display coordinates, origin bottom-left).
  Pick pick(int x, int y) const;
  /// Highlights one element or body (Kind::None clears the highlight).
  void setHighlight(const Pick& pick);

  /// Display name of an element ("diaphragm element 12") or a body (its model name).
  std::string describe(const Pick& pick) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> m_impl;
};

}  // namespace pneuma::viz
