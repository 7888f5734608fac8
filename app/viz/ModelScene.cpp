#include "viz/ModelScene.h"

#include <vtkActor.h>
#include <vtkAxesActor.h>
#include <vtkCallbackCommand.h>
#include <vtkCamera.h>
#include <vtkCaptionActor2D.h>
#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkCellPicker.h>
#include <vtkColorTransferFunction.h>
#include <vtkCoordinate.h>
#include <vtkCullerCollection.h>
#include <vtkDoubleArray.h>
#include <vtkFloatArray.h>
#include <vtkIdList.h>
#include <vtkIntArray.h>
#include <vtkLookupTable.h>
#include <vtkOpenGLPolyDataMapper.h>
#include <vtkOpenGLVertexBufferObject.h>
#include <vtkOrientationMarkerWidget.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkPolyDataMapper.h>
#include <vtkPolyDataNormals.h>
#include <vtkPropCollection.h>
#include <vtkProperty.h>
#include <vtkProperty2D.h>
#include <vtkQuadricDecimation.h>
#include <vtkRenderStepsPass.h>
#include <vtkRenderWindow.h>
#include <vtkRenderWindowInteractor.h>
#include <vtkRenderer.h>
#include <vtkScalarBarActor.h>
#include <vtkSphereSource.h>
#include <vtkStaticCellLocator.h>
#include <vtkTextActor.h>
#include <vtkTextProperty.h>
#include <vtkTextRenderer.h>
#include <vtkUnsignedCharArray.h>
#include <vtkXMLPolyDataReader.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <initializer_list>
#include <limits>
#include <sstream>

#include "pneuma/sim/Error.h"
#include "pneuma/sim/PosedGeometry.h"
#include "pneuma/sim/Ties.h"
#include "viz/PlotLayout.h"

namespace pneuma::viz {

namespace {

constexpr int kGroups = sim::kElementGroupCount;

// a 256-entry lookup table sampled from a piecewise-linear colour ramp of (value in [0, 1], r, g, b) points
vtkSmartPointer<vtkLookupTable> makeRampTable(std::initializer_list<std::array<double, 4>> points) {
  vtkNew<vtkColorTransferFunction> ramp;
  for (const auto& p : points) ramp->AddRGBPoint(p[0], p[1], p[2], p[3]);
  auto table = vtkSmartPointer<vtkLookupTable>::New();
  table->SetNumberOfTableValues(256);
  for (int i = 0; i < 256; ++i) {
    double rgb[3];
    ramp->GetColor(i / 255.0, rgb);
    table->SetTableValue(i, rgb[0], rgb[1], rgb[2], 1.0);
  }
  return table;
}

// colour scale of contractive force: pale orange (weak) to deep red (strong), never grey or blue
vtkSmartPointer<vtkLookupTable> makeForceTable() {
  auto table = makeRampTable({{0.0, 1.0, 0.78, 0.30}, {0.5, 0.95, 0.38, 0.08}, {1.0, 0.62, 0.0, 0.05}});
  table->SetNanColor(0.62, 0.62, 0.62, 1.0);  // slack elements are grey (Figure 3)
  table->Build();
  return table;
}

// colour scale of activation: dark violet through teal to yellow (viridis-like), distinct from force
vtkSmartPointer<vtkLookupTable> makeActivationTable() {
  auto table = makeRampTable({{0.0, 0.27, 0.0, 0.33}, {0.5, 0.13, 0.57, 0.55}, {1.0, 0.99, 0.91, 0.14}});
  table->SetNanColor(0.62, 0.62, 0.62, 1.0);
  table->Build();
  return table;
}

// colour scale of the gut: deep blue to cyan to white
vtkSmartPointer<vtkLookupTable> makeGutTable() {
  auto table = makeRampTable({{0.0, 0.17, 0.25, 0.62}, {0.6, 0.25, 0.72, 0.85}, {1.0, 0.88, 0.97, 1.0}});
  table->Build();
  return table;
}

// colour scale of the skin's displacement: a heat map, skin tone (still) through orange to deep red, over the
// fixed range [0, kSkinDisplacementTop] mm
vtkSmartPointer<vtkLookupTable> makeSkinTable() {
  auto table = makeRampTable({{0.0, 0.93, 0.80, 0.70}, {0.4, 0.98, 0.60, 0.25}, {1.0, 0.70, 0.05, 0.08}});
  table->Build();
  return table;
}

// a vertical colour legend at the right edge of the view, from height y to y + 0.4 (normalised viewport)
vtkSmartPointer<vtkScalarBarActor> makeScalarBar(vtkLookupTable* table, const char* title, double y) {
  auto bar = vtkSmartPointer<vtkScalarBarActor>::New();
  bar->SetLookupTable(table);
  bar->SetTitle(title);
  bar->SetPosition(0.855, y);
  bar->SetWidth(0.14);
  bar->SetHeight(0.4);
  bar->SetBarRatio(0.28);
  bar->UnconstrainedFontSizeOn();
  for (vtkTextProperty* text : {bar->GetTitleTextProperty(), bar->GetLabelTextProperty()}) {
    text->SetFontSize(12);
    text->ShadowOff();
    text->ItalicOff();
    text->SetColor(0.93, 0.93, 0.93);
  }
  bar->GetTitleTextProperty()->BoldOn();
  return bar;
}

// legend labels: the plots' ticks (viz::niceTicks, a 1-2-5 step) written with %g (no trailing zeros, and no
// exponent for 1e-4 <= |v| < 1e6)
constexpr const char* kLegendFormat = "%g";
constexpr int kLegendTicks = 5;  // [-] intervals aimed at

// one colour scale: its table and its legend over [lo, hi], labelled as legendLabels() writes them
void setScale(vtkScalarBarActor* bar, vtkLookupTable* table, double lo, double hi) {
  double range[2];
  table->GetTableRange(range);
  if (range[0] == lo && range[1] == hi && bar->GetUseCustomLabels()) return;
  table->SetTableRange(lo, hi);
  vtkNew<vtkDoubleArray> labels;
  for (double v : niceTicks(lo, hi, kLegendTicks).values) labels->InsertNextValue(v);
  bar->SetUseCustomLabels(true);
  bar->SetCustomLabels(labels);
  bar->SetLabelFormat(kLegendFormat);
}

// the top of an auto-ranged scale: the kAutoRangePercentile of `values` rounded up, never below `top`
double autoTop(std::vector<double>& values, double top) {
  if (values.empty()) return top;
  const auto k = static_cast<std::ptrdiff_t>(kAutoRangePercentile * static_cast<double>(values.size() - 1));
  std::nth_element(values.begin(), values.begin() + k, values.end());
  return std::max(top, niceCeil(values[static_cast<std::size_t>(k)]));
}

constexpr double kPascalPerCmH2O = 98.0665;  // [Pa / cmH2O]

constexpr int kLabelFontSize = 13;  // [px] every teaching caption's text
constexpr int kLabelPadding = 2;    // [px] between a caption's text and its box
constexpr int kLabelGap = 3;        // [px] kept free between two captions, and between a caption and a legend
constexpr int kLabelOffset = 28;    // [px] from a point to the near edge of its caption

// a teaching label: a caption drawn over the scene (never hidden by it) with a leader to its point
vtkSmartPointer<vtkCaptionActor2D> makeLabel(const std::string& text) {
  auto label = vtkSmartPointer<vtkCaptionActor2D>::New();
  label->SetCaption(text.c_str());
  label->BorderOff();
  label->LeaderOn();
  label->ThreeDimensionalLeaderOff();
  label->SetPadding(kLabelPadding);
  // the box in pixels (layoutLabels() sizes it to the text at kLabelFontSize, so every caption has that size)
  label->GetPosition2Coordinate()->SetCoordinateSystemToDisplay();
  label->GetProperty()->SetColor(1.0, 1.0, 0.8);
  vtkTextProperty* t = label->GetCaptionTextProperty();
  t->SetFontSize(kLabelFontSize);
  label->GetTextActor()->SetTextScaleModeToNone();  // that size, not scaled to fill the box
  t->SetColor(1.0, 1.0, 0.85);
  t->SetBackgroundColor(0.08, 0.09, 0.12);
  t->SetBackgroundOpacity(0.7);
  t->ShadowOff();
  t->ItalicOff();
  t->BoldOff();
  label->PickableOff();
  return label;
}

// display only: a mesh with `keep` of its triangles (quadric decimation, volume kept), shaded with normals
// split at 60 degrees as readBodyMesh() does. Under software OpenGL the bones' 41 000 triangles cost a third
// of a frame whatever the window size, and the skin's 20 800 (re-uploaded at every frame) a quarter. The
// exports (ParaView series, glTF) read the full meshes.
constexpr double kBoneDisplayKeep = 0.3;     // [-] share of the bones' triangles drawn
constexpr double kSkinDisplayKeep = 0.5;     // [-] share of the skin's triangles drawn (DisplaySkin)
constexpr vtkIdType kDecimationFloor = 400;  // [-] meshes with fewer triangles are drawn as they are

vtkSmartPointer<vtkPolyData> decimateForDisplay(vtkPolyData* mesh, double keep) {
  if (mesh->GetNumberOfPolys() < kDecimationFloor) return mesh;
  vtkNew<vtkQuadricDecimation> decimate;
  decimate->SetInputData(mesh);
  decimate->SetTargetReduction(1.0 - keep);
  decimate->VolumePreservationOn();
  vtkNew<vtkPolyDataNormals> normals;
  normals->SetInputConnection(decimate->GetOutputPort());
  normals->SetFeatureAngle(60.0);
  normals->Update();
  if (normals->GetOutput()->GetNumberOfPolys() == 0) return mesh;
  return normals->GetOutput();
}

// the drawn skin (display only): the skin decimated to kSkinDisplayKeep of its triangles, each of its
// vertices embedded in the full skin at rest (the three corners of the nearest full triangle and their
// barycentric weights, in LungSurface's form), so that it is posed from the full skin's posed vertices
// (PosedGeometry::skin) by sim::lungPositions(): x_v = sum_k w_k s_{i_k}. One posing function, a smaller mesh
// to draw.
sim::LungSurface displaySkin(const sim::Skin& skin, const Eigen::Matrix3Xd& rest) {
  vtkNew<vtkPolyData> full;
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->SetNumberOfPoints(rest.cols());
  for (Eigen::Index v = 0; v < rest.cols(); ++v) points->SetPoint(v, rest(0, v), rest(1, v), rest(2, v));
  full->SetPoints(points);
  vtkNew<vtkCellArray> polys;
  for (Eigen::Index t = 0; t < skin.triangles.cols(); ++t) {
    const vtkIdType ids[3] = {skin.triangles(0, t), skin.triangles(1, t), skin.triangles(2, t)};
    polys->InsertNextCell(3, ids);
  }
  full->SetPolys(polys);
  vtkSmartPointer<vtkPolyData> drawn = decimateForDisplay(full, kSkinDisplayKeep);

  sim::LungSurface out;
  const vtkIdType n = drawn->GetNumberOfPoints();
  out.cavityVertex.setConstant(sim::kLungVertexSlots, n, -1);
  out.weights.setZero(sim::kLungVertexSlots, n);
  vtkNew<vtkStaticCellLocator> locator;
  locator->SetDataSet(full);
  locator->BuildLocator();
  for (vtkIdType v = 0; v < n; ++v) {
    double at[3], closest[3], distance2 = 0.0;
    drawn->GetPoint(v, at);
    vtkIdType cell = -1;
    int sub = 0;
    locator->FindClosestPoint(at, closest, cell, sub, distance2);
    // barycentric weights of the closest point in its triangle (a, b, c), clamped into it
    const Eigen::Vector3i corner = skin.triangles.col(cell);
    const Eigen::Vector3d a = rest.col(corner(0)), e1 = rest.col(corner(1)) - a, e2 = rest.col(corner(2)) - a;
    const Eigen::Vector3d p = Eigen::Vector3d(closest[0], closest[1], closest[2]) - a;
    const double d11 = e1.dot(e1), d12 = e1.dot(e2), d22 = e2.dot(e2), det = d11 * d22 - d12 * d12;
    double u = det > 0.0 ? (d22 * e1.dot(p) - d12 * e2.dot(p)) / det : 0.0;
    double w = det > 0.0 ? (d11 * e2.dot(p) - d12 * e1.dot(p)) / det : 0.0;
    u = std::clamp(u, 0.0, 1.0);
    w = std::clamp(w, 0.0, 1.0 - u);
    const std::array<double, 3> weight{1.0 - u - w, u, w};
    for (int k = 0; k < 3; ++k) {
      out.cavityVertex(k, v) = corner(k);
      out.weights(k, v) = weight[static_cast<std::size_t>(k)];
    }
  }
  vtkCellArray* cells = drawn->GetPolys();
  out.triangles.resize(3, cells->GetNumberOfCells());
  vtkNew<vtkIdList> ids;
  cells->InitTraversal();
  for (Eigen::Index t = 0; cells->GetNextCell(ids); ++t)
    for (int k = 0; k < 3; ++k) out.triangles(k, t) = static_cast<int>(ids->GetId(k));
  return out;
}

}  // namespace

vtkSmartPointer<vtkPolyData> readBodyMesh(const std::string& path, const std::string& bodyName) {
  if (!std::filesystem::is_regular_file(path))
    throw sim::Error("bodies." + bodyName + ".mesh: file not found: " + path);
  vtkNew<vtkXMLPolyDataReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  if (reader->GetErrorCode() != 0 || reader->GetOutput()->GetNumberOfPoints() == 0)
    throw sim::Error("bodies." + bodyName + ".mesh: not a readable VTK polydata file: " + path);
  vtkNew<vtkPolyDataNormals> normals;
  normals->SetInputConnection(reader->GetOutputPort());
  normals->SetFeatureAngle(60.0);
  normals->Update();
  return normals->GetOutput();
}

double niceCeil(double v) {
  if (!(v > 0.0)) return 1.0;
  const double p = std::pow(10.0, std::floor(std::log10(v)));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * p >= v * (1.0 - 1e-12)) return m * p;
  return 10.0 * p;
}

std::vector<std::string> legendLabels(double lo, double hi) {
  std::vector<std::string> labels;
  char text[64];
  for (double v : niceTicks(lo, hi, kLegendTicks).values) {
    std::snprintf(text, sizeof text, kLegendFormat, v);
    labels.emplace_back(text);
  }
  return labels;
}

std::string magnificationError(double factor) {
  if (factor >= kMinMagnification && factor <= kMaxMagnification) return {};
  std::ostringstream out;
  out << "motion magnification: " << factor << " is outside [" << kMinMagnification << ", "
      << kMaxMagnification << "]";
  return out.str();
}

const char* groupLabel(sim::ElementGroup g) {
  switch (g) {
    case sim::ElementGroup::IntercostalExternal:
      return "External intercostals";
    case sim::ElementGroup::IntercostalInternal:
      return "Internal intercostals";
    case sim::ElementGroup::Diaphragm:
      return "Diaphragm";
    case sim::ElementGroup::Rectus:
      return "Rectus abdominis";
    case sim::ElementGroup::TransversusObliques:
      return "Transversus / obliques";
    case sim::ElementGroup::Cartilage:
      return "Costal cartilage";
    case sim::ElementGroup::Count:
      break;
  }
  return "?";
}

std::array<double, 3> groupColour(sim::ElementGroup g) {
  switch (g) {
    case sim::ElementGroup::IntercostalExternal:
      return {0.30, 0.78, 0.36};
    case sim::ElementGroup::IntercostalInternal:
      return {0.62, 0.42, 0.86};
    case sim::ElementGroup::Diaphragm:
      return {0.78, 0.36, 0.18};  // rust
    case sim::ElementGroup::Rectus:
      return {0.96, 0.62, 0.72};  // pink
    case sim::ElementGroup::TransversusObliques:
      return {0.33, 0.52, 0.93};  // blue
    case sim::ElementGroup::Cartilage:
      return {0.86, 0.86, 0.78};
    case sim::ElementGroup::Count:
      break;
  }
  return {1.0, 1.0, 1.0};
}

struct ModelScene::Impl {
  vtkSmartPointer<vtkRenderer> renderer = vtkSmartPointer<vtkRenderer>::New();
  vtkSmartPointer<vtkOrientationMarkerWidget> marker;
  unsigned long layoutObserver = 0;  // the renderer's StartEvent observer that runs layoutLabels()
  vtkSmartPointer<vtkLookupTable> forceTable = makeForceTable();
  vtkSmartPointer<vtkLookupTable> gutTable = makeGutTable();
  vtkSmartPointer<vtkLookupTable> activationTable = makeActivationTable();
  vtkSmartPointer<vtkScalarBarActor> forceBar = makeScalarBar(forceTable, "Tension per\nelement [N]", 0.55);
  vtkSmartPointer<vtkScalarBarActor> gutBar = makeScalarBar(gutTable, "Gut", 0.07);
  vtkSmartPointer<vtkLookupTable> skinTable = makeSkinTable();
  vtkSmartPointer<vtkScalarBarActor> skinBar = makeScalarBar(skinTable, "Skin\ndisplacement\n[mm]", 0.31);
  // "motion x5" at the top left of the view while the motion is magnified
  vtkSmartPointer<vtkTextActor> motionText = vtkSmartPointer<vtkTextActor>::New();
  std::string playback;            // the affect of the morph playback on show; empty: the physics
  std::vector<char> playbackBone;  // per body: posed by the playback (a baked bone), so drawn in it
  DisplayOptions options;

  sim::Model model;
  // the tops of the auto-ranged scales so far (DisplayOptions::isAutoRange): never shrinking
  double muscleTop = 0.0;           // [N] or [-]
  double gutDisplacementTop = 0.0;  // [mm]
  double gutPressureTop = 0.0;      // [cmH2O]
  double skinTop = 0.0;             // [mm]
  // the end-expiratory pose the displacements are measured from, posed (rest pose until there is one)
  double referenceTime = std::numeric_limits<double>::quiet_NaN();  // [s] its State::time
  sim::PosedGeometry reference;
  sim::PosedGeometry real;         // the state posed as it is, when the drawn pose is magnified
  std::vector<double> values;      // scratch for the auto range
  Eigen::Matrix3Xf normalScratch;  // scratch for setNormals()

  // muscle elements, one actor per group (points 2k, 2k+1 are the ends of the group's k-th element)
  struct Group {
    std::vector<int> element;  // model element index of each line
    vtkSmartPointer<vtkPolyData> lines;
    vtkSmartPointer<vtkFloatArray> force;  // [N] contractive force, NaN when slack
    // per line: 1 for an accessory muscle (a recruitment threshold), else 0; coloured through `kindTable`
    // (the group's colour, kAccessoryColour) in the group colouring when the group has one
    vtkSmartPointer<vtkFloatArray> kind;
    vtkSmartPointer<vtkLookupTable> kindTable;
    bool hasAccessory = false;
    vtkSmartPointer<vtkActor> actor;
  };
  std::array<Group, kGroups> groups;
  sim::PosedGeometry posed;  // the model posed for the last update() (the one posing function)

  // the bones, every body's mesh in one actor: one draw instead of one per body (31 actors cost 12 ms of a
  // frame under software OpenGL). Body b owns the points [start[b], start[b+1]); update() poses them from
  // their body-frame positions, x = R_b p + t_b and n = R_b n0, and colours them per body.
  struct Bones {
    vtkSmartPointer<vtkPolyData> data;
    vtkSmartPointer<vtkActor> actor;
    vtkSmartPointer<vtkFloatArray> xyz;                // [m] posed points       (3 x #P)
    vtkSmartPointer<vtkFloatArray> normal;             // [-] posed normals      (3 x #P)
    vtkSmartPointer<vtkUnsignedCharArray> colour;      // RGB per point          (3 x #P)
    Eigen::Matrix3Xf local;                            // [m] body-frame points  (3 x #P)
    Eigen::Matrix3Xf localNormal;                      // [-] body-frame normals (3 x #P)
    std::vector<Eigen::Index> start;                   // first point of each body (#B + 1)
    std::vector<vtkSmartPointer<vtkCellArray>> polys;  // each body's triangles, its own point ids (#B)
    std::vector<int> cellBody;                         // body of each drawn cell
    std::vector<char> shown;                           // per body: its cells are drawn (#B)
  } bones;

  vtkSmartPointer<vtkPolyData> gut;
  vtkSmartPointer<vtkFloatArray> gutScalar;
  vtkSmartPointer<vtkActor> gutActor;

  vtkSmartPointer<vtkPolyData> cavity;
  vtkSmartPointer<vtkActor> cavityActor;

  // the soft-tissue volume bodies, one surface of all their triangles over the nodes
  vtkSmartPointer<vtkPolyData> tissue;
  Eigen::Matrix3Xi tissueTriangles;
  vtkSmartPointer<vtkActor> tissueActor;

  std::array<vtkSmartPointer<vtkPolyData>, 2> lungs;  // right, left
  std::array<vtkSmartPointer<vtkActor>, 2> lungActors;

  vtkSmartPointer<vtkPolyData> landmarks;
  vtkSmartPointer<vtkActor> landmarkActor;

  // the skin, coloured plain or by its displacement from the rest pose, drawn decimated (displaySkin())
  sim::LungSurface drawnSkin;           // the drawn mesh, embedded in the full skin
  Eigen::Matrix3Xd drawnSkinAt;         // [m] its vertices as drawn (magnified)
  Eigen::Matrix3Xd drawnSkinReal;       // [m] as the state puts them (unmagnified)
  Eigen::Matrix3Xd drawnSkinReference;  // [m] at the end-expiratory reference
  vtkSmartPointer<vtkPolyData> skin;
  vtkSmartPointer<vtkFloatArray> skinScalar;  // [mm] displacement from end-expiration
  vtkSmartPointer<vtkActor> skinActor;

  // the ghost of a compared run: its gut and lungs, light grey and translucent
  std::vector<std::pair<vtkSmartPointer<vtkPolyData>, vtkSmartPointer<vtkActor>>> ghost;  // gut, right, left
  sim::PosedGeometry ghostPosed;
  bool hasGhost = false;

  // teaching labels: landmarks, group centres, and a few named bones
  struct Label {
    vtkSmartPointer<vtkCaptionActor2D> actor;
    int landmark = -1, group = -1, body = -1;
  };
  std::vector<Label> labels;

  Pick highlight;
  vtkSmartPointer<vtkPolyData> highlightLine;
  vtkSmartPointer<vtkActor> highlightActor;

  void clear() {
    for (vtkProp* prop : ownedProps()) renderer->RemoveViewProp(prop);
    for (Group& g : groups) g = Group{};
    bones = Bones{};
    labels.clear();
    gutActor = cavityActor = landmarkActor = highlightActor = skinActor = tissueActor = nullptr;
    tissue = nullptr;
    skin = nullptr;
    drawnSkin = {};
    ghost.clear();
    hasGhost = false;
    lungs = {};
    lungActors = {};
    highlight = Pick{};
    resetAutoRange();
    referenceTime = std::numeric_limits<double>::quiet_NaN();
    playback.clear();
    playbackBone.clear();
  }

  std::vector<vtkProp*> ownedProps() const {
    std::vector<vtkProp*> props;
    for (const Group& g : groups)
      if (g.actor) props.push_back(g.actor);
    if (bones.actor) props.push_back(bones.actor);
    for (const Label& l : labels) props.push_back(l.actor);
    for (vtkProp* p : {static_cast<vtkProp*>(gutActor), static_cast<vtkProp*>(cavityActor),
                       static_cast<vtkProp*>(lungActors[0]), static_cast<vtkProp*>(lungActors[1]),
                       static_cast<vtkProp*>(landmarkActor), static_cast<vtkProp*>(highlightActor),
                       static_cast<vtkProp*>(tissueActor)})
      if (p) props.push_back(p);
    for (const auto& g : ghost) props.push_back(g.second);
    if (skinActor) props.push_back(skinActor);
    return props;
  }

  static vtkSmartPointer<vtkActor> actorFor(vtkPolyData* data) {
    vtkNew<vtkPolyDataMapper> mapper;
    mapper->SetInputData(data);
    // the model lies within a metre of the origin [m]: single precision holds it to a micrometre, so the
    // coordinate shift and scale, whose range scan of every moved array cost at each upload, is off
    if (auto* gl = vtkOpenGLPolyDataMapper::SafeDownCast(mapper))
      gl->SetVBOShiftScaleMethod(vtkOpenGLVertexBufferObject::DISABLE_SHIFT_SCALE);
    auto actor = vtkSmartPointer<vtkActor>::New();
    actor->SetMapper(mapper);
    return actor;
  }

  // a smooth-shaded actor of `data`: its point normals, zero at first, are computed from its triangles at
  // every update (setNormals())
  static vtkSmartPointer<vtkActor> smoothActor(vtkPolyData* data) {
    vtkNew<vtkFloatArray> normals;
    normals->SetNumberOfComponents(3);
    normals->SetNumberOfTuples(data->GetNumberOfPoints());
    normals->Fill(0.0f);
    data->GetPointData()->SetNormals(normals);
    return actorFor(data);
  }

  // a smooth-shaded surface of `data` (smoothActor()) coloured through `table` by one float scalar per point
  // (`scalar`, zero at first)
  static vtkSmartPointer<vtkActor> scalarSurfaceActor(vtkPolyData* data,
                                                      vtkSmartPointer<vtkFloatArray>& scalar,
                                                      vtkLookupTable* table) {
    scalar = vtkSmartPointer<vtkFloatArray>::New();
    scalar->SetNumberOfValues(data->GetNumberOfPoints());
    scalar->Fill(0.0f);
    data->GetPointData()->SetScalars(scalar);
    auto actor = smoothActor(data);
    actor->GetMapper()->SetLookupTable(table);
    actor->GetMapper()->UseLookupTableScalarRangeOn();
    actor->PickableOff();
    return actor;
  }

  // the area-weighted vertex normals of a triangle surface posed at `x` (3 x #V [m]) into `data`'s point
  // normals: a few hundred microseconds for the skin's 20 000 triangles, where vtkPolyDataNormals rebuilt its
  // cell links on every frame
  static void setNormals(vtkPolyData* data, const Eigen::Matrix3Xd& x, const Eigen::Matrix3Xi& triangles,
                         Eigen::Matrix3Xf& scratch) {
    scratch.setZero(3, x.cols());
    for (Eigen::Index t = 0; t < triangles.cols(); ++t) {
      const Eigen::Vector3d a = x.col(triangles(0, t)), b = x.col(triangles(1, t)),
                            c = x.col(triangles(2, t));
      const Eigen::Vector3f n = (b - a).cross(c - a).cast<float>();  // twice the area, outward for CCW
      for (int k = 0; k < 3; ++k) scratch.col(triangles(k, t)) += n;
    }
    auto* normals = vtkFloatArray::SafeDownCast(data->GetPointData()->GetNormals());
    for (Eigen::Index i = 0; i < x.cols(); ++i) {
      const float length = scratch.col(i).norm();
      const Eigen::Vector3f n =
          length > 0.0f ? Eigen::Vector3f(scratch.col(i) / length) : Eigen::Vector3f::UnitZ();
      normals->SetTypedTuple(i, n.data());
    }
    normals->Modified();
  }

  static vtkSmartPointer<vtkPolyData> surface(int nPoints, const Eigen::Matrix3Xi& triangles) {
    auto data = vtkSmartPointer<vtkPolyData>::New();
    vtkNew<vtkPoints> points;
    points->SetNumberOfPoints(nPoints);
    data->SetPoints(points);
    vtkNew<vtkCellArray> polys;
    for (Eigen::Index t = 0; t < triangles.cols(); ++t) {
      const vtkIdType ids[3] = {triangles(0, t), triangles(1, t), triangles(2, t)};
      polys->InsertNextCell(3, ids);
    }
    data->SetPolys(polys);
    return data;
  }

  // the drawn skin posed from the full skin's vertices `full` (3 x #V [m]): its points and normals
  void setSkin(const Eigen::Matrix3Xd& full) {
    sim::lungPositions(drawnSkin, full, drawnSkinAt);
    setPoints(skin, drawnSkinAt);
    setNormals(skin, drawnSkinAt, drawnSkin.triangles, normalScratch);
  }

  static void setPoints(vtkPolyData* data, const Eigen::Matrix3Xd& x) {
    vtkPoints* points = data->GetPoints();
    for (Eigen::Index i = 0; i < x.cols(); ++i) points->SetPoint(i, x(0, i), x(1, i), x(2, i));
    points->Modified();
  }

  // body meshes in body-frame coordinates; a small sphere for bodies without one
  static std::vector<vtkSmartPointer<vtkPolyData>> readBodyMeshes(const sim::Model& model,
                                                                  const std::string& modelDir) {
    std::vector<vtkSmartPointer<vtkPolyData>> meshes;
    for (int b = 0; b < model.bodies.size(); ++b) {
      const std::string& file = model.bodies.mesh[static_cast<std::size_t>(b)];
      if (file.empty()) {
        vtkNew<vtkSphereSource> sphere;
        sphere->SetRadius(0.008);
        sphere->Update();
        meshes.emplace_back(sphere->GetOutput());
      } else {
        meshes.push_back(decimateForDisplay(readBodyMesh((std::filesystem::path(modelDir) / file).string(),
                                                         model.bodies.name[static_cast<std::size_t>(b)]),
                                            kBoneDisplayKeep));
      }
    }
    return meshes;
  }

  void build(const std::vector<vtkSmartPointer<vtkPolyData>>& meshes) {
    buildBones(meshes);

    // muscle elements by group, those that views draw (sim::isDrawn: no ties, volume-body springs or
    // gliding springs)
    for (int e = 0; e < model.elements.size(); ++e)
      if (sim::isDrawn(model, e))
        groups[static_cast<std::size_t>(model.elements.group[static_cast<std::size_t>(e)])].element.push_back(
            e);
    for (int gi = 0; gi < kGroups; ++gi) {
      Group& g = groups[static_cast<std::size_t>(gi)];
      const int n = static_cast<int>(g.element.size());
      g.lines = vtkSmartPointer<vtkPolyData>::New();
      vtkNew<vtkPoints> points;
      points->SetNumberOfPoints(2 * n);
      g.lines->SetPoints(points);
      vtkNew<vtkCellArray> cells;
      for (int k = 0; k < n; ++k) {
        const vtkIdType ids[2] = {2 * k, 2 * k + 1};
        cells->InsertNextCell(2, ids);
      }
      g.lines->SetLines(cells);
      g.force = vtkSmartPointer<vtkFloatArray>::New();
      g.force->SetName("contractive_force_N");
      g.force->SetNumberOfValues(n);
      g.force->Fill(std::numeric_limits<float>::quiet_NaN());
      g.lines->GetCellData()->SetScalars(g.force);
      g.kind = vtkSmartPointer<vtkFloatArray>::New();
      g.kind->SetName("accessory");
      g.kind->SetNumberOfValues(n);
      for (int k = 0; k < n; ++k) {
        const bool accessory = model.elements.recruitmentOf(g.element[static_cast<std::size_t>(k)]) > 0.0;
        g.kind->SetValue(k, accessory ? 1.0f : 0.0f);
        g.hasAccessory = g.hasAccessory || accessory;
      }
      g.lines->GetCellData()->AddArray(g.kind);
      g.kindTable = vtkSmartPointer<vtkLookupTable>::New();
      g.kindTable->SetNumberOfTableValues(2);
      g.kindTable->SetTableRange(0.0, 1.0);
      const auto own = groupColour(static_cast<sim::ElementGroup>(gi));
      g.kindTable->SetTableValue(0, own[0], own[1], own[2], 1.0);
      g.kindTable->SetTableValue(1, kAccessoryColour[0], kAccessoryColour[1], kAccessoryColour[2], 1.0);
      g.kindTable->Build();
      g.actor = actorFor(g.lines);
      g.actor->GetMapper()->SetLookupTable(forceTable);
      g.actor->GetMapper()->SetScalarModeToUseCellFieldData();
      g.actor->GetMapper()->SelectColorArray("contractive_force_N");
      g.actor->GetMapper()->UseLookupTableScalarRangeOn();
      g.actor->GetProperty()->SetLineWidth(gi == static_cast<int>(sim::ElementGroup::Cartilage) ? 3.0f
                                                                                                : 2.5f);
      g.actor->GetProperty()->SetRenderLinesAsTubes(true);
    }

    // gut, cavity, landmarks
    gut = surface(model.nodes.size(), model.gut.triangles);
    gutActor = scalarSurfaceActor(gut, gutScalar, gutTable);

    // the volume bodies: muscle-red, opaque, under the skin
    if (model.volumes.size() > 0) {
      Eigen::Index count = 0;
      for (const Eigen::Matrix3Xi& t : model.volumes.triangles) count += t.cols();
      tissueTriangles.resize(3, count);
      count = 0;
      for (const Eigen::Matrix3Xi& t : model.volumes.triangles) {
        tissueTriangles.middleCols(count, t.cols()) = t;
        count += t.cols();
      }
      tissue = surface(model.nodes.size(), tissueTriangles);
      tissueActor = smoothActor(tissue);
      tissueActor->GetProperty()->SetColor(0.74, 0.33, 0.31);
      tissueActor->PickableOff();
    }

    cavity = surface(model.cavity.vertices.size(), model.cavity.triangles);
    cavityActor = actorFor(cavity);
    cavityActor->GetProperty()->SetColor(0.55, 0.78, 0.98);
    cavityActor->GetProperty()->SetOpacity(0.28);
    cavityActor->PickableOff();

    // the lungs: translucent pink, a model without lung surfaces shows none
    const std::array<const sim::LungSurface*, 2> lungSurfaces{&model.lungs.right, &model.lungs.left};
    for (std::size_t i = 0; i < 2; ++i) {
      if (lungSurfaces[i]->vertexCount() == 0) continue;
      lungs[i] = surface(lungSurfaces[i]->vertexCount(), lungSurfaces[i]->triangles);
      lungActors[i] = actorFor(lungs[i]);
      lungActors[i]->GetProperty()->SetColor(0.96, 0.62, 0.66);
      lungActors[i]->GetProperty()->SetOpacity(0.5);  // one layer (front faces): as dense as two at 0.3
      lungActors[i]->PickableOff();
    }

    // the skin: smooth-shaded, drawn last among the surfaces so the translucent body wraps the rest
    if (model.skin.vertexCount() > 0) {
      sim::PosedGeometry rest;
      sim::poseGeometry(model, sim::makeInitialState(model), rest);
      drawnSkin = displaySkin(model.skin, rest.skin);
      skin = surface(drawnSkin.vertexCount(), drawnSkin.triangles);
      skinActor = scalarSurfaceActor(skin, skinScalar, skinTable);
      skinActor->GetProperty()->SetSpecular(0.15);
      skinActor->GetProperty()->SetSpecularPower(12.0);
    }

    landmarks = vtkSmartPointer<vtkPolyData>::New();
    vtkNew<vtkPoints> lmPoints;
    lmPoints->SetNumberOfPoints(static_cast<vtkIdType>(model.landmarks.name.size()));
    landmarks->SetPoints(lmPoints);
    vtkNew<vtkCellArray> verts;
    for (vtkIdType i = 0; i < lmPoints->GetNumberOfPoints(); ++i) verts->InsertNextCell(1, &i);
    landmarks->SetVerts(verts);
    landmarkActor = actorFor(landmarks);
    landmarkActor->GetProperty()->SetColor(0.25, 0.95, 0.55);
    landmarkActor->GetProperty()->SetPointSize(11.0f);
    landmarkActor->GetProperty()->SetRenderPointsAsSpheres(true);
    landmarkActor->PickableOff();

    // labels
    for (std::size_t l = 0; l < model.landmarks.name.size(); ++l) {
      std::string name = model.landmarks.name[l];
      std::replace(name.begin(), name.end(), '_', ' ');
      Label label{makeLabel(name), static_cast<int>(l), -1, -1};
      labels.push_back(label);
    }
    // group captions: a fixed column at the lower left of the view (layoutLabels()), one row per group, so
    // that they never overlap; their leaders follow the groups
    for (int gi = 0; gi < kGroups; ++gi) {
      if (groups[static_cast<std::size_t>(gi)].element.empty()) continue;
      auto caption = makeLabel(groupLabel(static_cast<sim::ElementGroup>(gi)));
      vtkCoordinate* at = caption->GetPositionCoordinate();
      at->SetReferenceCoordinate(nullptr);
      at->SetCoordinateSystemToDisplay();  // placed by layoutLabels()
      labels.push_back(Label{caption, -1, gi, -1});
    }
    for (int b = 0; b < model.bodies.size(); ++b) {
      const std::string& name = model.bodies.name[static_cast<std::size_t>(b)];
      if (name == "sternum") labels.push_back(Label{makeLabel(name), -1, -1, b});
    }

    // selection highlight: one bright line
    highlightLine = vtkSmartPointer<vtkPolyData>::New();
    vtkNew<vtkPoints> hlPoints;
    hlPoints->SetNumberOfPoints(2);
    highlightLine->SetPoints(hlPoints);
    vtkNew<vtkCellArray> hlCell;
    const vtkIdType hlIds[2] = {0, 1};
    hlCell->InsertNextCell(2, hlIds);
    highlightLine->SetLines(hlCell);
    highlightActor = actorFor(highlightLine);
    highlightActor->GetProperty()->SetColor(0.2, 1.0, 1.0);
    highlightActor->GetProperty()->SetLineWidth(7.0f);
    highlightActor->GetProperty()->SetRenderLinesAsTubes(true);
    highlightActor->PickableOff();
    highlightActor->VisibilityOff();

    // the ghost: the compared run's gut and lungs, drawn before the skin
    const auto addGhost = [&](int nPoints, const Eigen::Matrix3Xi& triangles) {
      auto data = surface(nPoints, triangles);
      auto actor = actorFor(data);
      actor->GetProperty()->SetColor(0.86, 0.88, 0.92);
      actor->GetProperty()->SetOpacity(0.4);
      actor->GetProperty()->BackfaceCullingOn();
      actor->PickableOff();
      ghost.emplace_back(data, actor);
    };
    addGhost(model.nodes.size(), model.gut.triangles);
    for (const sim::LungSurface* lung : lungSurfaces)
      if (lung->vertexCount() > 0) addGhost(lung->vertexCount(), lung->triangles);

    // the closed surfaces (outward triangles, sim/Model.h) draw their front faces only: a translucent one
    // blends one layer instead of two, which halves its fragments under software OpenGL
    for (vtkActor* a : {gutActor.GetPointer(), cavityActor.GetPointer(), lungActors[0].GetPointer(),
                        lungActors[1].GetPointer(), skinActor.GetPointer(), tissueActor.GetPointer()})
      if (a) a->GetProperty()->BackfaceCullingOn();

    for (vtkProp* prop : ownedProps()) renderer->AddViewProp(prop);
  }

  // fixed bodies are dark (Figure 2), moving ones bone-white
  std::array<unsigned char, 3> boneColour(int b) const {
    if (model.bodies.isFixed[static_cast<std::size_t>(b)] != 0) return {128, 125, 120};
    return {237, 230, 209};
  }

  void colourBone(int b, const std::array<unsigned char, 3>& rgb) {
    const auto k = static_cast<std::size_t>(b);
    if (!bones.colour || k + 1 >= bones.start.size()) return;
    for (Eigen::Index i = bones.start[k]; i < bones.start[k + 1]; ++i)
      for (int c = 0; c < 3; ++c) bones.colour->SetValue(3 * i + c, rgb[static_cast<std::size_t>(c)]);
    bones.colour->Modified();
  }

  // the bones' meshes (body frame) appended into one polydata with per-point normals and colours
  void buildBones(const std::vector<vtkSmartPointer<vtkPolyData>>& meshes) {
    Bones& B = bones;
    const std::size_t count = meshes.size();
    B.start.assign(1, 0);
    for (const auto& mesh : meshes) B.start.push_back(B.start.back() + mesh->GetNumberOfPoints());
    const Eigen::Index n = B.start.back();
    B.local.resize(3, n);
    B.localNormal.setZero(3, n);
    for (std::size_t b = 0; b < count; ++b) {
      vtkPolyData* mesh = meshes[b];
      vtkDataArray* normals = mesh->GetPointData()->GetNormals();
      for (vtkIdType i = 0; i < mesh->GetNumberOfPoints(); ++i) {
        double p[3];
        mesh->GetPoint(i, p);
        B.local.col(B.start[b] + i) = Eigen::Vector3d(p[0], p[1], p[2]).cast<float>();
        if (normals) {
          normals->GetTuple(i, p);
          B.localNormal.col(B.start[b] + i) = Eigen::Vector3d(p[0], p[1], p[2]).cast<float>();
        }
      }
      auto polys = vtkSmartPointer<vtkCellArray>::New();
      polys->DeepCopy(mesh->GetPolys());
      B.polys.push_back(polys);
    }
    B.data = vtkSmartPointer<vtkPolyData>::New();
    B.xyz = vtkSmartPointer<vtkFloatArray>::New();
    B.xyz->SetNumberOfComponents(3);
    B.xyz->SetNumberOfTuples(n);
    vtkNew<vtkPoints> points;
    points->SetData(B.xyz);
    B.data->SetPoints(points);
    B.normal = vtkSmartPointer<vtkFloatArray>::New();
    B.normal->SetNumberOfComponents(3);
    B.normal->SetNumberOfTuples(n);
    B.data->GetPointData()->SetNormals(B.normal);
    B.colour = vtkSmartPointer<vtkUnsignedCharArray>::New();
    B.colour->SetName("colour");
    B.colour->SetNumberOfComponents(3);
    B.colour->SetNumberOfTuples(n);
    B.data->GetPointData()->SetScalars(B.colour);
    // which body each point belongs to (tests and tools read it; the mapper does not)
    vtkNew<vtkIntArray> body;
    body->SetName("body");
    body->SetNumberOfValues(n);
    for (std::size_t b = 0; b < count; ++b)
      for (Eigen::Index i = B.start[b]; i < B.start[b + 1]; ++i) body->SetValue(i, static_cast<int>(b));
    B.data->GetPointData()->AddArray(body);
    for (std::size_t b = 0; b < count; ++b) colourBone(static_cast<int>(b), boneColour(static_cast<int>(b)));
    B.actor = actorFor(B.data);
    B.actor->GetMapper()->SetColorModeToDirectScalars();
    B.actor->GetMapper()->SetScalarModeToUsePointData();
    B.actor->GetProperty()->SetSpecular(0.25);
    B.actor->GetProperty()->SetSpecularPower(20.0);
    B.shown.clear();
    showBones([](std::size_t) { return true; });
    poseBones();
  }

  // the drawn cells: those of the bodies `isShown` picks (rebuilt only when that set changes)
  template <class IsShown>
  void showBones(IsShown isShown) {
    Bones& B = bones;
    if (!B.actor) return;
    std::vector<char> shown(B.polys.size());
    for (std::size_t b = 0; b < shown.size(); ++b) shown[b] = isShown(b) ? 1 : 0;
    B.actor->SetVisibility(std::find(shown.begin(), shown.end(), 1) != shown.end());
    if (shown == B.shown) return;
    B.shown = shown;
    vtkNew<vtkCellArray> cells;
    B.cellBody.clear();
    for (std::size_t b = 0; b < shown.size(); ++b) {
      if (!shown[b]) continue;
      cells->Append(B.polys[b], B.start[b]);
      B.cellBody.resize(static_cast<std::size_t>(cells->GetNumberOfCells()), static_cast<int>(b));
    }
    B.data->SetPolys(cells);
  }

  // the bones' points and normals at posed.body's poses (before the first update(): at rest)
  void poseBones() {
    Bones& B = bones;
    if (!B.data) return;
    const Eigen::Index n = B.local.cols();
    Eigen::Map<Eigen::Matrix3Xf> x(B.xyz->GetPointer(0), 3, n), normal(B.normal->GetPointer(0), 3, n);
    for (std::size_t b = 0; b + 1 < B.start.size(); ++b) {
      const Eigen::Index first = B.start[b], size = B.start[b + 1] - first;
      const Eigen::Isometry3d T =
          b < posed.body.size()
              ? posed.body[b]
              : Eigen::Isometry3d(Eigen::Translation3d(model.bodies.com.col(static_cast<Eigen::Index>(b))));
      const Eigen::Matrix3f R = T.linear().cast<float>();
      x.middleCols(first, size) =
          (R * B.local.middleCols(first, size)).colwise() + T.translation().cast<float>();
      normal.middleCols(first, size) = R * B.localNormal.middleCols(first, size);
    }
    B.xyz->Modified();
    B.normal->Modified();
    B.data->GetPoints()->Modified();
  }

  void resetAutoRange() { muscleTop = gutDisplacementTop = gutPressureTop = skinTop = 0.0; }

  std::string motionCaption() const {
    std::ostringstream out;
    if (!playback.empty()) out << "morph playback: " << playback << ", no physics";
    if (options.magnification != 1.0)
      out << (playback.empty() ? "" : " \u00b7 ") << "motion \u00d7" << options.magnification;
    return out.str();
  }

  // the shown legends one above the other down the right edge (tension, skin, gut): two of 0.4 of the view's
  // height each, as each was made, three of 0.27, so that none covers another
  void stackLegends() {
    std::vector<vtkScalarBarActor*> shown;
    for (vtkScalarBarActor* bar : {forceBar.GetPointer(), skinBar.GetPointer(), gutBar.GetPointer()})
      if (bar->GetVisibility()) shown.push_back(bar);
    const double n = static_cast<double>(shown.size());
    const double h = shown.size() > 2 ? 0.27 : 0.4;                          // [-] of the view's height
    const double gap = shown.size() > 1 ? (0.88 - n * h) / (n - 1.0) : 0.0;  // between 0.07 and 0.95
    for (std::size_t i = 0; i < shown.size(); ++i) {
      shown[i]->SetHeight(h);
      shown[i]->SetPosition(0.855, 0.95 - h - static_cast<double>(i) * (h + gap));
    }
  }

  // a rectangle on the screen [px]: display coordinates, y up
  struct Box {
    double x0 = 0.0, y0 = 0.0, x1 = 0.0, y1 = 0.0;
    bool overlaps(const Box& o, double gap) const {
      return x0 < o.x1 + gap && o.x0 < x1 + gap && y0 < o.y1 + gap && o.y0 < y1 + gap;
    }
  };

  // a caption's box size [px] for its text at kLabelFontSize (FreeType's measure at the window's dpi),
  // padded; one height for all, a line's with ascenders and descenders
  static std::array<double, 2> captionSize(vtkCaptionActor2D* caption, int dpi) {
    int bbox[4] = {0, 0, 0, 0}, line[4] = {0, 0, 0, 0};
    vtkTextRenderer* text = vtkTextRenderer::GetInstance();
    vtkTextProperty* property = caption->GetCaptionTextProperty();
    if (!text || !text->GetBoundingBox(property, caption->GetCaption(), bbox, dpi) ||
        !text->GetBoundingBox(property, "Ahgjpqy|", line, dpi))
      return {8.0 * static_cast<double>(std::string(caption->GetCaption()).size()), 18.0};
    const double pad = 2.0 * kLabelPadding + 2.0;  // [px] +2: a pixel of slack on each side
    return {bbox[1] - bbox[0] + 1.0 + pad, line[3] - line[2] + 1.0 + pad};
  }

  static Box displayBox(vtkActor2D* actor, vtkViewport* viewport) {
    const int* a = actor->GetPositionCoordinate()->GetComputedDisplayValue(viewport);
    const int* b = actor->GetPosition2Coordinate()->GetComputedDisplayValue(viewport);
    return {static_cast<double>(std::min(a[0], b[0])), static_cast<double>(std::min(a[1], b[1])),
            static_cast<double>(std::max(a[0], b[0])), static_cast<double>(std::max(a[1], b[1]))};
  }

  // The teaching captions on the screen, before each render (so for any camera, view size or off-screen
  // frame): every caption's box sized to its text, so all have one font size; the group captions in their
  // column; each landmark's or bone's caption kLabelOffset beside its point, on the side of the body its
  // point lies (the subject's right drawn left from the front, right from the back), then moved up or down,
  // whichever is shorter, until it overlaps no other caption, the colour legends, the "motion x5" caption or
  // the orientation axes, and kept left of the legends.
  void layoutLabels() {
    vtkRenderWindow* window = renderer->GetRenderWindow();
    const int* size = renderer->GetSize();
    if (!window || size[0] <= 0 || size[1] <= 0) return;
    const double width = size[0], height = size[1];
    const int dpi = window->GetDPI();
    std::vector<Box> taken;            // what a point's caption must not overlap
    double right = width - kLabelGap;  // [px] right edge for captions: left of the legends
    for (vtkScalarBarActor* bar : {forceBar.GetPointer(), gutBar.GetPointer(), skinBar.GetPointer()})
      if (bar->GetVisibility()) {
        const Box b = displayBox(bar, renderer);
        taken.push_back(b);
        right = std::min(right, b.x0 - kLabelGap);
      }
    if (motionText->GetVisibility()) {
      double bbox[4];
      motionText->GetBoundingBox(renderer, bbox);
      taken.push_back({bbox[0], bbox[2], bbox[1], bbox[3]});
    }
    if (marker && marker->GetEnabled()) {
      const double* v = marker->GetViewport();
      taken.push_back({v[0] * width, v[1] * height, v[2] * width, v[3] * height});
    }
    // the group captions first: their fixed column at the lower left, above the orientation axes, a row each
    int row = 0;
    for (const Label& l : labels) {
      const std::array<double, 2> box = captionSize(l.actor, dpi);
      l.actor->GetPosition2Coordinate()->SetValue(box[0], box[1]);
      if (l.group < 0) continue;
      l.actor->GetPositionCoordinate()->SetValue(
          std::round(0.015 * width), std::round(0.44 * height - (row++) * (box[1] + 2.0 * kLabelGap)));
      if (l.actor->GetVisibility()) taken.push_back(displayBox(l.actor, renderer));
    }
    // which way the subject's right (+x) runs on the screen
    auto toDisplay = [&](const Eigen::Vector3d& p) {
      renderer->SetWorldPoint(p.x(), p.y(), p.z(), 1.0);
      renderer->WorldToDisplay();
      const double* d = renderer->GetDisplayPoint();
      return Eigen::Vector2d(d[0], d[1]);
    };
    const Eigen::Vector3d centre = posed.landmarks.cols() > 0
                                       ? Eigen::Vector3d(posed.landmarks.rowwise().mean())
                                       : Eigen::Vector3d::Zero();
    const double rightward = toDisplay(centre + Eigen::Vector3d(0.1, 0.0, 0.0)).x() - toDisplay(centre).x();
    // the points' captions, from the top of the screen down
    struct Placed {
      const Label* label;
      Eigen::Vector2d anchor;  // [px]
      double w, h;             // [px]
      bool isLeft;
    };
    std::vector<Placed> points;
    for (const Label& l : labels) {
      if (l.group >= 0 || !l.actor->GetVisibility()) continue;
      const double* a = l.actor->GetAttachmentPoint();
      const double* box = l.actor->GetPosition2Coordinate()->GetValue();
      const bool isSubjectsRight = a[0] > 0.01;  // [m] off the midline to the subject's right
      points.push_back({&l, toDisplay(Eigen::Vector3d(a[0], a[1], a[2])), box[0], box[1],
                        isSubjectsRight == (rightward <= 0.0)});
    }
    std::stable_sort(points.begin(), points.end(),
                     [](const Placed& p, const Placed& q) { return p.anchor.y() > q.anchor.y(); });
    for (const Placed& p : points) {
      Box b;
      b.x0 = p.isLeft ? p.anchor.x() - kLabelOffset - p.w : p.anchor.x() + kLabelOffset;
      b.x0 = std::clamp(b.x0, static_cast<double>(kLabelGap), std::max<double>(kLabelGap, right - p.w));
      b.x1 = b.x0 + p.w;
      const double y = std::clamp(p.anchor.y() - 0.5 * p.h, static_cast<double>(kLabelGap),
                                  std::max<double>(kLabelGap, height - kLabelGap - p.h));
      // the nearest free height below and above
      auto moved = [&](double dir) {
        double y0 = y;
        for (bool isBlocked = true; isBlocked;) {
          isBlocked = false;
          for (const Box& t : taken)
            if (Box{b.x0, y0, b.x1, y0 + p.h}.overlaps(t, kLabelGap)) {
              y0 = dir < 0.0 ? t.y0 - kLabelGap - p.h - 1.0 : t.y1 + kLabelGap + 1.0;
              isBlocked = true;
            }
        }
        return y0;
      };
      const double down = moved(-1.0), up = moved(1.0);
      const bool isDownInside = down >= 0.0, isUpInside = up + p.h <= height;
      b.y0 = isDownInside && (!isUpInside || y - down <= up - y) ? down : isUpInside ? up : y;
      b.y1 = b.y0 + p.h;
      taken.push_back(b);
      vtkCoordinate* at = p.label->actor->GetPositionCoordinate();
      at->SetReferenceCoordinate(nullptr);
      at->SetCoordinateSystemToDisplay();
      at->SetValue(std::round(b.x0), std::round(b.y0));
    }
  }

  void applyOptions() {
    const bool byForce = options.muscleColouring != MuscleColouring::Group;  // force or activation
    const bool byActivation = options.muscleColouring == MuscleColouring::Activation;
    forceBar->SetLookupTable(byActivation ? activationTable : forceTable);
    forceBar->SetTitle(byActivation ? "Activation\n\u03b1 [0-1]" : "Tension per\nelement [N]");
    bool anyMuscleShown = false;
    for (int gi = 0; gi < kGroups; ++gi) {
      Group& g = groups[static_cast<std::size_t>(gi)];
      if (!g.actor) continue;
      const auto group = static_cast<sim::ElementGroup>(gi);
      // structural springs keep their own colour: they carry no muscle force
      const bool colourByForce = byForce && sim::isMuscleGroup(group);
      // the group colouring shows a group's accessory muscles apart (kindTable)
      const bool colourByKind = !byForce && g.hasAccessory;
      vtkMapper* mapper = g.actor->GetMapper();
      mapper->SetScalarVisibility(colourByForce || colourByKind);
      mapper->SelectColorArray(colourByKind ? "accessory" : "contractive_force_N");
      mapper->SetLookupTable(colourByKind   ? g.kindTable.GetPointer()
                             : byActivation ? activationTable.GetPointer()
                                            : forceTable.GetPointer());
      const auto rgb = groupColour(group);
      g.actor->GetProperty()->SetColor(rgb[0], rgb[1], rgb[2]);
      const bool shown = options.showGroup[static_cast<std::size_t>(gi)];
      g.actor->SetVisibility(shown);
      anyMuscleShown = anyMuscleShown || (shown && colourByForce && !g.element.empty());
    }
    forceBar->SetVisibility(anyMuscleShown);
    showBones([&](std::size_t) { return options.showBones; });
    if (gutActor) {
      gutActor->SetVisibility(options.showGut);
      gutActor->GetProperty()->SetOpacity(options.isGutTranslucent ? 0.55 : 1.0);  // one layer (front faces)
      const bool coloured = options.gutColouring != GutColouring::Plain;
      gutActor->GetMapper()->SetScalarVisibility(coloured);
      gutActor->GetProperty()->SetColor(0.72, 0.58, 0.82);
      gutBar->SetTitle(options.gutColouring == GutColouring::Pressure ? "Gut\npressure\n[cmH2O]"
                                                                      : "Gut\ndisplacement\n[mm]");
      gutBar->SetVisibility(options.showGut && coloured);
    }
    if (tissueActor) tissueActor->SetVisibility(options.showTissue);
    if (cavityActor) cavityActor->SetVisibility(options.showCavity);
    for (const auto& a : lungActors)
      if (a) a->SetVisibility(options.showLungs);
    if (landmarkActor) landmarkActor->SetVisibility(options.showLandmarks);
    const bool isSkinShown = skinActor && options.skin != SkinDisplay::Hidden;
    const bool isSkinColoured = options.skinColouring == SkinColouring::Displacement;
    if (skinActor) {
      skinActor->SetVisibility(isSkinShown);
      skinActor->GetProperty()->SetOpacity(options.skin == SkinDisplay::Translucent ? kSkinTranslucency
                                                                                    : 1.0);
      skinActor->GetProperty()->SetColor(0.93, 0.76, 0.64);
      skinActor->GetMapper()->SetScalarVisibility(isSkinColoured);
    }
    skinBar->SetVisibility(isSkinShown && isSkinColoured);
    stackLegends();
    for (const auto& g : ghost) g.second->SetVisibility(hasGhost && options.showGhost);
    motionText->SetInput(motionCaption().c_str());
    motionText->SetVisibility(!motionCaption().empty());
    // morph playback: the skin, plain, and the baked bones; everything else the physics moves is hidden
    if (!playback.empty()) {
      for (vtkProp* prop : ownedProps()) prop->SetVisibility(prop == skinActor.GetPointer() && isSkinShown);
      showBones(
          [&](std::size_t b) { return options.showBones && b < playbackBone.size() && playbackBone[b]; });
      for (vtkProp* bar : {forceBar.GetPointer(), gutBar.GetPointer(), skinBar.GetPointer()})
        bar->SetVisibility(false);
      if (skinActor) skinActor->GetMapper()->SetScalarVisibility(false);
    }
    for (const Label& l : labels) {
      const bool relevant = l.group >= 0      ? options.showGroup[static_cast<std::size_t>(l.group)]
                            : l.landmark >= 0 ? options.showLandmarks
                                              : options.showBones;
      l.actor->SetVisibility(options.showLabels && relevant);
    }
  }
};

ModelScene::ModelScene() : m_impl(std::make_unique<Impl>()) {
  vtkRenderer* r = m_impl->renderer;
  // translucent surfaces blended in the order drawn (gut, cavity, lungs, skin: inside out) instead of VTK's
  // default order-independent pass, whose two floating-point targets and final pass cost a fifth of a frame
  // under software OpenGL
  vtkNew<vtkRenderStepsPass> steps;
  r->SetPass(steps);
  // no frustum culling: the whole model is in view, and the culler's bounds of every moved actor (a pass over
  // its cells) were recomputed at every frame
  r->GetCullers()->RemoveAllItems();
  // paraview-like blue-grey gradient
  r->GradientBackgroundOn();
  r->SetBackground(0.11, 0.12, 0.16);
  r->SetBackground2(0.36, 0.39, 0.47);
  r->AddViewProp(m_impl->forceBar);
  r->AddViewProp(m_impl->gutBar);
  r->AddViewProp(m_impl->skinBar);
  m_impl->forceBar->VisibilityOff();
  m_impl->gutBar->VisibilityOff();
  m_impl->skinBar->VisibilityOff();
  vtkTextActor* motion = m_impl->motionText;
  motion->GetPositionCoordinate()->SetCoordinateSystemToNormalizedViewport();
  motion->SetPosition(0.015, 0.94);
  vtkTextProperty* text = motion->GetTextProperty();
  text->SetFontSize(18);
  text->BoldOn();
  text->ShadowOff();
  text->SetColor(1.0, 0.86, 0.35);
  text->SetBackgroundColor(0.08, 0.09, 0.12);
  text->SetBackgroundOpacity(0.7);
  motion->PickableOff();
  r->AddViewProp(motion);
  // the teaching captions are laid out on the screen before every render, whatever moved the camera
  vtkNew<vtkCallbackCommand> layout;
  layout->SetClientData(m_impl.get());
  layout->SetCallback(
      [](vtkObject*, unsigned long, void* impl, void*) { static_cast<Impl*>(impl)->layoutLabels(); });
  m_impl->layoutObserver = r->AddObserver(vtkCommand::StartEvent, layout);
  m_impl->applyOptions();
}

ModelScene::~ModelScene() { m_impl->renderer->RemoveObserver(m_impl->layoutObserver); }

vtkRenderer* ModelScene::renderer() const { return m_impl->renderer; }

void ModelScene::installOrientationMarker(vtkRenderWindowInteractor* interactor) {
  // axes labelled with the anatomical directions of the RAS world frame
  vtkNew<vtkAxesActor> axes;
  axes->SetXAxisLabelText("R");
  axes->SetYAxisLabelText("A");
  axes->SetZAxisLabelText("S");
  for (vtkCaptionActor2D* caption :
       {axes->GetXAxisCaptionActor2D(), axes->GetYAxisCaptionActor2D(), axes->GetZAxisCaptionActor2D()}) {
    caption->GetCaptionTextProperty()->SetFontSize(14);
    caption->GetCaptionTextProperty()->ShadowOff();
    caption->GetCaptionTextProperty()->ItalicOff();
  }
  m_impl->marker = vtkSmartPointer<vtkOrientationMarkerWidget>::New();
  m_impl->marker->SetOrientationMarker(axes);
  m_impl->marker->SetInteractor(interactor);
  m_impl->marker->SetDefaultRenderer(m_impl->renderer);
  m_impl->marker->SetViewport(0.0, 0.0, 0.14, 0.2);
  m_impl->marker->SetEnabled(1);
  m_impl->marker->InteractiveOff();
}

void ModelScene::setModel(const sim::Model& model, const std::string& modelDir) {
  // read everything first so a failure leaves the current scene untouched
  const auto meshes = Impl::readBodyMeshes(model, modelDir);
  m_impl->clear();
  m_impl->model = model;
  m_impl->build(meshes);
  m_impl->applyOptions();
  const sim::State rest = sim::makeInitialState(model);
  sim::Metrics relaxed;
  relaxed.elementForce = Eigen::VectorXd::Zero(model.elements.size());
  relaxed.isSlack.assign(static_cast<std::size_t>(model.elements.size()), 1);
  update(rest, relaxed);
  setCamera(CameraPreset::Oblique);
}

void ModelScene::update(const sim::State& state, const sim::Metrics& metrics,
                        const sim::State* endExpiration) {
  Impl& s = *m_impl;
  const sim::Model& model = s.model;

  // display only: the motion from the end-expiratory pose magnified, posed by the one posing function
  const bool isMagnified = endExpiration && s.options.magnification != 1.0;
  if (isMagnified)
    sim::poseGeometry(model, sim::magnifyMotion(*endExpiration, state, s.options.magnification), s.posed);
  else
    sim::poseGeometry(model, state, s.posed);
  // the real (unmagnified) pose and the end-expiratory one, for the displacements the colours show
  if (isMagnified) sim::poseGeometry(model, state, s.real);
  const sim::PosedGeometry& real = isMagnified ? s.real : s.posed;
  const double referenceKey = endExpiration ? endExpiration->time : -1.0;
  if (!(referenceKey == s.referenceTime)) {
    sim::poseGeometry(model, endExpiration ? *endExpiration : sim::makeInitialState(model), s.reference);
    if (s.skin) sim::lungPositions(s.drawnSkin, s.reference.skin, s.drawnSkinReference);
    s.referenceTime = referenceKey;
  }
  const bool isAuto = s.options.isAutoRange;

  s.poseBones();

  // muscle elements: end positions, and their tension [N] (NaN = slack = grey) or their group's activation
  const bool hasForces = metrics.elementForce.size() == model.elements.size();
  const bool byActivation = s.options.muscleColouring == MuscleColouring::Activation;
  s.values.clear();
  for (Impl::Group& g : s.groups) {
    if (!g.lines) continue;
    vtkPoints* points = g.lines->GetPoints();
    for (std::size_t k = 0; k < g.element.size(); ++k) {
      const int e = g.element[k];
      const auto id = static_cast<vtkIdType>(2 * k);
      points->SetPoint(id, s.posed.elementA(0, e), s.posed.elementA(1, e), s.posed.elementA(2, e));
      points->SetPoint(id + 1, s.posed.elementB(0, e), s.posed.elementB(1, e), s.posed.elementB(2, e));
      const sim::ElementGroup group = model.elements.group[static_cast<std::size_t>(e)];
      double value = std::numeric_limits<double>::quiet_NaN();
      if (byActivation) {
        value = metrics.activations[static_cast<std::size_t>(group)].alpha;
      } else {
        const double tension = hasForces ? std::max(0.0, -metrics.elementForce(e)) : 0.0;
        const bool isSlack = !(tension > 0.0) || (static_cast<std::size_t>(e) < metrics.isSlack.size() &&
                                                  metrics.isSlack[static_cast<std::size_t>(e)]);
        if (!isSlack) value = tension;
      }
      g.force->SetValue(static_cast<vtkIdType>(k), static_cast<float>(value));
      if (isAuto && std::isfinite(value) && sim::isMuscleGroup(group)) s.values.push_back(value);
    }
    points->Modified();
    g.force->Modified();
  }
  if (byActivation) {
    setScale(s.forceBar, s.activationTable, 0.0, kActivationTop);
  } else {
    if (isAuto) s.muscleTop = autoTop(s.values, s.muscleTop);
    setScale(s.forceBar, s.forceTable, 0.0, isAuto ? std::max(s.muscleTop, 1.0) : kTensionTop);
  }

  // gut surface, coloured by its real displacement from end-expiration [mm] or its pressure [cmH2O]
  if (s.gut) {
    Impl::setPoints(s.gut, s.posed.gut);
    Impl::setNormals(s.gut, s.posed.gut, model.gut.triangles, s.normalScratch);
    const bool byPressure = s.options.gutColouring == GutColouring::Pressure;
    const double pressure = metrics.gutPressure / kPascalPerCmH2O;
    s.values.clear();
    for (int n = 0; n < model.nodes.size(); ++n) {
      const double d = 1000.0 * (real.gut.col(n) - s.reference.gut.col(n)).norm();
      s.gutScalar->SetValue(n, static_cast<float>(byPressure ? pressure : d));
      if (isAuto && !byPressure) s.values.push_back(d);
    }
    s.gutScalar->Modified();
    if (byPressure) {
      // the pressure is uniform (Eq. 4): its colour moves over a symmetric scale
      if (isAuto) s.gutPressureTop = std::max(s.gutPressureTop, niceCeil(std::abs(pressure)));
      const double top = isAuto ? std::max(s.gutPressureTop, 1.0) : kGutPressureTop;
      setScale(s.gutBar, s.gutTable, -top, top);
    } else {
      if (isAuto) s.gutDisplacementTop = autoTop(s.values, s.gutDisplacementTop);
      setScale(s.gutBar, s.gutTable, 0.0, isAuto ? std::max(s.gutDisplacementTop, 1.0) : kGutDisplacementTop);
    }
  }

  // the volume bodies: their nodes
  if (s.tissue) {
    Impl::setPoints(s.tissue, s.posed.gut);
    Impl::setNormals(s.tissue, s.posed.gut, s.tissueTriangles, s.normalScratch);
  }

  // cavity and landmarks
  if (s.cavity) {
    Impl::setPoints(s.cavity, s.posed.cavity);
    if (s.lungs[0]) Impl::setPoints(s.lungs[0], s.posed.lungRight);
    if (s.lungs[1]) Impl::setPoints(s.lungs[1], s.posed.lungLeft);
  }
  const Eigen::Matrix3Xd& lm = s.posed.landmarks;
  if (s.landmarks) Impl::setPoints(s.landmarks, lm);

  // skin and its real displacement from end-expiration [mm]
  if (s.skin) {
    s.setSkin(s.posed.skin);
    if (isMagnified) sim::lungPositions(s.drawnSkin, real.skin, s.drawnSkinReal);
    const Eigen::Matrix3Xd& drawnReal = isMagnified ? s.drawnSkinReal : s.drawnSkinAt;
    s.values.clear();
    for (Eigen::Index v = 0; v < drawnReal.cols(); ++v) {
      const double d = 1000.0 * (drawnReal.col(v) - s.drawnSkinReference.col(v)).norm();
      s.skinScalar->SetValue(v, static_cast<float>(d));
      if (isAuto) s.values.push_back(d);
    }
    s.skinScalar->Modified();
    if (isAuto) s.skinTop = autoTop(s.values, s.skinTop);
    setScale(s.skinBar, s.skinTable, 0.0, isAuto ? std::max(s.skinTop, 1.0) : kSkinDisplacementTop);
  }

  // labels follow their structures
  for (const Impl::Label& l : s.labels) {
    Eigen::Vector3d at = Eigen::Vector3d::Zero();
    if (l.landmark >= 0) {
      at = lm.col(l.landmark);
    } else if (l.body >= 0) {
      at = s.posed.body[static_cast<std::size_t>(l.body)].translation();
    } else {
      // a group is labelled at its element furthest to the subject's right, clear of the midline
      at = Eigen::Vector3d::Constant(-1e9);
      for (int e : s.groups[static_cast<std::size_t>(l.group)].element) {
        const Eigen::Vector3d mid = 0.5 * (s.posed.elementA.col(e) + s.posed.elementB.col(e));
        if (mid.x() > at.x()) at = mid;
      }
    }
    l.actor->SetAttachmentPoint(at.x(), at.y(), at.z());
  }
  // (the captions are placed on the screen before each render: layoutLabels())

  // selection highlight
  if (s.highlight.kind == Pick::Kind::Element) {
    const int e = s.highlight.index;
    s.highlightLine->GetPoints()->SetPoint(0, s.posed.elementA(0, e), s.posed.elementA(1, e),
                                           s.posed.elementA(2, e));
    s.highlightLine->GetPoints()->SetPoint(1, s.posed.elementB(0, e), s.posed.elementB(1, e),
                                           s.posed.elementB(2, e));
    s.highlightLine->GetPoints()->Modified();
  }
}

void ModelScene::setGhost(const sim::State* state, const sim::State* endExpiration) {
  Impl& s = *m_impl;
  s.hasGhost = state && state->nodePosition.cols() == s.model.nodes.size() && !s.ghost.empty();
  if (s.hasGhost) {
    // the same magnification as this run's (update())
    if (endExpiration && s.options.magnification != 1.0)
      sim::poseGeometry(s.model, sim::magnifyMotion(*endExpiration, *state, s.options.magnification),
                        s.ghostPosed);
    else
      sim::poseGeometry(s.model, *state, s.ghostPosed);
    Impl::setPoints(s.ghost[0].first, s.ghostPosed.gut);
    std::size_t k = 1;
    for (const Eigen::Matrix3Xd* lung : {&s.ghostPosed.lungRight, &s.ghostPosed.lungLeft})
      if (k < s.ghost.size() && lung->cols() == s.ghost[k].first->GetNumberOfPoints())
        Impl::setPoints(s.ghost[k++].first, *lung);
  }
  for (const auto& g : s.ghost)
    g.second->SetVisibility(s.hasGhost && s.options.showGhost && s.playback.empty());
}

bool ModelScene::isGhostShown() const {
  return m_impl->hasGhost && m_impl->options.showGhost && m_impl->playback.empty();
}

const sim::PosedGeometry& ModelScene::posed() const { return m_impl->posed; }

std::string ModelScene::motionCaption() const { return m_impl->motionCaption(); }

void ModelScene::setMorphPlayback(const std::string& affect) {
  m_impl->playback = affect;
  m_impl->applyOptions();
}

const std::string& ModelScene::morphPlayback() const { return m_impl->playback; }

void ModelScene::updateMorphPlayback(const sim::MorphTargets& targets, const Eigen::VectorXd& weights) {
  Impl& s = *m_impl;
  if (!s.skinActor || !s.skin || targets.base.cols() != s.model.skin.vertexCount() ||
      weights.size() != static_cast<Eigen::Index>(targets.targets.size()))
    return;
  // the skin: base + m sum_k w_k D_k [m]
  const double m = s.options.magnification;
  Eigen::Matrix3Xd x = targets.base;
  for (std::size_t k = 0; k < targets.targets.size(); ++k)
    x += m * weights(static_cast<Eigen::Index>(k)) * targets.targets[k].displacement;
  s.setSkin(x);
  // the bones by the same (magnified) weights; a body the targets do not carry stays hidden
  const std::vector<Eigen::Isometry3d> poses = sim::blendBones(targets, m * weights);
  const std::size_t bodyCount = s.bones.polys.size();
  s.playbackBone.assign(bodyCount, 0);
  for (std::size_t k = 0; k < poses.size(); ++k) {
    const auto& names = s.model.bodies.name;
    const auto b =
        static_cast<std::size_t>(std::find(names.begin(), names.end(), targets.bones[k]) - names.begin());
    if (b >= bodyCount) continue;
    if (s.posed.body.size() != bodyCount) s.posed.body.resize(bodyCount, Eigen::Isometry3d::Identity());
    s.playbackBone[b] = 1;
    s.posed.body[b] = poses[k];
  }
  s.poseBones();
  s.applyOptions();
}

void ModelScene::setOptions(const DisplayOptions& options) {
  if (options.isAutoRange != m_impl->options.isAutoRange) m_impl->resetAutoRange();
  m_impl->options = options;
  m_impl->applyOptions();
}

const DisplayOptions& ModelScene::options() const { return m_impl->options; }

const std::vector<std::pair<std::string, CameraPreset>>& cameraPresets() {
  static const std::vector<std::pair<std::string, CameraPreset>> presets{
      {"anterior", CameraPreset::Anterior},
      {"lateral", CameraPreset::Lateral},
      {"superior", CameraPreset::Superior},
      {"posterior", CameraPreset::Posterior},
      {"oblique", CameraPreset::Oblique}};
  return presets;
}

void ModelScene::setCamera(CameraPreset preset) {
  Eigen::Vector3d dir(0.0, 1.0, 0.0);  // from the camera's side toward... the camera (RAS)
  Eigen::Vector3d up(0.0, 0.0, 1.0);
  switch (preset) {
    case CameraPreset::Anterior:
      dir = {0.0, 1.0, 0.0};
      break;
    case CameraPreset::Lateral:
      dir = {1.0, 0.0, 0.0};
      break;
    case CameraPreset::Superior:
      dir = {0.0, 0.0, 1.0};
      up = {0.0, 1.0, 0.0};
      break;
    case CameraPreset::Posterior:
      dir = {0.0, -1.0, 0.0};
      break;
    case CameraPreset::Oblique:
      dir = Eigen::Vector3d(0.8, 1.0, 0.45).normalized();
      break;
  }
  vtkCamera* camera = m_impl->renderer->GetActiveCamera();
  camera->SetFocalPoint(0.0, 0.0, 0.0);
  camera->SetPosition(dir.x(), dir.y(), dir.z());
  camera->SetViewUp(up.x(), up.y(), up.z());
  m_impl->renderer->ResetCamera();
  camera->Zoom(1.15);
  m_impl->renderer->ResetCameraClippingRange();
}

Pick ModelScene::pick(int x, int y) const {
  vtkNew<vtkCellPicker> picker;
  picker->SetTolerance(0.004);
  if (!picker->Pick(x, y, 0.0, m_impl->renderer)) return {};
  vtkActor* hit = picker->GetActor();
  for (const Impl::Group& g : m_impl->groups)
    if (hit && hit == g.actor && picker->GetCellId() >= 0 &&
        static_cast<std::size_t>(picker->GetCellId()) < g.element.size())
      return {Pick::Kind::Element, g.element[static_cast<std::size_t>(picker->GetCellId())]};
  const Impl::Bones& bones = m_impl->bones;
  if (hit && hit == bones.actor && picker->GetCellId() >= 0 &&
      static_cast<std::size_t>(picker->GetCellId()) < bones.cellBody.size())
    return {Pick::Kind::Body, bones.cellBody[static_cast<std::size_t>(picker->GetCellId())]};
  return {};
}

void ModelScene::setHighlight(const Pick& pick) {
  Impl& s = *m_impl;
  // restore the previous body colour, then mark the new selection
  if (s.highlight.kind == Pick::Kind::Body) s.colourBone(s.highlight.index, s.boneColour(s.highlight.index));
  s.highlight = pick;
  if (!s.highlightActor) return;
  s.highlightActor->SetVisibility(pick.kind == Pick::Kind::Element);
  if (pick.kind == Pick::Kind::Body) s.colourBone(pick.index, {77, 242, 242});
  if (pick.kind == Pick::Kind::Element) {
    const int e = pick.index;
    s.highlightLine->GetPoints()->SetPoint(0, s.posed.elementA(0, e), s.posed.elementA(1, e),
                                           s.posed.elementA(2, e));
    s.highlightLine->GetPoints()->SetPoint(1, s.posed.elementB(0, e), s.posed.elementB(1, e),
                                           s.posed.elementB(2, e));
    s.highlightLine->GetPoints()->Modified();
  }
}

std::string ModelScene::describe(const Pick& pick) const {
  const sim::Model& model = m_impl->model;
  if (pick.kind == Pick::Kind::Body) return model.bodies.name[static_cast<std::size_t>(pick.index)];
  if (pick.kind == Pick::Kind::Element) {
    const auto g = model.elements.group[static_cast<std::size_t>(pick.index)];
    const std::string kind = model.elements.recruitmentOf(pick.index) > 0.0
                                 ? std::string("Accessory muscle (") + groupLabel(g) + " drive)"
                                 : groupLabel(g);
    return kind + " element " + std::to_string(pick.index);
  }
  return {};
}

}  // namespace pneuma::viz
