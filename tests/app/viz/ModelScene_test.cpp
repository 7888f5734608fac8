// The 3D scene (viz::ModelScene) draws the posed model: after update(), each bone's drawn points are its rest
// points moved by its body's pose [R x], and the drawn points (every actor's data through its matrix) hold
// every gut node, both ends of every element and every cavity vertex where the state puts them, none left at
// rest.
#include "viz/ModelScene.h"

#include <gtest/gtest.h>
#include <vtkActor.h>
#include <vtkActorCollection.h>
#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkDataSet.h>
#include <vtkMapper.h>
#include <vtkMatrix4x4.h>
#include <vtkPointData.h>
#include <vtkProperty.h>
#include <vtkRenderer.h>
#include <vtkUnsignedCharArray.h>

#include <cmath>
#include <limits>
#include <vector>

#include "VizTestSupport.h"

namespace pneuma {
namespace {

using Eigen::Vector3d;

// the points of every actor's data in world coordinates (through the actor's matrix)
void drawn(vtkRenderer* renderer, std::vector<Vector3d>& points) {
  vtkActorCollection* actors = renderer->GetActors();
  actors->InitTraversal();
  while (vtkActor* actor = actors->GetNextActor()) {
    vtkMapper* mapper = actor->GetMapper();
    if (!mapper) continue;
    mapper->Update();
    vtkDataSet* data = mapper->GetInput();
    Eigen::Matrix4d m;
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 4; ++j) m(i, j) = actor->GetMatrix()->GetElement(i, j);
    for (vtkIdType k = 0; data && k < data->GetNumberOfPoints(); ++k) {
      double p[3];
      data->GetPoint(k, p);
      points.push_back((m * Eigen::Vector4d(p[0], p[1], p[2], 1.0)).head<3>());
    }
  }
}

// the bones' drawn points with their body (the point array "body" of the bones' one actor), world [m]
std::vector<std::pair<int, Vector3d>> bonePoints(vtkRenderer* renderer) {
  std::vector<std::pair<int, Vector3d>> out;
  vtkActorCollection* actors = renderer->GetActors();
  actors->InitTraversal();
  while (vtkActor* actor = actors->GetNextActor()) {
    vtkDataSet* data = actor->GetMapper() ? actor->GetMapper()->GetInput() : nullptr;
    vtkDataArray* body = data ? data->GetPointData()->GetArray("body") : nullptr;
    for (vtkIdType k = 0; body && k < data->GetNumberOfPoints(); ++k) {
      double p[3];
      data->GetPoint(k, p);
      out.emplace_back(static_cast<int>(body->GetTuple1(k)), Vector3d(p[0], p[1], p[2]));
    }
  }
  return out;
}

double nearest(const std::vector<Vector3d>& points, const Vector3d& x) {
  double best = std::numeric_limits<double>::infinity();
  for (const Vector3d& p : points) best = std::min(best, (p - x).squaredNorm());
  return std::sqrt(best);
}

TEST(ModelScene, ActorsAreAtThePosedPositions) {
  const sim::Model model = sim::test::makeToyTorso(2);
  viz::ModelScene scene;
  scene.setModel(model, "");
  viz::DisplayOptions all = scene.options();
  all.showCavity = true;
  scene.setOptions(all);
  const double tol = 1e-6;  // [m] VTK keeps points in single precision
  const sim::State rest = sim::makeInitialState(model);
  scene.update(rest, test::someMetrics(model, rest, 3));
  const std::vector<std::pair<int, Vector3d>> restBones = bonePoints(scene.renderer());
  const sim::State s = test::posedState(model, 3);
  scene.update(s, test::someMetrics(model, s, 3));

  std::vector<Vector3d> points;
  drawn(scene.renderer(), points);

  // each bone is drawn at its body's pose: x = R (x_rest - c_rest) + c, every point of every body
  const std::vector<std::pair<int, Vector3d>> posedBones = bonePoints(scene.renderer());
  ASSERT_EQ(posedBones.size(), restBones.size());
  std::vector<int> pointsOf(static_cast<std::size_t>(model.bodies.size()), 0);
  for (std::size_t k = 0; k < posedBones.size(); ++k) {
    const int b = posedBones[k].first;
    ASSERT_EQ(b, restBones[k].first);
    const Eigen::Matrix3d R = s.bodyOrientation[static_cast<std::size_t>(b)].toRotationMatrix();
    const Vector3d expected = R * (restBones[k].second - model.bodies.com.col(b)) + s.bodyPosition.col(b);
    EXPECT_LT((posedBones[k].second - expected).norm(), tol) << "body " << b << " point " << k;
    ++pointsOf[static_cast<std::size_t>(b)];
  }
  for (int b = 0; b < model.bodies.size(); ++b) EXPECT_GT(pointsOf[static_cast<std::size_t>(b)], 0) << b;
  // gut nodes, element ends and cavity vertices where the state puts them
  for (int i = 0; i < model.nodes.size(); ++i)
    EXPECT_LT(nearest(points, s.nodePosition.col(i)), tol) << "node " << i;
  Eigen::Matrix3Xd a, b, cavity;
  sim::anchorPositions(model.elements.endA, s, a);
  sim::anchorPositions(model.elements.endB, s, b);
  for (int e = 0; e < model.elements.size(); ++e) {
    EXPECT_LT(nearest(points, a.col(e)), tol) << "element " << e << " end A";
    EXPECT_LT(nearest(points, b.col(e)), tol) << "element " << e << " end B";
  }
  sim::anchorPositions(model.cavity.vertices, s, cavity);
  for (Eigen::Index i = 0; i < cavity.cols(); ++i)
    EXPECT_LT(nearest(points, cavity.col(i)), tol) << "cavity " << i;
  // and nothing of the moved nodes is left at its rest position
  int atRest = 0;
  for (int i = 0; i < model.nodes.size(); ++i) atRest += nearest(points, model.nodes.rest.col(i)) < tol;
  EXPECT_EQ(atRest, 0);
}

// the accessory inspiratory muscles (a recruitment threshold, driven with the external intercostals) are
// drawn in their own colour when the muscles are coloured by group, and by their tension like every muscle
// otherwise
TEST(ModelScene, AccessoryMusclesHaveTheirOwnGroupColour) {
  sim::Model model = sim::test::makeToyTorso(2);
  model.elements.recruitment.setZero(model.elements.size());
  std::vector<int> external;
  for (int e = 0; e < model.elements.size(); ++e)
    if (model.elements.group[static_cast<std::size_t>(e)] == sim::ElementGroup::IntercostalExternal)
      external.push_back(e);
  ASSERT_GE(external.size(), 3u);
  model.elements.recruitment(external[0]) = 0.2;
  model.elements.recruitment(external[1]) = 0.2;
  viz::ModelScene scene;
  scene.setModel(model, "");
  const sim::State rest = sim::makeInitialState(model);
  const auto toByte = [](const std::array<double, 3>& c) {
    return Eigen::Vector3i(static_cast<int>(std::lround(255 * c[0])),
                           static_cast<int>(std::lround(255 * c[1])),
                           static_cast<int>(std::lround(255 * c[2])));
  };
  // the drawn colour of every line of the actor that holds the accessory lines: (kind, RGB) per line
  const auto colours = [&](viz::MuscleColouring colouring) {
    viz::DisplayOptions o = scene.options();
    o.muscleColouring = colouring;
    scene.setOptions(o);
    scene.update(rest, test::someMetrics(model, rest, 3));
    std::vector<std::pair<int, Eigen::Vector3i>> out;
    vtkActorCollection* actors = scene.renderer()->GetActors();
    actors->InitTraversal();
    while (vtkActor* actor = actors->GetNextActor()) {
      vtkMapper* mapper = actor->GetMapper();
      vtkDataSet* data = mapper ? mapper->GetInput() : nullptr;
      vtkDataArray* kind = data ? data->GetCellData()->GetArray("accessory") : nullptr;
      if (!kind || kind->GetRange()[1] < 1.0) continue;
      vtkUnsignedCharArray* rgba = mapper->GetScalarVisibility() ? mapper->MapScalars(1.0) : nullptr;
      const double* c = actor->GetProperty()->GetColor();
      for (vtkIdType k = 0; k < data->GetNumberOfCells(); ++k) {
        const Eigen::Vector3i shown = rgba ? Eigen::Vector3i(rgba->GetValue(4 * k), rgba->GetValue(4 * k + 1),
                                                             rgba->GetValue(4 * k + 2))
                                           : toByte({c[0], c[1], c[2]});
        out.emplace_back(static_cast<int>(kind->GetTuple1(k)), shown);
      }
    }
    return out;
  };
  const auto byGroup = colours(viz::MuscleColouring::Group);
  ASSERT_EQ(byGroup.size(), external.size()) << "one actor: the external intercostals";
  int accessory = 0;
  for (const auto& [kind, rgb] : byGroup) {
    accessory += kind;
    const Eigen::Vector3i want =
        toByte(kind == 1 ? viz::kAccessoryColour : viz::groupColour(sim::ElementGroup::IntercostalExternal));
    EXPECT_LE((rgb - want).cwiseAbs().maxCoeff(), 1) << "kind " << kind << ": " << rgb.transpose();
  }
  EXPECT_EQ(accessory, 2);
  // by tension: no line is amber
  for (const auto& [kind, rgb] : colours(viz::MuscleColouring::Force))
    EXPECT_GT((rgb - toByte(viz::kAccessoryColour)).cwiseAbs().maxCoeff(), 8) << "kind " << kind;
  EXPECT_EQ(scene.describe(viz::Pick{viz::Pick::Kind::Element, external[0]}).rfind("Accessory muscle", 0),
            0u);
}

// legend labels: evenly spaced on a 1-2-5 step, no stray decimals or exponents
TEST(ModelScene, LegendLabelsAreRoundNumbersWithoutStrayDecimals) {
  using Labels = std::vector<std::string>;
  EXPECT_EQ(viz::legendLabels(0.0, viz::kTensionTop), (Labels{"0", "5", "10", "15", "20"}));
  EXPECT_EQ(viz::legendLabels(0.0, 1.0), (Labels{"0", "0.2", "0.4", "0.6", "0.8", "1"}));
  EXPECT_EQ(viz::legendLabels(0.0, 10.0), (Labels{"0", "2", "4", "6", "8", "10"}));
  EXPECT_EQ(viz::legendLabels(-5.0, 5.0), (Labels{"-4", "-2", "0", "2", "4"}));
  EXPECT_EQ(viz::legendLabels(0.0, 500.0), (Labels{"0", "100", "200", "300", "400", "500"}));
  EXPECT_EQ(viz::legendLabels(0.0, 0.05), (Labels{"0", "0.01", "0.02", "0.03", "0.04", "0.05"}));
  // auto-ranged tops are 1, 2 or 5 x 10^n at or above the value
  EXPECT_EQ(viz::niceCeil(13.2), 20.0);
  EXPECT_EQ(viz::niceCeil(20.0), 20.0);
  EXPECT_EQ(viz::niceCeil(0.31), 0.5);
}

}  // namespace
}  // namespace pneuma
