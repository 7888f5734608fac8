#include "viz/VtkSeriesWriter.h"

#include <vtkCellArray.h>
#include <vtkCellData.h>
#include <vtkDoubleArray.h>
#include <vtkFieldData.h>
#include <vtkIdList.h>
#include <vtkIntArray.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPoints.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>
#include <vtkUnsignedCharArray.h>
#include <vtkXMLPolyDataWriter.h>

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <sstream>
#include <stdexcept>
#include <vector>

#include "pneuma/sim/Error.h"
#include "pneuma/sim/PosedGeometry.h"
#include "pneuma/sim/Ties.h"
#include "viz/AtomicFile.h"
#include "viz/ModelScene.h"

namespace pneuma::viz {

namespace fs = std::filesystem;

namespace {

constexpr const char* kPartNames[] = {"bones", "muscles", "gut", "cavity", "lungs", "skin", "tissue"};
constexpr int kPartCount = 7;

// true for a part file of a series ("gut_000012.vtp")
bool isPartFile(const std::string& name) {
  for (const char* part : kPartNames) {
    const std::string prefix = std::string(part) + "_";
    if (name.size() == prefix.size() + 10 && name.rfind(prefix, 0) == 0 &&
        name.compare(name.size() - 4, 4, ".vtp") == 0 &&
        std::all_of(name.begin() + static_cast<std::ptrdiff_t>(prefix.size()), name.end() - 4,
                    [](unsigned char c) { return std::isdigit(c) != 0; }))
      return true;
  }
  return false;
}

vtkSmartPointer<vtkDoubleArray> scalarArray(const char* name, int components, vtkIdType tuples) {
  auto a = vtkSmartPointer<vtkDoubleArray>::New();
  a->SetName(name);
  a->SetNumberOfComponents(components);
  a->SetNumberOfTuples(tuples);
  return a;
}

vtkSmartPointer<vtkCellArray> triangles(const Eigen::Matrix3Xi& tri) {
  auto cells = vtkSmartPointer<vtkCellArray>::New();
  for (Eigen::Index f = 0; f < tri.cols(); ++f) {
    const vtkIdType ids[3] = {tri(0, f), tri(1, f), tri(2, f)};
    cells->InsertNextCell(3, ids);
  }
  return cells;
}

void setPoints(vtkPolyData* pd, const Eigen::Matrix3Xd& x) {
  vtkNew<vtkPoints> pts;
  pts->SetDataTypeToDouble();
  pts->SetNumberOfPoints(x.cols());
  for (Eigen::Index i = 0; i < x.cols(); ++i) pts->SetPoint(i, x(0, i), x(1, i), x(2, i));
  pd->SetPoints(pts);
}

void fieldValue(vtkPolyData* pd, const char* name, double v) {
  auto a = scalarArray(name, 1, 1);
  a->SetValue(0, v);
  pd->GetFieldData()->AddArray(a);
}

}  // namespace

std::string SeriesRange::error(const std::string& fromName, const std::string& toName,
                               const std::string& strideName) const {
  if (!std::isfinite(from) || from < 0.0) return fromName + ": expected seconds >= 0";
  if (std::isnan(to) || !(to >= from)) return toName + ": expected seconds at or after " + fromName;
  if (stride < 1) return strideName + ": expected a whole number >= 1, got " + std::to_string(stride);
  return {};
}

int SeriesRange::count(std::size_t frames, double first, double last) const {
  if (frames == 0) return 0;
  long long lo = 0, hi = static_cast<long long>(frames) - 1;  // the recording's frames inside [from, to]
  if (frames == 1 || !(last > first)) {
    if (first < from - kTimeTolerance || first > to + kTimeTolerance) return 0;
    hi = 0;
  } else {
    const double dt = (last - first) / static_cast<double>(frames - 1);  // [s]
    lo = std::max(lo, static_cast<long long>(std::ceil((from - kTimeTolerance - first) / dt)));
    if (std::isfinite(to))
      hi = std::min(hi, static_cast<long long>(std::floor((to + kTimeTolerance - first) / dt)));
  }
  const long long inRange = hi - lo + 1;
  return inRange > 0 ? static_cast<int>((inRange + stride - 1) / stride) : 0;
}

bool SeriesSelector::take(double time) {
  if (time < m_range.from - SeriesRange::kTimeTolerance || time > m_range.to + SeriesRange::kTimeTolerance)
    return false;
  return m_inRange++ % m_range.stride == 0;
}

struct VtkSeriesWriter::Impl {
  const sim::Model& model;
  std::string outDir;
  std::string baseName;
  // bones: all body meshes appended, in body-frame coordinates, with the body of every point
  Eigen::Matrix3Xd boneLocal;      // [m] (3 x #points)
  std::vector<int> bonePointBody;  // (#points)
  vtkSmartPointer<vtkCellArray> bonePolys, boneVerts;
  vtkSmartPointer<vtkIntArray> boneBodyId;  // per cell: vertices first, then polygons (VTK's cell order)
  std::vector<double> frameTimes;           // [s]
  sim::PosedGeometry posed;                 // the frame being written (the one posing function)
  Eigen::Matrix3Xd skinRest;                // [m] skin vertices at the rest pose (3 x #V)

  fs::path frameDir;              // the frames' temporary folder, renamed by finish()
  std::vector<fs::path> written;  // the files written into it
  std::size_t bytesWritten = 0;
  bool isFinished = false;
  bool isStaged = false;  // Staging::TemporaryFolder

  Impl(const sim::Model& m, const std::string& modelDir, std::string dir, std::string base)
      : model(m), outDir(std::move(dir)), baseName(std::move(base)) {
    bonePolys = vtkSmartPointer<vtkCellArray>::New();
    boneVerts = vtkSmartPointer<vtkCellArray>::New();
    std::vector<int> vertBody, polyBody;
    std::vector<Eigen::Vector3d> local;
    for (int b = 0; b < model.bodies.size(); ++b) {
      const std::string& file = model.bodies.mesh[static_cast<std::size_t>(b)];
      const vtkIdType base0 = static_cast<vtkIdType>(local.size());
      if (file.empty()) {
        // no mesh: one vertex at the com (body-frame origin)
        local.emplace_back(Eigen::Vector3d::Zero());
        bonePointBody.push_back(b);
        boneVerts->InsertNextCell(1, &base0);
        vertBody.push_back(b);
        continue;
      }
      const std::string path = (fs::path(modelDir) / file).string();
      const vtkSmartPointer<vtkPolyData> mesh =
          readBodyMesh(path, model.bodies.name[static_cast<std::size_t>(b)]);
      for (vtkIdType p = 0; p < mesh->GetNumberOfPoints(); ++p) {
        double q[3];
        mesh->GetPoint(p, q);
        local.emplace_back(q[0], q[1], q[2]);
        bonePointBody.push_back(b);
      }
      vtkCellArray* polys = mesh->GetPolys();
      polys->InitTraversal();
      vtkNew<vtkIdList> ids;
      while (polys->GetNextCell(ids)) {
        std::vector<vtkIdType> shifted(static_cast<std::size_t>(ids->GetNumberOfIds()));
        for (vtkIdType k = 0; k < ids->GetNumberOfIds(); ++k)
          shifted[static_cast<std::size_t>(k)] = ids->GetId(k) + base0;
        bonePolys->InsertNextCell(static_cast<vtkIdType>(shifted.size()), shifted.data());
        polyBody.push_back(b);
      }
    }
    boneBodyId = vtkSmartPointer<vtkIntArray>::New();
    boneBodyId->SetName("body_id");
    for (int b : vertBody) boneBodyId->InsertNextValue(b);
    for (int b : polyBody) boneBodyId->InsertNextValue(b);
    boneLocal.resize(3, static_cast<Eigen::Index>(local.size()));
    for (std::size_t i = 0; i < local.size(); ++i) boneLocal.col(static_cast<Eigen::Index>(i)) = local[i];
    sim::poseGeometry(model, sim::makeInitialState(model), posed);
    skinRest = posed.skin;
  }

  static std::string partName(int part, int frame) {
    char name[64];
    std::snprintf(name, sizeof name, "%s_%06d.vtp", kPartNames[part], frame);
    return name;
  }
  // the part's file as the .pvd names it, relative to outDir
  std::string partPath(int part, int frame) const { return baseName + "/" + partName(part, frame); }

  // one part as VTK XML (appended data), encoded in memory
  static std::string encode(vtkPolyData* pd) {
    vtkNew<vtkXMLPolyDataWriter> writer;
    writer->SetInputData(pd);
    writer->WriteToOutputStringOn();
    writer->SetDataModeToAppended();
    if (writer->Write() != 1) throw std::runtime_error("VTK could not encode the frame");
    return writer->GetOutputString();
  }

  // the seven parts of the posed frame, encoded
  std::array<std::string, kPartCount> encodeFrame(const sim::Metrics& metrics) const {
    return {encode(bones()),        encode(muscles(metrics)), encode(gut(metrics)),   encode(cavity(metrics)),
            encode(lungs(metrics)), encode(skin()),           encode(tissue(metrics))};
  }

  // written through writeFileAtomically(), whose every write is checked: VTK's own file output can report
  // success on a full disk and leave a truncated frame
  // an error names the file as it will be called once in place (<outDir>/<baseName>/<part>)
  void write(const std::string& bytes, int part, int frame) {
    const fs::path path = frameDir / partName(part, frame);
    written.push_back(path);
    try {
      writeFileAtomically(path.string(), bytes);
      bytesWritten += bytes.size();
    } catch (const std::runtime_error& e) {
      std::string message = e.what();
      const std::string from = frameDir.string(), to = (fs::path(outDir) / baseName).string();
      for (std::size_t at = 0; from != to && (at = message.find(from, at)) != std::string::npos;
           at += to.size())
        message.replace(at, from.size(), to);
      throw std::runtime_error(message);
    }
  }

  vtkSmartPointer<vtkPolyData> bones() const {
    Eigen::Matrix3Xd x(3, boneLocal.cols());
    for (Eigen::Index i = 0; i < boneLocal.cols(); ++i)
      x.col(i) = posed.body[static_cast<std::size_t>(bonePointBody[static_cast<std::size_t>(i)])] *
                 Eigen::Vector3d(boneLocal.col(i));
    auto pd = vtkSmartPointer<vtkPolyData>::New();
    setPoints(pd, x);
    pd->SetVerts(boneVerts);
    pd->SetPolys(bonePolys);
    pd->GetCellData()->AddArray(boneBodyId);
    return pd;
  }

  vtkSmartPointer<vtkPolyData> muscles(const sim::Metrics& metrics) const {
    const sim::Elements& el = model.elements;
    const Eigen::Matrix3Xd& a = posed.elementA;
    const Eigen::Matrix3Xd& b = posed.elementB;
    Eigen::Matrix3Xd x(3, 2 * el.size());
    vtkNew<vtkCellArray> lines;
    auto force = scalarArray("force_N", 1, el.size());
    auto tension = scalarArray("tension_N", 1, el.size());
    vtkNew<vtkIntArray> group;
    group->SetName("group");
    vtkNew<vtkUnsignedCharArray> slack;
    slack->SetName("is_slack");
    vtkNew<vtkUnsignedCharArray> apposition;  // 1: an apposition spring, anchored beyond the rib face
    apposition->SetName("is_apposition");
    vtkNew<vtkUnsignedCharArray> gliding;  // 1: a gliding spring, its far end a virtual anchor off the bone
    gliding->SetName("is_gliding");
    for (int e = 0; e < el.size(); ++e) {
      x.col(2 * e) = a.col(e);
      x.col(2 * e + 1) = b.col(e);
      const vtkIdType ids[2] = {2 * e, 2 * e + 1};
      lines->InsertNextCell(2, ids);
      const double f = e < metrics.elementForce.size() ? metrics.elementForce(e) : 0.0;
      force->SetValue(e, f);
      tension->SetValue(e, f < 0.0 ? -f : 0.0);
      group->InsertNextValue(static_cast<int>(el.group[static_cast<std::size_t>(e)]));
      apposition->InsertNextValue(sim::isApposition(model, e) ? 1 : 0);
      gliding->InsertNextValue(el.glides(e) ? 1 : 0);
      slack->InsertNextValue(static_cast<std::size_t>(e) < metrics.isSlack.size()
                                 ? metrics.isSlack[static_cast<std::size_t>(e)]
                                 : 0);
    }
    auto pd = vtkSmartPointer<vtkPolyData>::New();
    setPoints(pd, x);
    pd->SetLines(lines);
    pd->GetCellData()->AddArray(force);
    pd->GetCellData()->AddArray(tension);
    pd->GetCellData()->AddArray(group);
    pd->GetCellData()->AddArray(apposition);
    pd->GetCellData()->AddArray(gliding);
    pd->GetCellData()->AddArray(slack);
    return pd;
  }

  vtkSmartPointer<vtkPolyData> gut(const sim::Metrics& metrics) const {
    auto pd = vtkSmartPointer<vtkPolyData>::New();
    setPoints(pd, posed.gut);
    pd->SetPolys(triangles(model.gut.triangles));
    auto disp = scalarArray("displacement_m", 3, posed.gut.cols());
    for (Eigen::Index i = 0; i < posed.gut.cols(); ++i) {
      const Eigen::Vector3d d = posed.gut.col(i) - model.nodes.rest.col(i);
      disp->SetTuple3(i, d.x(), d.y(), d.z());
    }
    pd->GetPointData()->AddArray(disp);
    fieldValue(pd, "pressure_Pa", metrics.gutPressure);
    fieldValue(pd, "volume_error", metrics.gutVolumeError);
    return pd;
  }

  vtkSmartPointer<vtkPolyData> cavity(const sim::Metrics& metrics) const {
    auto pd = vtkSmartPointer<vtkPolyData>::New();
    setPoints(pd, posed.cavity);
    pd->SetPolys(triangles(model.cavity.triangles));
    fieldValue(pd, "thoracic_cavity_volume_m3", metrics.thoracicCavityVolume);
    fieldValue(pd, "lung_volume_m3", metrics.lungVolume);
    return pd;
  }

  // both lungs in one polydata, the right lung's vertices and triangles first; cell data side: 0 right, 1
  // left
  vtkSmartPointer<vtkPolyData> lungs(const sim::Metrics& metrics) const {
    const sim::LungSurface& right = model.lungs.right;
    const sim::LungSurface& left = model.lungs.left;
    const Eigen::Matrix3Xd& xr = posed.lungRight;
    const Eigen::Matrix3Xd& xl = posed.lungLeft;
    Eigen::Matrix3Xd x(3, xr.cols() + xl.cols());
    x << xr, xl;
    Eigen::Matrix3Xi t(3, right.triangles.cols() + left.triangles.cols());
    t << right.triangles, (left.triangles.array() + right.vertexCount()).matrix();
    auto side = vtkSmartPointer<vtkIntArray>::New();
    side->SetName("side");
    for (Eigen::Index i = 0; i < t.cols(); ++i) side->InsertNextValue(i < right.triangles.cols() ? 0 : 1);
    auto pd = vtkSmartPointer<vtkPolyData>::New();
    setPoints(pd, x);
    pd->SetPolys(triangles(t));
    pd->GetCellData()->AddArray(side);
    fieldValue(pd, "right_lung_volume_m3", metrics.rightLungVolume);
    fieldValue(pd, "left_lung_volume_m3", metrics.leftLungVolume);
    fieldValue(pd, "lung_volume_m3", metrics.lungVolume);
    return pd;
  }

  // the volume bodies over all nodes (empty for a model without them); cell data body (index in
  // Model::volumes), point data displacement_m from the rest pose, field data volume_error per body
  vtkSmartPointer<vtkPolyData> tissue(const sim::Metrics& metrics) const {
    const sim::VolumeBodies& v = model.volumes;
    Eigen::Index count = 0;
    for (const Eigen::Matrix3Xi& t : v.triangles) count += t.cols();
    Eigen::Matrix3Xi t(3, count);
    auto body = vtkSmartPointer<vtkIntArray>::New();
    body->SetName("body");
    count = 0;
    for (int k = 0; k < v.size(); ++k) {
      const Eigen::Matrix3Xi& tk = v.triangles[static_cast<std::size_t>(k)];
      t.middleCols(count, tk.cols()) = tk;
      count += tk.cols();
      for (Eigen::Index i = 0; i < tk.cols(); ++i) body->InsertNextValue(k);
    }
    auto pd = vtkSmartPointer<vtkPolyData>::New();
    setPoints(pd, v.size() > 0 ? posed.gut : Eigen::Matrix3Xd(3, 0));
    pd->SetPolys(triangles(t));
    pd->GetCellData()->AddArray(body);
    if (v.size() > 0) {
      auto disp = scalarArray("displacement_m", 3, posed.gut.cols());
      for (Eigen::Index i = 0; i < posed.gut.cols(); ++i) {
        const Eigen::Vector3d d = posed.gut.col(i) - model.nodes.rest.col(i);
        disp->SetTuple3(i, d.x(), d.y(), d.z());
      }
      pd->GetPointData()->AddArray(disp);
    }
    auto error = scalarArray("volume_error", 1, metrics.volumeBodyError.size());
    for (Eigen::Index k = 0; k < metrics.volumeBodyError.size(); ++k)
      error->SetValue(k, metrics.volumeBodyError(k));
    pd->GetFieldData()->AddArray(error);
    return pd;
  }

  // the skin (empty for a model without one); point data displacement_m from the rest pose
  vtkSmartPointer<vtkPolyData> skin() const {
    auto pd = vtkSmartPointer<vtkPolyData>::New();
    setPoints(pd, posed.skin);
    pd->SetPolys(triangles(model.skin.triangles));
    auto disp = scalarArray("displacement_m", 3, posed.skin.cols());
    for (Eigen::Index i = 0; i < posed.skin.cols(); ++i) {
      const Eigen::Vector3d d = posed.skin.col(i) - skinRest.col(i);
      disp->SetTuple3(i, d.x(), d.y(), d.z());
    }
    pd->GetPointData()->AddArray(disp);
    return pd;
  }
};

VtkSeriesWriter::VtkSeriesWriter(const sim::Model& model, const std::string& modelDir,
                                 const std::string& outDir, const std::string& baseName, Staging staging)
    : m_impl(std::make_unique<Impl>(model, modelDir, outDir, baseName)) {
  // staged, the frames go to a folder of this process's own, renamed into place by finish()
  m_impl->isStaged = staging == Staging::TemporaryFolder;
  const std::string folder = (fs::path(outDir) / baseName).string();
  m_impl->frameDir = fs::path(m_impl->isStaged ? temporaryPathFor(folder) : folder);
  std::error_code ec;
  fs::create_directories(m_impl->frameDir, ec);
  if (ec) throw std::runtime_error("cannot create " + m_impl->frameDir.string() + ": " + ec.message());
}

VtkSeriesWriter::~VtkSeriesWriter() {
  if (m_impl->isFinished || !m_impl->isStaged) return;
  // unfinished (cancelled, failed): remove what this writer wrote, and its folder once empty
  std::error_code ec;
  for (const fs::path& f : m_impl->written) fs::remove(f, ec);
  fs::remove(m_impl->frameDir, ec);  // only when empty
}

std::size_t VtkSeriesWriter::frameBytes(const sim::Model& model, const std::string& modelDir,
                                        const sim::State& state, const sim::Metrics& metrics) {
  Impl impl(model, modelDir, "", "");
  sim::poseGeometry(model, state, impl.posed);
  std::size_t bytes = 0;
  for (const std::string& part : impl.encodeFrame(metrics)) bytes += part.size();
  return bytes;
}

void VtkSeriesWriter::writeFrame(const sim::State& state, const sim::Metrics& metrics) {
  const int frame = static_cast<int>(m_impl->frameTimes.size());
  sim::poseGeometry(m_impl->model, state, m_impl->posed);
  const std::array<std::string, kPartCount> parts = m_impl->encodeFrame(metrics);
  for (int part = 0; part < kPartCount; ++part)
    m_impl->write(parts[static_cast<std::size_t>(part)], part, frame);
  m_impl->frameTimes.push_back(state.time);
}

std::string VtkSeriesWriter::finish() {
  Impl& s = *m_impl;
  // the frames' folder into place: an earlier series of the same name is replaced, a folder holding anything
  // else is left alone and refused
  const fs::path target = fs::path(s.outDir) / s.baseName;
  std::error_code ec;
  if (s.isStaged && fs::exists(target, ec)) {
    for (const auto& entry : fs::directory_iterator(target, ec)) {
      const std::string name = entry.path().filename().string();
      if (!entry.is_regular_file() || !isPartFile(name))
        throw std::runtime_error("cannot write " + target.string() + ": the folder holds " + name +
                                 ", which is not a frame of a series; choose another name");
    }
    fs::remove_all(target, ec);
    if (ec) throw std::runtime_error("cannot replace " + target.string() + ": " + ec.message());
  }
  if (s.isStaged) fs::rename(s.frameDir, target, ec);
  if (ec)
    throw std::runtime_error("cannot rename " + s.frameDir.string() + " to " + target.string() + ": " +
                             ec.message());
  s.isFinished = true;

  std::ostringstream pvd;
  pvd.precision(9);
  pvd << "<?xml version=\"1.0\"?>\n<VTKFile type=\"Collection\" version=\"0.1\" "
         "byte_order=\"LittleEndian\">\n"
      << "  <Collection>\n";
  for (std::size_t f = 0; f < s.frameTimes.size(); ++f)
    for (int part = 0; part < kPartCount; ++part)
      pvd << "    <DataSet timestep=\"" << s.frameTimes[f] << "\" group=\"\" part=\"" << part << "\" name=\""
          << kPartNames[part] << "\" file=\"" << s.partPath(part, static_cast<int>(f)) << "\"/>\n";
  pvd << "  </Collection>\n</VTKFile>\n";
  const std::string name = s.baseName + ".pvd";
  writeFileAtomically((fs::path(s.outDir) / name).string(), pvd.str());
  return name;
}

int VtkSeriesWriter::frameCount() const { return static_cast<int>(m_impl->frameTimes.size()); }

std::size_t VtkSeriesWriter::bytesWritten() const { return m_impl->bytesWritten; }

}  // namespace pneuma::viz
