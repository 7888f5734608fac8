// The ParaView series (viz::VtkSeriesWriter) reproduces the posed geometry of every frame: read back with
// VTK's own reader, the bones are their body-frame meshes moved by R p + x, each muscle a line between its
// two anchor positions, the gut at the node positions with displacement x - x_rest, the cavity at its bound
// vertices, with the frame's pressure, forces and time.
#include "viz/VtkSeriesWriter.h"

#include <gtest/gtest.h>
#include <unistd.h>
#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkFieldData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkXMLPolyDataReader.h>
#include <vtkXMLPolyDataWriter.h>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

#include "VizTestSupport.h"

namespace pneuma {
namespace {

namespace fs = std::filesystem;
using Eigen::Vector3d;

vtkSmartPointer<vtkPolyData> readPart(const std::string& path) {
  vtkNew<vtkXMLPolyDataReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  return reader->GetOutput();
}

Vector3d point(vtkPolyData* pd, vtkIdType i) {
  double p[3];
  pd->GetPoint(i, p);
  return {p[0], p[1], p[2]};
}

TEST(VtkSeriesWriter, FramesHoldThePosedGeometry) {
  const fs::path dir = fs::path(testing::TempDir()) / ("pneuma_series_" + std::to_string(getpid()));
  fs::remove_all(dir);
  fs::create_directories(dir / "model");
  // one body with a render mesh (a triangle in its body frame), the others drawn as a vertex at the com
  sim::Model model = sim::test::makeToyTorso(2);
  int meshed = 0;
  while (model.bodies.isFixed[static_cast<std::size_t>(meshed)]) ++meshed;
  const Eigen::Matrix3d triangle =
      (Eigen::Matrix3d() << 0.01, 0, 0, 0, 0.02, 0, 0, 0, 0.03).finished();  // [m] columns
  {
    vtkNew<vtkPolyData> mesh;
    vtkNew<vtkPoints> pts;
    for (int k = 0; k < 3; ++k) pts->InsertNextPoint(triangle(0, k), triangle(1, k), triangle(2, k));
    mesh->SetPoints(pts);
    vtkNew<vtkCellArray> polys;
    const vtkIdType ids[3] = {0, 1, 2};
    polys->InsertNextCell(3, ids);
    mesh->SetPolys(polys);
    vtkNew<vtkXMLPolyDataWriter> writer;
    writer->SetInputData(mesh);
    writer->SetFileName((dir / "model" / "bone.vtp").c_str());
    ASSERT_EQ(writer->Write(), 1);
  }
  model.bodies.mesh[static_cast<std::size_t>(meshed)] = "bone.vtp";

  viz::VtkSeriesWriter writer(model, (dir / "model").string(), dir.string(), "run");
  std::vector<sim::State> states;
  for (unsigned f = 1; f <= 2; ++f) {
    states.push_back(test::posedState(model, f));
    writer.writeFrame(states.back(), test::someMetrics(model, states.back(), f));
  }
  EXPECT_EQ(writer.finish(), "run.pvd");

  // the collection lists the seven parts of each frame at its time
  std::ifstream pvdFile(dir / "run.pvd");
  std::stringstream pvd;
  pvd << pvdFile.rdbuf();
  EXPECT_NE(pvd.str().find("timestep=\"0.5\" group=\"\" part=\"2\" name=\"gut\" file=\"run/gut_000001.vtp\""),
            std::string::npos)
      << pvd.str();

  // the skin, the sixth part: written for every frame, empty for a model without a skin
  EXPECT_NE(pvd.str().find("part=\"5\" name=\"skin\" file=\"run/skin_000001.vtp\""), std::string::npos);
  EXPECT_TRUE(fs::exists(dir / "run" / "skin_000001.vtp"));

  const sim::State& s = states[1];
  const double tol = 1e-12;  // [m] written as doubles
  // bones: the meshed body's triangle at R p + x, every other body a vertex at its com
  const auto bones = readPart((dir / "run" / "bones_000001.vtp").string());
  ASSERT_EQ(bones->GetNumberOfPoints(), model.bodies.size() - 1 + 3);
  vtkDataArray* bodyId = bones->GetCellData()->GetArray("body_id");
  ASSERT_NE(bodyId, nullptr);
  int checked = 0;
  for (vtkIdType c = 0; c < bones->GetNumberOfCells(); ++c) {
    const int b = static_cast<int>(bodyId->GetTuple1(c));
    vtkIdType n = 0;
    const vtkIdType* ids = nullptr;
    bones->GetCellPoints(c, n, ids);
    const Eigen::Matrix3d r = s.bodyOrientation[static_cast<std::size_t>(b)].toRotationMatrix();
    for (vtkIdType k = 0; k < n; ++k) {
      // the nearest of the body's posed mesh points (the mesh reader may reorient the triangle)
      double nearest = 1e9;
      for (int j = 0; j < (b == meshed ? 3 : 1); ++j) {
        const Vector3d local = b == meshed ? Vector3d(triangle.col(j)) : Vector3d::Zero();
        nearest = std::min(nearest, (point(bones, ids[k]) - (r * local + s.bodyPosition.col(b))).norm());
      }
      EXPECT_LT(nearest, 1e-8) << "body " << b;  // the mesh file holds single precision
      ++checked;
    }
  }
  EXPECT_EQ(checked, bones->GetNumberOfPoints());

  // muscles: element e is the line from its end A to its end B, with its force
  Eigen::Matrix3Xd a, b;
  sim::anchorPositions(model.elements.endA, s, a);
  sim::anchorPositions(model.elements.endB, s, b);
  const auto muscles = readPart((dir / "run" / "muscles_000001.vtp").string());
  ASSERT_EQ(muscles->GetNumberOfCells(), model.elements.size());
  const sim::Metrics metrics = test::someMetrics(model, s, 2);
  for (int e = 0; e < model.elements.size(); ++e) {
    vtkIdType n = 0;
    const vtkIdType* ids = nullptr;
    muscles->GetCellPoints(e, n, ids);
    ASSERT_EQ(n, 2);
    EXPECT_LT((point(muscles, ids[0]) - a.col(e)).norm(), tol) << e;
    EXPECT_LT((point(muscles, ids[1]) - b.col(e)).norm(), tol) << e;
    EXPECT_EQ(muscles->GetCellData()->GetArray("force_N")->GetTuple1(e), metrics.elementForce(e));
  }

  // gut: the node positions, their displacement from rest, the frame's pressure
  const auto gut = readPart((dir / "run" / "gut_000001.vtp").string());
  ASSERT_EQ(gut->GetNumberOfPoints(), model.nodes.size());
  vtkDataArray* displacement = gut->GetPointData()->GetArray("displacement_m");
  for (int i = 0; i < model.nodes.size(); ++i) {
    EXPECT_LT((point(gut, i) - s.nodePosition.col(i)).norm(), tol) << i;
    double d[3];
    displacement->GetTuple(i, d);
    EXPECT_LT((Vector3d(d[0], d[1], d[2]) - (s.nodePosition.col(i) - model.nodes.rest.col(i))).norm(), tol)
        << i;
  }
  EXPECT_EQ(gut->GetFieldData()->GetArray("pressure_Pa")->GetTuple1(0), 200.0);

  // cavity: its vertices where they are bound (bones and nodes)
  Eigen::Matrix3Xd cavity;
  sim::anchorPositions(model.cavity.vertices, s, cavity);
  const auto cav = readPart((dir / "run" / "cavity_000001.vtp").string());
  ASSERT_EQ(cav->GetNumberOfPoints(), cavity.cols());
  for (Eigen::Index i = 0; i < cavity.cols(); ++i)
    EXPECT_LT((point(cav, i) - cavity.col(i)).norm(), tol) << i;
  fs::remove_all(dir);
}

// the dialog's and the CLI's frame count is the number of frames the selector keeps, for a 60 Hz recording
// that starts late (a kept window of the last 60 s) and any range and stride
TEST(SeriesRange, CountIsWhatTheSelectorKeeps) {
  const double first = 2.5, rate = 60.0;  // [s], [1/s]
  const std::size_t frames = 3601;        // 60 s
  for (const viz::SeriesRange r :
       {viz::SeriesRange{10.0, 20.0, 3}, viz::SeriesRange{0.0, 100.0, 1}, viz::SeriesRange{2.5, 2.5, 7},
        viz::SeriesRange{30.01, 30.02, 1}, viz::SeriesRange{61.0, 70.0, 4}, viz::SeriesRange{}}) {
    viz::SeriesSelector selector(r);
    int kept = 0;
    double previous = -1.0;
    for (std::size_t i = 0; i < frames; ++i) {
      const double t = first + static_cast<double>(i) / rate;
      if (!selector.take(t)) continue;
      EXPECT_GE(t, r.from - 1e-9);
      EXPECT_LE(t, r.to + 1e-9);
      // every stride-th frame
      if (kept > 0) {
        EXPECT_NEAR(t - previous, r.stride / rate, 1e-9);
      }
      previous = t;
      ++kept;
    }
    EXPECT_EQ(r.count(frames, first, first + (frames - 1) / rate), kept) << r.from << " to " << r.to;
  }
  // 10 s to 20 s at 60 Hz is 601 frames; one in three of them is 201
  EXPECT_EQ((viz::SeriesRange{10.0, 20.0, 3}).count(frames, first, first + 60.0), 201);
  EXPECT_EQ((viz::SeriesRange{0.0, 1.0, 0}).error("from", "to", "stride"),
            "stride: expected a whole number >= 1, got 0");
  EXPECT_EQ((viz::SeriesRange{2.0, 1.0, 1}).error("--vtk-from", "--vtk-to", "s"),
            "--vtk-to: expected seconds at or after --vtk-from");
}

constexpr auto kStaged = viz::VtkSeriesWriter::Staging::TemporaryFolder;  // the app's export

// a toy model with its bodies drawn as vertices, a posed frame of it, and a fresh folder
struct SeriesFixture {
  sim::Model model = sim::test::makeToyTorso(2);
  fs::path dir;
  explicit SeriesFixture(const std::string& name)
      : dir(fs::path(testing::TempDir()) / ("pneuma_series_" + name + "_" + std::to_string(getpid()))) {
    fs::remove_all(dir);
    fs::create_directories(dir);
  }
  void writeFrames(viz::VtkSeriesWriter& writer, unsigned n) const {
    for (unsigned f = 1; f <= n; ++f) {
      const sim::State s = test::posedState(model, f);
      writer.writeFrame(s, test::someMetrics(model, s, f));
    }
  }
  std::size_t entries(const fs::path& folder) const {
    return static_cast<std::size_t>(std::distance(fs::directory_iterator(folder), fs::directory_iterator{}));
  }
};

// a writer destroyed unfinished (a cancelled export) removes what it wrote and its own folder, and nothing
// else: an earlier series of the same name and another file stay as they were
TEST(VtkSeriesWriter, UnfinishedWriterRemovesOnlyItsOwnFiles) {
  SeriesFixture f("cancel");
  fs::create_directories(f.dir / "run");
  { std::ofstream(f.dir / "run" / "bones_000000.vtp") << "an earlier series"; }
  { std::ofstream(f.dir / "notes.txt") << "the lecturer's notes"; }
  {
    viz::VtkSeriesWriter writer(f.model, f.dir.string(), f.dir.string(), "run", kStaged);
    f.writeFrames(writer, 3);
    EXPECT_EQ(f.entries(f.dir), 3u) << "run, notes.txt and the writer's own folder";
  }
  EXPECT_EQ(f.entries(f.dir), 2u);
  EXPECT_EQ(f.entries(f.dir / "run"), 1u);
  std::ifstream earlier(f.dir / "run" / "bones_000000.vtp");
  std::string text;
  std::getline(earlier, text);
  EXPECT_EQ(text, "an earlier series");
  EXPECT_TRUE(fs::exists(f.dir / "notes.txt"));

  // finished, it replaces the earlier series whole
  viz::VtkSeriesWriter writer(f.model, f.dir.string(), f.dir.string(), "run", kStaged);
  f.writeFrames(writer, 2);
  EXPECT_EQ(writer.finish(), "run.pvd");
  EXPECT_EQ(f.entries(f.dir / "run"), 14u) << "two frames of seven parts";
  EXPECT_GT(fs::file_size(f.dir / "run" / "bones_000000.vtp"), 100u);
  EXPECT_EQ(f.entries(f.dir), 3u) << "run, run.pvd and notes.txt";
}

// a folder of the series' name that holds anything else is not replaced: the export fails naming it and
// removes its own frames
TEST(VtkSeriesWriter, AFolderHoldingOtherFilesIsNotReplaced) {
  SeriesFixture f("occupied");
  fs::create_directories(f.dir / "run");
  { std::ofstream(f.dir / "run" / "thesis.tex") << "months of work"; }
  {
    viz::VtkSeriesWriter writer(f.model, f.dir.string(), f.dir.string(), "run", kStaged);
    f.writeFrames(writer, 2);
    try {
      writer.finish();
      ADD_FAILURE() << "the folder was replaced";
    } catch (const std::runtime_error& e) {
      EXPECT_NE(std::string(e.what()).find("thesis.tex"), std::string::npos) << e.what();
    }
  }
  EXPECT_EQ(f.entries(f.dir), 1u) << "only run/";
  EXPECT_EQ(f.entries(f.dir / "run"), 1u) << "only thesis.tex";
}

// the size shown before an export is what a frame takes on disk: frameBytes() equals the six files' sizes
TEST(VtkSeriesWriter, FrameBytesIsTheSizeOfAWrittenFrame) {
  SeriesFixture f("bytes");
  const sim::State s = test::posedState(f.model, 1);
  const sim::Metrics m = test::someMetrics(f.model, s, 1);
  viz::VtkSeriesWriter writer(f.model, f.dir.string(), f.dir.string(), "run", kStaged);
  writer.writeFrame(s, m);
  writer.finish();
  std::size_t onDisk = 0;
  for (const auto& e : fs::directory_iterator(f.dir / "run")) onDisk += fs::file_size(e.path());
  EXPECT_EQ(viz::VtkSeriesWriter::frameBytes(f.model, f.dir.string(), s, m), onDisk);
  EXPECT_GT(onDisk, 1000u);
}

}  // namespace
}  // namespace pneuma
