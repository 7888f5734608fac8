/// @file PneumaModule.cpp
/// The `pneuma` Python module (pybind11): the public pneuma::sim API for scripts (docs/python.md). It adds no
/// physics: models are loaded with sim::loadModel(), runs are sim::Simulation, controllers come from
/// sim::makeController() as in `pneuma-cli simulate`, and parameters change through sim::applyOverride(), the
/// scenario files' rule. Arrays are SI, as inside the simulator; the state's node and body positions are
/// numpy views of the simulation's own (3 x N) matrices, without a copy. The output files (summary.json,
/// timeseries.csv, the plots, a ParaView series) are written by the CLI's own writers (viz::RunRecord,
/// viz::runSummary(), viz::VtkSeriesWriter), so they are the same files as `pneuma-cli simulate` writes.

#include <pybind11/eigen.h>
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <algorithm>
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "pneuma/sim/Error.h"
#include "pneuma/sim/ModelIO.h"
#include "pneuma/sim/Resources.h"
#include "pneuma/sim/Scenario.h"
#include "pneuma/sim/Simulation.h"
#include "pneuma/sim/pattern/PatternController.h"
#include "viz/AtomicFile.h"
#include "viz/RunRecord.h"
#include "viz/RunSummary.h"
#include "viz/VtkSeriesWriter.h"

namespace py = pybind11;
namespace sim = pneuma::sim;

namespace {

/// The per-frame series a script reads back, one entry per output frame.
struct Frames {
  std::vector<double> time;            // [s]
  std::vector<double> lungVolume;      // [m^3]
  std::vector<double> abdomenVolume;   // [m^3]
  std::vector<double> gutVolumeError;  // [-]
  std::vector<double> target;          // [-] pattern target fraction (NaN without a pattern)
  std::vector<double> measured;        // [-] pattern measured fraction (NaN without a pattern)
  std::vector<double> alpha, r;        // [-] (frames x groups), row-major
};

py::array_t<double> toArray(const std::vector<double>& v) { return py::array_t<double>(v.size(), v.data()); }

/// A read-only numpy view (3, N) of a (3 x N) column-major matrix owned by `owner`, without a copy.
py::array_t<double> viewOf(const Eigen::Matrix3Xd& x, const py::object& owner) {
  py::array_t<double> a({py::ssize_t{3}, static_cast<py::ssize_t>(x.cols())},
                        {py::ssize_t{sizeof(double)}, py::ssize_t{3 * sizeof(double)}}, x.data(), owner);
  a.attr("flags").attr("writeable") = false;
  return a;
}

/// One simulation run driven from Python.
class PySimulation {
 public:
  PySimulation(std::shared_ptr<const sim::Model> model, std::string modelDir, sim::Scenario scenario)
      : m_model(std::move(model)), m_modelDir(std::move(modelDir)), m_scenario(std::move(scenario)) {
    std::unique_ptr<sim::Controller> controller =
        sim::makeController(m_scenario, m_model, sim::resourceDir());
    // the pattern controller stays reachable for push_affect() and the target/measured series
    m_pattern = dynamic_cast<sim::pattern::PatternController*>(controller.get());
    m_sim = std::make_unique<sim::Simulation>(m_model, std::move(controller), m_scenario.options);
  }

  void run(double seconds) {
    py::gil_scoped_release release;
    m_sim->advance(seconds, [this](const sim::Simulation& s) {
      record(s.latestMetrics());
      return true;
    });
  }

  void step(int count) {
    for (int i = 0; i < count; ++i) {
      const double before = m_sim->latestMetrics().time;
      m_sim->stepOnce();
      if (m_sim->latestMetrics().time != before) record(m_sim->latestMetrics());
    }
  }

  void set(const std::string& key, const py::object& value) {
    sim::SimulationOptions options = m_sim->options();
    const std::string text = py::isinstance<py::str>(value)
                                 ? value.cast<std::string>()
                                 : py::module_::import("json").attr("dumps")(value).cast<std::string>();
    sim::applyOverride(options, key, text, "set");
    m_sim->setOptions(options);
  }

  void pushAffect(const std::string& name, bool immediate) {
    const auto mode = immediate ? sim::pattern::SwitchMode::Immediate : sim::pattern::SwitchMode::EndOfCycle;
    if (m_pattern != nullptr) {
      m_pattern->push(sim::pattern::loadAffect(name, sim::resourceDir()).layers, mode);
      return;
    }
    // a breath style runs: calibrate the drive on this model and hand over to the affect (as the app does)
    py::gil_scoped_release release;
    const sim::pattern::DriveCalibration calibration =
        sim::pattern::calibrateDrive(m_model, m_sim->options());
    auto controller =
        sim::pattern::makeAffectController(name, sim::resourceDir(), m_scenario.seed, calibration);
    m_pattern = controller.get();
    m_sim->setController(std::move(controller));
  }

  void pushPattern(const std::string& path, bool immediate) {
    if (m_pattern == nullptr)
      throw sim::Error("push_pattern: no pattern plays; start with affect= or pattern=");
    m_pattern->push(sim::pattern::loadPatternFile(path, sim::resourceDir()).layers,
                    immediate ? sim::pattern::SwitchMode::Immediate : sim::pattern::SwitchMode::EndOfCycle);
  }

  void startOutputs(const std::string& directory, bool csv, bool plots, bool vtk) {
    if (directory.empty()) throw sim::Error("start_outputs: directory: must not be empty");
    std::filesystem::create_directories(directory);
    auto record = std::make_unique<pneuma::viz::RunRecord>(
        *m_model, m_sim->controller().tracksVolume(), csv ? directory + "/timeseries.csv" : std::string());
    m_vtk = vtk ? std::make_unique<pneuma::viz::VtkSeriesWriter>(*m_model, m_modelDir, directory, "frames")
                : nullptr;
    m_record = std::move(record);
    m_outDir = directory, m_hasCsv = csv, m_hasPlots = plots;
  }

  std::vector<std::string> writeOutputs() {
    if (!m_record) throw sim::Error("write_outputs: no outputs started; call start_outputs(directory) first");
    std::vector<std::string> files;
    if (m_hasCsv) {
      m_record->commitCsv();
      files.push_back("timeseries.csv");
    }
    if (m_hasPlots && m_record->size() > 0)
      for (const std::string& f : m_record->writePlots(m_outDir, m_scenario.name)) files.push_back(f);
    if (m_vtk) files.push_back(m_vtk->finish());
    // the run's duration is what ran after settling
    sim::Scenario ran = m_scenario;
    ran.duration = std::max(0.0, m_sim->state().time - m_sim->options().settleTime);
    const nlohmann::json summary = pneuma::viz::runSummary(
        *m_model, ran, m_sim.get(),
        {m_modelDir, m_sim->controller().describe(), false, "", m_record->size(), files});
    pneuma::viz::writeFileAtomically(m_outDir + "/summary.json", summary.dump(2) + "\n");
    m_record.reset();
    m_vtk.reset();
    files.insert(files.begin(), "summary.json");
    return files;
  }

  py::dict frames() const {
    py::dict d;
    d["time"] = toArray(m_frames.time);
    d["lung_volume"] = toArray(m_frames.lungVolume);
    d["abdomen_volume"] = toArray(m_frames.abdomenVolume);
    d["gut_volume_error"] = toArray(m_frames.gutVolumeError);
    d["target_fraction"] = toArray(m_frames.target);
    d["measured_fraction"] = toArray(m_frames.measured);
    const auto n = static_cast<py::ssize_t>(m_frames.time.size());
    d["alpha"] = py::array_t<double>({n, py::ssize_t{sim::kElementGroupCount}}, m_frames.alpha.data());
    d["r"] = py::array_t<double>({n, py::ssize_t{sim::kElementGroupCount}}, m_frames.r.data());
    return d;
  }

  py::dict metrics() const {
    const sim::Metrics& m = m_sim->latestMetrics();
    py::dict d;
    d["time"] = m.time;
    d["lung_volume"] = m.lungVolume;
    d["thoracic_cavity_volume"] = m.thoracicCavityVolume;
    d["right_lung_volume"] = m.rightLungVolume;
    d["left_lung_volume"] = m.leftLungVolume;
    d["gut_volume"] = m.gutVolume;
    d["gut_volume_error"] = m.gutVolumeError;
    d["gut_pressure"] = m.gutPressure;
    d["abdomen_volume"] = m.abdomenVolume;
    d["kinetic_energy"] = m.kineticEnergy;
    d["elastic_energy"] = m.elasticEnergy;
    d["gravity_energy"] = m.gravityEnergy;
    d["element_force"] = py::array_t<double>(m.elementForce.size(), m.elementForce.data());
    d["group_mean_tension"] = py::array_t<double>(m.groupMeanTension.size(), m.groupMeanTension.data());
    d["landmarks"] = py::array_t<double>({py::ssize_t{3}, static_cast<py::ssize_t>(m.landmarks.cols())},
                                         {py::ssize_t{sizeof(double)}, py::ssize_t{3 * sizeof(double)}},
                                         m.landmarks.data());  // a copy: the frame changes
    return d;
  }

  py::dict summary() const {
    const sim::Summary s = m_sim->summary();
    const sim::Motion& m = s.motion;
    py::dict d;
    d["tidal_volume"] = s.tidalVolume;
    d["breaths_per_minute"] = s.breathsPerMinute;
    d["end_expiratory_volume"] = s.endExpiratoryVolume;
    d["end_inspiratory_volume"] = s.endInspiratoryVolume;
    d["cycles"] = s.cycles;
    d["max_gut_volume_error"] = s.maxGutVolumeError;
    d["mean_gut_volume_error"] = s.meanGutVolumeError;
    d["dome_descent"] = m.domeDescent;
    d["dome_anterior"] = m.domeAnterior;
    d["sternum_anterior"] = m.sternumAnterior;
    d["sternum_cranial"] = m.sternumCranial;
    d["xiphoid_anterior"] = m.xiphoidAnterior;
    d["xiphoid_cranial"] = m.xiphoidCranial;
    d["lower_rib_expansion"] = m.lowerRibExpansion;
    d["umbilicus_anterior"] = m.umbilicusAnterior;
    d["rib_cage_tidal"] = m.ribCageTidal;
    d["abdomen_tidal"] = m.abdomenTidal;
    d["rib_cage_fraction"] = m.ribCageShare();
    d["rc_ab_phase"] = m.phaseAngle;
    d["tracking_rms_pct"] = m_sim->controller().trackingRmsPercent();
    d["real_time_factor"] = s.realTimeFactor;
    d["steps"] = s.steps;
    d["dt"] = s.dt;
    d["measured_from"] = s.measuredFrom;
    return d;
  }

  const sim::Simulation& simulation() const { return *m_sim; }

 private:
  void record(const sim::Metrics& m) {
    if (m_record) {
      if (m_sim->controller().tracksVolume())
        m_record->append(m, m_sim->controller().targetFraction(), m_sim->controller().measuredFraction());
      else
        m_record->append(m);
    }
    if (m_vtk) m_vtk->writeFrame(m_sim->state(), m);
    m_frames.time.push_back(m.time);
    m_frames.lungVolume.push_back(m.lungVolume);
    m_frames.abdomenVolume.push_back(m.abdomenVolume);
    m_frames.gutVolumeError.push_back(m.gutVolumeError);
    m_frames.target.push_back(m_sim->controller().targetFraction());
    m_frames.measured.push_back(m_sim->controller().measuredFraction());
    for (const sim::GroupActivation& g : m.activations) {
      m_frames.alpha.push_back(g.alpha);
      m_frames.r.push_back(g.r);
    }
  }

  std::shared_ptr<const sim::Model> m_model;
  std::string m_modelDir;  // for the ParaView series' body meshes
  sim::Scenario m_scenario;
  std::unique_ptr<sim::Simulation> m_sim;
  sim::pattern::PatternController* m_pattern = nullptr;  // owned by m_sim; null for a breath style
  Frames m_frames;
  // the output files being recorded (start_outputs() to write_outputs())
  std::unique_ptr<pneuma::viz::RunRecord> m_record;
  std::unique_ptr<pneuma::viz::VtkSeriesWriter> m_vtk;
  std::string m_outDir;
  bool m_hasCsv = false, m_hasPlots = false;
};

/// A scenario from keyword arguments (or a file), with `overrides` applied by the scenario files' rule.
sim::Scenario scenarioFrom(const std::string& file, const std::string& style, const std::string& affect,
                           const std::string& pattern, std::uint64_t seed, const py::object& dt,
                           const py::object& settleTime, double outputRate, const py::dict& overrides) {
  sim::Scenario s;
  if (!file.empty()) s = sim::loadScenario(file);
  const int given = !file.empty() + !style.empty() + !affect.empty() + !pattern.empty();
  if (given != 1) throw sim::Error("give exactly one of scenario=, style=, affect= or pattern=");
  if (!style.empty()) s.controller = sim::ControllerKind::Style, s.controllerName = style;
  if (!affect.empty()) s.controller = sim::ControllerKind::Affect, s.controllerName = affect;
  if (!pattern.empty()) s.controller = sim::ControllerKind::Pattern, s.controllerName = pattern;
  if (file.empty()) {
    s.seed = seed;
    s.options.outputRate = outputRate;
  }
  if (!dt.is_none()) sim::applyOverride(s.options, "dt_s", py::str(dt).cast<std::string>(), "dt");
  if (!settleTime.is_none())
    sim::applyOverride(s.options, "settle_time_s", py::str(settleTime).cast<std::string>(), "settle_time");
  for (const auto& [key, value] : overrides) {
    const std::string text = py::isinstance<py::str>(value)
                                 ? value.cast<std::string>()
                                 : py::module_::import("json").attr("dumps")(value).cast<std::string>();
    sim::applyOverride(s.options, key.cast<std::string>(), text, "overrides");
  }
  // named as pneuma-cli simulate names a run without a scenario name (summary.json's "scenario", plot titles)
  if (s.name.empty())
    s.name = s.controllerName.empty() ? "run" : std::filesystem::path(s.controllerName).stem().string();
  s.options.recordSeconds = sim::kTraceOnlyRecordSeconds;
  return s;
}

}  // namespace

PYBIND11_MODULE(pneuma, m) {
  m.doc() =
      "Pneuma: breathing simulation after Zordan et al. 2004 and de Melo et al. 2010 (docs/python.md). "
      "Every quantity is SI: volumes in m^3, lengths in m, times in s, forces in N.";
  py::register_exception<sim::Error>(m, "Error", PyExc_ValueError);

  py::class_<sim::Model, std::shared_ptr<sim::Model>>(
      m, "Model", py::dynamic_attr(),
      "An immutable torso model (docs/model-format.md); `directory` is where load_model() read it.")
      .def_readonly("name", &sim::Model::name, "model name")
      .def_property_readonly(
          "body_count", [](const sim::Model& mo) { return mo.bodies.mass.size(); }, "rigid bodies [-]")
      .def_property_readonly(
          "node_count", [](const sim::Model& mo) { return mo.nodes.size(); }, "gut nodes [-]")
      .def_property_readonly(
          "element_count", [](const sim::Model& mo) { return mo.elements.restLength.size(); },
          "spring elements [-]");

  m.def(
      "load_model",
      [](const std::string& dir) {
        const std::string path = dir.empty() ? sim::defaultModelDir() : dir;
        py::object model = py::cast(std::make_shared<sim::Model>(sim::loadModel(path)));
        model.attr("directory") = path;  // for the ParaView series' body meshes (start_outputs(vtk=True))
        return model;
      },
      py::arg("directory") = "",
      "Loads a model directory (model.json); the default model when `directory` is empty "
      "($PNEUMA_MODEL_DIR, else share/pneuma/models/default beside the module).");
  m.def("resource_dir", &sim::resourceDir, "The resource folder (presets, patterns, scenarios).");
  m.def("override_keys", &sim::overrideKeys, "The keys Simulation.set() and overrides= accept.");

  py::class_<PySimulation>(m, "Simulation", "One run: the model, its state, a controller and the options.")
      .def(
          py::init([](const py::object& model, const std::string& scenario, const std::string& style,
                      const std::string& affect, const std::string& pattern, std::uint64_t seed,
                      const py::object& dt, const py::object& settleTime, double outputRate,
                      const py::dict& overrides) {
            return std::make_unique<PySimulation>(
                model.cast<std::shared_ptr<sim::Model>>(),
                py::hasattr(model, "directory") ? model.attr("directory").cast<std::string>() : std::string(),
                scenarioFrom(scenario, style, affect, pattern, seed, dt, settleTime, outputRate, overrides));
          }),
          py::arg("model"), py::kw_only(), py::arg("scenario") = "", py::arg("style") = "",
          py::arg("affect") = "", py::arg("pattern") = "", py::arg("seed") = 0, py::arg("dt") = py::none(),
          py::arg("settle_time") = py::none(), py::arg("output_rate") = 60.0,
          py::arg("overrides") = py::dict(),
          "Makes a run from a scenario file (`scenario=`) or from keyword arguments: one of `style` (calm, "
          "deep, "
          "panting, forced-exhale), `affect` (de Melo's presets) or `pattern` (a pattern file); `seed`; "
          "`dt` [s] "
          "time step (default: the integrator's, 10 ms for patterns); `settle_time` [s] settling before the "
          "controller starts (default 2); `output_rate` [Hz] frames per simulated second (default 60); "
          "`overrides`: {key: value} as a scenario's overrides (see override_keys()). An affect or pattern "
          "calibrates its muscle drive on the model first (a few simulated seconds).")
      .def("run", &PySimulation::run, py::arg("seconds"),
           "Advances `seconds` [s] of simulated time, recording every output frame.")
      .def("step", &PySimulation::step, py::arg("count") = 1, "Takes `count` steps of dt.")
      .def("set", &PySimulation::set, py::arg("key"), py::arg("value"),
           "Changes one override between steps, by the scenario files' rule: "
           "set('active_gain_scale.diaphragm', "
           "1.2), set('posture', 'supine'), set('dt_s', 0.005) [s]. Raises pneuma.Error naming the key.")
      .def("push_affect", &PySimulation::pushAffect, py::arg("name"), py::arg("immediate") = false,
           "Plays an affect preset next (at the end of the current breath, or at once with immediate=True); "
           "under a breath style the drive is calibrated first and the affect takes over.")
      .def("push_pattern", &PySimulation::pushPattern, py::arg("path"), py::arg("immediate") = false,
           "Plays the layers of a pattern file next (the run must already play an affect or pattern).")
      .def_property_readonly(
          "time", [](const PySimulation& p) { return p.simulation().state().time; },
          "[s] simulated time (0 = start of settling)")
      .def_property_readonly(
          "dt", [](const PySimulation& p) { return p.simulation().dt(); }, "[s] time step in use")
      .def_property_readonly(
          "settle_time", [](const PySimulation& p) { return p.simulation().options().settleTime; },
          "[s] settling phase before the controller starts")
      .def_property_readonly(
          "controller", [](const PySimulation& p) { return p.simulation().controller().describe(); },
          "what drives the muscles, in words")
      .def_property_readonly(
          "node_positions",
          [](py::object self) {
            return viewOf(self.cast<const PySimulation&>().simulation().state().nodePosition, self);
          },
          "[m] gut node positions, world RAS, (3, #N): a read-only view of the state, valid until the next "
          "step")
      .def_property_readonly(
          "body_positions",
          [](py::object self) {
            return viewOf(self.cast<const PySimulation&>().simulation().state().bodyPosition, self);
          },
          "[m] rigid bodies' centres of mass, world RAS, (3, #B): a read-only view of the state")
      .def("frames", &PySimulation::frames,
           "Every output frame so far as numpy arrays: time [s], lung_volume [m^3], abdomen_volume [m^3], "
           "gut_volume_error [-], target_fraction and measured_fraction [-] (NaN without a pattern), alpha "
           "and "
           "r [-] (frames x 6 groups: intercostal_external, intercostal_internal, diaphragm, rectus, "
           "transversus_obliques, cartilage).")
      .def("start_outputs", &PySimulation::startOutputs, py::arg("directory"), py::kw_only(),
           py::arg("csv") = true, py::arg("plots") = true, py::arg("vtk") = false,
           "Records every output frame from now on into `directory` (created if missing), as `pneuma-cli "
           "simulate --out` does: timeseries.csv (`csv`, the CLI's columns and units: mL, mm, %), the PNG "
           "and SVG "
           "plots (`plots`) and a ParaView series frames.pvd + frames/ (`vtk`; body meshes from the model's "
           "directory). Nothing is final until write_outputs().")
      .def("write_outputs", &PySimulation::writeOutputs,
           "Writes what start_outputs() recorded and summary.json (the CLI's keys and units; duration_s is "
           "the "
           "time run after settling), each through a temporary file and a rename; returns the file names "
           "written, summary.json first.")
      .def("metrics", &PySimulation::metrics,
           "The latest output frame: volumes [m^3], gut_pressure [Pa], energies [J], element_force [N] (#E), "
           "group_mean_tension [N] (6), landmarks [m] (3, #L).")
      .def(
          "summary", &PySimulation::summary,
          "Figures measured after settling (SI: tidal_volume [m^3], breaths_per_minute [1/min], dome_descent "
          "[m], rc_ab_phase [rad], ...), as summary.json gives them in mL and mm.");
}
