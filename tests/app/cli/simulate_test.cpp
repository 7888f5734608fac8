// pneuma-cli simulate: outputs, their units and values, interruption and bad input.
#include <vtkCellData.h>
#include <vtkDataArray.h>
#include <vtkNew.h>
#include <vtkPolyData.h>
#include <vtkXMLPolyDataReader.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>

#include "CliRunner.h"
#include "ToyModelDir.h"

using pneuma::test::freshOutDir;
using pneuma::test::runCli;
using pneuma::test::runReplacingEarlierRun;
using pneuma::test::slurp;
using pneuma::test::toyModelDir;
namespace fs = std::filesystem;

namespace {

std::vector<std::string> splitCsvLine(const std::string& line) {
  std::vector<std::string> out;
  std::stringstream ss(line);
  std::string cell;
  while (std::getline(ss, cell, ',')) out.push_back(cell);
  return out;
}

void expectPng(const std::string& path) {
  const std::string png = slurp(path);
  ASSERT_GT(png.size(), 24u) << path;
  EXPECT_EQ(png.substr(0, 8), std::string("\x89PNG\r\n\x1a\n", 8)) << path;
  // IHDR width and height, big-endian
  auto be32 = [&](std::size_t at) {
    return (static_cast<unsigned char>(png[at]) << 24) | (static_cast<unsigned char>(png[at + 1]) << 16) |
           (static_cast<unsigned char>(png[at + 2]) << 8) | static_cast<unsigned char>(png[at + 3]);
  };
  EXPECT_EQ(be32(16), 960) << path;
  EXPECT_EQ(be32(20), 540) << path;
}

}  // namespace

TEST(CliSimulate, CalmStyleWritesSummaryCsvAndPlotsWithUnits) {
  const std::string out = freshOutDir("calm");
  // dt pinned: the toy torso is uncalibrated and these tests are about the outputs, not its physics
  auto r = runCli({"simulate", "--model", toyModelDir(), "--style", "calm", "--duration", "8", "--settle",
                   "1", "--output-rate", "30", "--dt", "0.002", "--out", out});
  ASSERT_EQ(r.exitCode, 0) << r.err << r.out;

  // summary.json: every documented field, consistent values
  const nlohmann::json s = nlohmann::json::parse(slurp(out + "/summary.json"));
  for (const char* key : {"tidal_volume_ml",
                          "breaths_per_minute",
                          "end_expiratory_volume_ml",
                          "max_gut_volume_error_pct",
                          "mean_gut_volume_error_pct",
                          "dome_descent_mm",
                          "xiphoid_anterior_mm",
                          "lower_rib_expansion_mm",
                          "umbilicus_anterior_mm",
                          "rib_cage_tidal_ml",
                          "abdomen_tidal_ml",
                          "rc_ab_phase_deg",
                          "real_time_factor",
                          "dt_s",
                          "steps",
                          "integrator",
                          "posture",
                          "model",
                          "controller",
                          "pneuma_version",
                          "partial",
                          "tracking_rms_pct"})
    EXPECT_TRUE(s.contains(key)) << key;
  EXPECT_FALSE(s["partial"].get<bool>());
  EXPECT_EQ(s["pneuma_version"], PNEUMA_VERSION);
  EXPECT_EQ(s["integrator"], "implicit-euler-joints");
  EXPECT_EQ(s["posture"], "upright");
  EXPECT_TRUE(s["tracking_rms_pct"].is_null());  // no volume target for a breath style
  EXPECT_GT(s["tidal_volume_ml"].get<double>(), 0.0);
  EXPECT_GE(s["breaths_per_minute"].get<double>(), 0.0);
  EXPECT_GE(s["max_gut_volume_error_pct"].get<double>(), s["mean_gut_volume_error_pct"].get<double>());
  EXPECT_GT(s["real_time_factor"].get<double>(), 0.0);
  // steps = simulated time / dt (settling included)
  EXPECT_NEAR(s["steps"].get<double>() * s["dt_s"].get<double>(), 9.0, 2.0 * s["dt_s"].get<double>());

  // timeseries.csv: a header of "name [unit]" columns, one row per frame, numbers in every cell
  std::ifstream csv(out + "/timeseries.csv");
  std::string line;
  ASSERT_TRUE(std::getline(csv, line));
  const auto header = splitCsvLine(line);
  EXPECT_EQ(header.at(0), "time [s]");
  EXPECT_EQ(header.at(1), "lung_volume [mL]");
  EXPECT_EQ(header.at(2), "gut_volume_error [%]");
  for (const std::string& h : header) EXPECT_NE(h.find(" ["), std::string::npos) << "no unit: " << h;
  for (const char* col :
       {"diaphragm.r [-]", "diaphragm.alpha [-]", "diaphragm.mean_tension [N]", "xiphoid.z [mm]"})
    EXPECT_NE(std::find(header.begin(), header.end(), col), header.end()) << col;
  // the summary's figures follow from the CSV's columns in their units (mL, %, mm), from the end of settling
  // on
  auto column = [&](const std::string& name) {
    return static_cast<std::size_t>(std::find(header.begin(), header.end(), name) - header.begin());
  };
  const std::size_t xi = column("xiphoid.x [mm]");
  const double from = s["measured_from_s"].get<double>();
  double vMin = 1e300, vMax = -1e300, gutMax = 0.0, lastTime = -1.0;
  Eigen::Vector3d xMin = Eigen::Vector3d::Constant(1e300), xMax = -xMin;
  int rows = 0;
  while (std::getline(csv, line)) {
    const auto cells = splitCsvLine(line);
    ASSERT_EQ(cells.size(), header.size()) << line;
    const double t = std::stod(cells[0]);
    EXPECT_GT(t, lastTime);
    lastTime = t;
    ++rows;
    if (t < from) continue;
    vMin = std::min(vMin, std::stod(cells[1]));
    vMax = std::max(vMax, std::stod(cells[1]));
    gutMax = std::max(gutMax, std::abs(std::stod(cells[2])));
    for (int k = 0; k < 3; ++k) {
      xMin(k) = std::min(xMin(k), std::stod(cells[xi + static_cast<std::size_t>(k)]));
      xMax(k) = std::max(xMax(k), std::stod(cells[xi + static_cast<std::size_t>(k)]));
    }
  }
  EXPECT_NEAR(rows, 9 * 30, 3);
  const double tol = 1e-6 * vMax;  // the CSV holds 9 significant digits
  EXPECT_LE(s["tidal_volume_ml"].get<double>(), vMax - vMin + tol);
  EXPECT_GE(s["end_expiratory_volume_ml"].get<double>(), vMin - tol);
  EXPECT_LE(s["end_expiratory_volume_ml"].get<double>(), vMax + tol);
  EXPECT_NEAR(s["max_gut_volume_error_pct"].get<double>(), gutMax, 1e-6 * std::max(1.0, gutMax));
  // the xiphoid's end-inspiratory minus end-expiratory anterior motion lies within its anteroposterior range
  EXPECT_LE(std::abs(s["xiphoid_anterior_mm"].get<double>()), xMax(1) - xMin(1) + 1e-6);

  // plots: PNG decodes (signature, 960 x 540), SVG is an svg document
  for (const char* stem : {"lung_volume", "gut_volume_error", "activations", "tensions"}) {
    expectPng(out + "/" + stem + ".png");
    const std::string svg = slurp(out + "/" + stem + ".svg");
    EXPECT_NE(svg.find("<svg"), std::string::npos) << stem;
    EXPECT_NE(svg.find("</svg>"), std::string::npos) << stem;
    EXPECT_NE(svg.find("time [s]"), std::string::npos) << stem;
  }
  // no temporary files left behind
  for (const auto& e : fs::directory_iterator(out))
    EXPECT_EQ(e.path().string().find(".tmp-"), std::string::npos) << e.path();
}

TEST(CliSimulate, SameSeedAndInputsGiveIdenticalCsv) {
  const std::string a = freshOutDir("det_a"), b = freshOutDir("det_b");
  for (const std::string& out : {a, b}) {
    auto r = runCli({"simulate", "--model", toyModelDir(), "--style", "deep", "--duration", "2", "--settle",
                     "0.5", "--dt", "0.002", "--out", out});
    ASSERT_EQ(r.exitCode, 0) << r.err;
  }
  EXPECT_EQ(slurp(a + "/timeseries.csv"), slurp(b + "/timeseries.csv"));
}

TEST(CliSimulate, VtkSeriesListsFivePartsPerFrame) {
  const std::string out = freshOutDir("vtk");
  auto r = runCli({"simulate", "--model", toyModelDir(), "--style", "calm", "--duration", "0.5", "--settle",
                   "0", "--output-rate", "10", "--dt", "0.002", "--vtk", "--out", out});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const std::string pvd = slurp(out + "/frames.pvd");
  EXPECT_NE(pvd.find("type=\"Collection\""), std::string::npos);
  std::size_t n = 0;
  for (std::size_t p = 0; (p = pvd.find("<DataSet", p)) != std::string::npos; ++p) ++n;
  EXPECT_EQ(n % 5, 0u);
  EXPECT_GE(n, 5u * 5u);
  EXPECT_NE(pvd.find("name=\"lungs\""), std::string::npos);
  // the muscles part reads back as polydata: one line per element with its force, tension = max(0, -force)
  vtkNew<vtkXMLPolyDataReader> reader;
  reader->SetFileName((out + "/frames/muscles_000003.vtp").c_str());
  reader->Update();
  vtkPolyData* muscles = reader->GetOutput();
  const auto toy = pneuma::sim::test::makeToyTorso();
  ASSERT_EQ(muscles->GetNumberOfLines(), toy.elements.size());
  vtkDataArray* force = muscles->GetCellData()->GetArray("force_N");
  vtkDataArray* tension = muscles->GetCellData()->GetArray("tension_N");
  ASSERT_NE(force, nullptr);
  ASSERT_NE(tension, nullptr);
  int taut = 0;
  for (vtkIdType c = 0; c < force->GetNumberOfTuples(); ++c) {
    EXPECT_DOUBLE_EQ(tension->GetTuple1(c), std::max(0.0, -force->GetTuple1(c)));
    taut += force->GetTuple1(c) < 0.0;
  }
  EXPECT_GT(taut, 0);
  // the gut part has the model's triangles
  reader->SetFileName((out + "/frames/gut_000003.vtp").c_str());
  reader->Update();
  EXPECT_EQ(reader->GetOutput()->GetNumberOfPolys(), toy.gut.triangles.cols());
}

// --vtk-from, --vtk-to and --vtk-stride keep one output frame in N over a stretch of the run, the count and
// size said before the run; a bad stride or one without --vtk is refused by name
TEST(CliSimulate, VtkSeriesOverARangeWithAStride) {
  const std::string out = freshOutDir("vtk_range");
  auto r = runCli({"simulate",   "--model", toyModelDir(),   "--style", "calm",         "--duration", "1.5",
                   "--settle",   "0.5",     "--output-rate", "20",      "--dt",         "0.002",      "--vtk",
                   "--vtk-from", "1",       "--vtk-to",      "1.6",     "--vtk-stride", "3",          "--out",
                   out});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  // 1 s to 1.6 s at 20 Hz is 13 output frames; one in three: 1.0, 1.15, 1.3, 1.45, 1.6 s
  EXPECT_NE(
      r.out.find("ParaView series: 5 frames (one in 3 of the 20 output frames per second, 1 s to 1.6 s)"),
      std::string::npos)
      << r.out;
  const std::string pvd = slurp(out + "/frames.pvd");
  // the size said after the first frame is the size written, within 10 % (frames differ a little)
  const std::size_t about = r.out.find("ParaView series: about ");
  ASSERT_NE(about, std::string::npos) << r.out;
  double written = 0.0;  // [bytes]
  for (const auto& e : fs::directory_iterator(out + "/frames")) written += static_cast<double>(e.file_size());
  EXPECT_NEAR(std::stod(r.out.substr(about + 23)) * 1e6, written, 0.1 * written + 0.05e6) << r.out;
  std::vector<double> times;
  for (std::size_t p = 0; (p = pvd.find("timestep=\"", p)) != std::string::npos; p += 10)
    if (pvd.compare(pvd.find("part=\"", p), 8, "part=\"0\"") == 0)
      times.push_back(std::stod(pvd.substr(p + 10)));
  ASSERT_EQ(times.size(), 5u) << pvd;
  for (std::size_t k = 0; k < times.size(); ++k)
    EXPECT_NEAR(times[k], 1.0 + 0.15 * static_cast<double>(k), 1e-6);
  EXPECT_EQ(std::distance(fs::directory_iterator(out + "/frames"), fs::directory_iterator{}), 5 * 7)
      << "five frames of seven parts (VtkSeriesWriter.h)";
  for (const auto& e : fs::directory_iterator(out))
    EXPECT_EQ(e.path().filename().string().find(".tmp-"), std::string::npos) << e.path();

  const auto zero = runCli({"simulate", "--model", toyModelDir(), "--style", "calm", "--duration", "1",
                            "--vtk", "--vtk-stride", "0", "--out", freshOutDir("vtk_stride0")});
  EXPECT_EQ(zero.exitCode, 2);
  EXPECT_NE(zero.err.find("--vtk-stride: expected a whole number >= 1, got 0"), std::string::npos)
      << zero.err;
  const auto alone = runCli({"simulate", "--model", toyModelDir(), "--style", "calm", "--duration", "1",
                             "--vtk-stride", "2", "--out", freshOutDir("vtk_alone")});
  EXPECT_EQ(alone.exitCode, 2);
  EXPECT_NE(alone.err.find("--vtk"), std::string::npos) << alone.err;
}

TEST(CliSimulate, AffectAddsTargetAndMeasuredVolumeFraction) {
  const std::string out = freshOutDir("affect");
  auto r = runCli({"simulate", "--model", toyModelDir(), "--affect", "neutral", "--duration", "4", "--settle",
                   "1", "--output-rate", "20", "--dt", "0.002", "--out", out});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const nlohmann::json s = nlohmann::json::parse(slurp(out + "/summary.json"));
  EXPECT_EQ(s["controller_kind"], "affect");
  ASSERT_TRUE(s["tracking_rms_pct"].is_number());
  EXPECT_GE(s["tracking_rms_pct"].get<double>(), 0.0);
  std::ifstream csv(out + "/timeseries.csv");
  std::string header;
  std::getline(csv, header);
  EXPECT_NE(header.find("target_volume_fraction [-],measured_volume_fraction [-]"), std::string::npos);
  // the neutral pattern breathes between 5 and 25 % of the volume range
  double lo = 1.0, hi = 0.0;
  for (std::string line; std::getline(csv, line);) {
    const auto cells = splitCsvLine(line);
    if (std::stod(cells[0]) < 2.0) continue;
    lo = std::min(lo, std::stod(cells[cells.size() - 2]));
    hi = std::max(hi, std::stod(cells[cells.size() - 2]));
  }
  EXPECT_NEAR(lo, 0.05, 0.03);
  EXPECT_NEAR(hi, 0.25, 0.05);
  expectPng(out + "/volume_fraction.png");
}

TEST(CliSimulate, ScenarioFileRunsAndCommandLineOverridesIt) {
  const std::string out = freshOutDir("scenario");
  const std::string inputs = freshOutDir("scenario_inputs");
  fs::create_directories(inputs);
  const std::string file = inputs + "/run.json";
  std::ofstream(file) << R"({"format": "pneuma-scenario", "version": 1, "name": "deep-short", "model": ")"
                      << toyModelDir() << R"(", "duration_s": 30, "controller": {"style": "deep"},
      "overrides": {"settle_time_s": 0.5, "posture": "supine"}, "outputs": {"output_rate_hz": 10, "plots": false}})";
  auto r = runCli({"simulate", "--scenario", file, "--duration", "2", "--out", out});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  nlohmann::json s = nlohmann::json::parse(slurp(out + "/summary.json"));
  EXPECT_EQ(s["scenario"], "deep-short");
  EXPECT_EQ(s["posture"], "supine");
  EXPECT_EQ(s["duration_s"].get<double>(), 2.0);  // the command line wins
  EXPECT_NEAR(s["simulated_time_s"].get<double>(), 2.5, 1e-6);
  EXPECT_EQ(s["frames"].get<int>(), 25);
  EXPECT_FALSE(fs::exists(out + "/lung_volume.png"));  // plots off in the scenario
  r = runCli(
      {"simulate", "--scenario", file, "--duration", "0.5", "--posture", "upright", "--force", "--out", out});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  s = nlohmann::json::parse(slurp(out + "/summary.json"));
  EXPECT_EQ(s["posture"], "upright");  // the command line wins

  // a bad scenario names the file and the JSON path, exit 2
  std::ofstream(file)
      << R"({"format": "pneuma-scenario", "version": 1, "duration_s": 3, "controller": {"style": "deep"},
      "overrides": {"dt_s": -1}})";
  r = runCli({"simulate", "--scenario", file, "--out", out});
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_NE(r.err.find("run.json: overrides.dt_s: must be in [1e-06, 0.05] s, got -1"), std::string::npos)
      << r.err;
}

TEST(CliSimulate, SigintWritesValidPartialSummary) {
  const std::string out = freshOutDir("sigint");
  auto r = runCli(
      {"simulate", "--model", toyModelDir(), "--style", "calm", "--duration", "3000", "--out", out}, 1.5);
  EXPECT_EQ(r.exitCode, 130) << r.err;
  const nlohmann::json s = nlohmann::json::parse(slurp(out + "/summary.json"));
  EXPECT_TRUE(s["partial"].get<bool>());
  EXPECT_TRUE(s["interrupted"].get<bool>());
  EXPECT_GT(s["simulated_time_s"].get<double>(), 0.0);
  EXPECT_LT(s["simulated_time_s"].get<double>(), 3000.0);
  EXPECT_GT(s["steps"].get<long long>(), 0);
  EXPECT_TRUE(fs::exists(out + "/timeseries.csv"));
  EXPECT_TRUE(fs::exists(out + "/lung_volume.png"));
}

// data loss: a second run into the same --out keeps the first run's results unless --force is given
TEST(CliSimulate, EarlierRunIsReplacedOnlyWithForce) {
  const std::string out = freshOutDir("again");
  const std::vector<std::string> run = {
      "simulate", "--model", toyModelDir(),   "--style", "calm",  "--duration", "0.5",
      "--settle", "0",       "--output-rate", "10",      "--out", out};
  ASSERT_EQ(runCli(run).exitCode, 0);
  std::vector<std::string> again = run;
  again[6] = "1";  // a different run
  const auto r = runReplacingEarlierRun(again, out, "summary.json");
  ASSERT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(nlohmann::json::parse(slurp(out + "/summary.json"))["duration_s"].get<double>(), 1.0);
}

// data loss: an --out that holds files simulate does not write is refused, even with --force, and left as it
// was
TEST(CliSimulate, FolderOfOtherFilesIsRefused) {
  const std::string out = freshOutDir("foreign");
  fs::create_directories(out);
  std::ofstream(out + "/thesis.tex") << "chapter 1";
  for (const bool force : {false, true}) {
    std::vector<std::string> run = {"simulate", "--model",  toyModelDir(), "--style", "calm", "--duration",
                                    "0.5",      "--settle", "0",           "--out",   out};
    if (force) run.push_back("--force");
    const auto r = runCli(run);
    EXPECT_EQ(r.exitCode, 2) << r.err;
    EXPECT_NE(r.err.find("holds 'thesis.tex', which pneuma-cli simulate does not write"), std::string::npos)
        << r.err;
    EXPECT_EQ(pneuma::test::lineCount(r.err), 1) << r.err;
    EXPECT_EQ(slurp(out + "/thesis.tex"), "chapter 1");
    EXPECT_EQ(std::distance(fs::directory_iterator(out), fs::directory_iterator()), 1);
  }
}

// messages: a run too short for a full breath reports its breath figures as null, not as 0 or as the range of
// a fraction of a breath
TEST(CliSimulate, NoFullBreathGivesNullBreathFigures) {
  const std::string out = freshOutDir("nobreath");
  const auto r = runCli({"simulate", "--model", toyModelDir(), "--style", "calm", "--duration", "0.5",
                         "--settle", "0", "--output-rate", "20", "--out", out});
  ASSERT_EQ(r.exitCode, 0) << r.err;
  const nlohmann::json s = nlohmann::json::parse(slurp(out + "/summary.json"));
  EXPECT_EQ(s["cycles"].get<int>(), 0);
  for (const char* key : {"tidal_volume_ml", "breaths_per_minute", "end_expiratory_volume_ml",
                          "end_inspiratory_volume_ml", "dome_descent_mm", "rib_cage_fraction"})
    EXPECT_TRUE(s[key].is_null()) << key << " = " << s[key];
  EXPECT_TRUE(s["max_gut_volume_error_pct"].is_number());  // measured whether or not it breathed
  EXPECT_NE(r.out.find("no full breath found"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("breaths/min"), std::string::npos) << r.out;
}

// integers do not wrap: --seed -1 is not 2^64 - 1
TEST(CliSimulate, NegativeOrOverflowingSeedIsRejected) {
  for (const char* seed : {"-1", "18446744073709551616", "1.5"}) {
    const std::string out = freshOutDir("seed");
    auto r = runCli({"simulate", "--model", toyModelDir(), "--style", "calm", "--duration", "0.5", "--seed",
                     seed, "--out", out});
    EXPECT_EQ(r.exitCode, 2) << seed;
    EXPECT_NE(r.err.find(std::string("--seed: must be an integer in [0, 18446744073709551615], got ") + seed),
              std::string::npos)
        << r.err;
    EXPECT_FALSE(fs::exists(out + "/summary.json"));
  }
}

TEST(CliSimulate, UnknownStyleListsValidNames) {
  auto r = runCli({"simulate", "--model", toyModelDir(), "--style", "yodel", "--duration", "1", "--out",
                   freshOutDir("bad")});
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_NE(r.err.find("yodel"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("calm"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("panting"), std::string::npos) << r.err;
  EXPECT_EQ(pneuma::test::lineCount(r.err), 1) << r.err;
}

TEST(CliSimulate, UnknownAffectListsValidNames) {
  auto r = runCli({"simulate", "--model", toyModelDir(), "--affect", "ennui", "--duration", "1", "--out",
                   freshOutDir("bad")});
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_NE(r.err.find("ennui"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("startle"), std::string::npos) << r.err;
}

TEST(CliSimulate, BadInputIsOneLineErrorAndExit2) {
  struct Case {
    std::vector<std::string> args;
    std::string mentions;
  };
  const std::string out = freshOutDir("bad");
  const std::vector<Case> cases = {
      {{"--model", "/nonexistent/model", "--style", "calm", "--duration", "1", "--out", out},
       "/nonexistent/model"},
      {{"--model", toyModelDir(), "--style", "calm", "--duration", "0", "--out", out}, "--duration"},
      {{"--model", toyModelDir(), "--style", "calm", "--duration", "-3", "--out", out}, "--duration"},
      {{"--model", toyModelDir(), "--style", "calm", "--duration", "1", "--out", "/proc/pneuma-cannot-write"},
       "--out"},
      {{"--model", toyModelDir(), "--duration", "1", "--out", out}, "--style"},
      {{"--model", toyModelDir(), "--style", "calm", "--duration", "1", "--dt", "-1", "--out", out}, "--dt"},
      {{"--model", toyModelDir(), "--style", "calm", "--duration", "1", "--integrator", "rk4", "--out", out},
       "rk4"},
      {{"--model", toyModelDir(), "--style", "calm", "--duration", "1", "--posture", "sitting", "--out", out},
       "--posture: unknown posture 'sitting' (valid: upright, supine, prone, left-lateral, right-lateral)"},
      // inputs that would never finish (issue 15, class 5): refused at once, naming the option and the value
      {{"--model", toyModelDir(), "--style", "calm", "--duration", "1", "--dt", "1e-300", "--out", out},
       "--dt: must be in [1e-06, 0.05] s, got 1e-300"},
      {{"--model", toyModelDir(), "--style", "calm", "--duration", "1e308", "--out", out},
       "--duration: must be in [0.001, 86400] s, got 1e+308"},
      {{"--model", toyModelDir(), "--style", "calm", "--duration", "1", "--settle", "1e9", "--out", out},
       "--settle: must be in [0, 600] s, got 1e+09"},
      {{"--model", toyModelDir(), "--style", "calm", "--duration", "1", "--output-rate", "1e12", "--out",
        out},
       "--output-rate: must be in [0.01, 10000] Hz, got 1e+12"},
      {{"--model", toyModelDir(), "--style", "calm", "--duration", "86400", "--dt", "1e-6", "--out", out},
       "--duration: 86402 s at dt 1e-06 s needs more than the 1e+09 steps a run may take"},
  };
  for (const Case& c : cases) {
    std::vector<std::string> args{"simulate"};
    args.insert(args.end(), c.args.begin(), c.args.end());
    auto r = runCli(args);
    EXPECT_EQ(r.exitCode, 2) << c.mentions << ": " << r.err;
    EXPECT_EQ(r.err.rfind("pneuma-cli: error: ", 0), 0u) << r.err;
    EXPECT_NE(r.err.find(c.mentions), std::string::npos) << r.err;
    EXPECT_EQ(pneuma::test::lineCount(r.err), 1) << r.err;
  }
}

TEST(CliScenario, CheckAcceptsTheExamplesAndNamesTheFailingPath) {
  std::vector<std::string> args{"scenario", "check"};
  for (const auto& e : fs::recursive_directory_iterator(std::string(PNEUMA_RESOURCE_DIR) + "/scenarios"))
    if (e.is_regular_file()) args.push_back(e.path().string());
  auto r = runCli(args);
  EXPECT_EQ(r.exitCode, 0) << r.err;
  EXPECT_EQ(pneuma::test::lineCount(r.out), static_cast<int>(args.size()) - 2)
      << r.out;  // one "ok" line per file

  const std::string dir = freshOutDir("scenario_check");
  fs::create_directories(dir);
  std::ofstream(dir + "/bad.json") << R"({"format": "pneuma-scenario", "version": 1, "duration_s": 3,
      "controller": {"style": "calm"}, "overrides": {"active_gain_scale": {"diaphram": 2}}})";
  r = runCli({"scenario", "check", dir + "/bad.json"});
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_NE(r.err.find("bad.json: overrides.active_gain_scale.diaphram: unknown muscle group"),
            std::string::npos)
      << r.err;

  // show prints a scenario that parses back to itself
  r = runCli({"scenario", "show", std::string(PNEUMA_RESOURCE_DIR) + "/scenarios/calm.json"});
  EXPECT_EQ(r.exitCode, 0) << r.err;
  EXPECT_NE(r.out.find("\"format\": \"pneuma-scenario\""), std::string::npos) << r.out;
}

TEST(CliSimulate, BlowUpIsReportedWritesPartialOutputsAndExits1) {
  const std::string out = freshOutDir("blowup");
  // explicit Euler far above its stability limit on the stiff cartilage springs
  auto r = runCli({"simulate", "--model", toyModelDir(), "--style", "calm", "--duration", "5", "--integrator",
                   "symplectic-euler", "--dt", "0.01", "--out", out});
  EXPECT_EQ(r.exitCode, 1) << r.err;
  EXPECT_NE(r.err.find("blew up"), std::string::npos) << r.err;
  const nlohmann::json s = nlohmann::json::parse(slurp(out + "/summary.json"));
  EXPECT_TRUE(s["partial"].get<bool>());
  EXPECT_FALSE(s["interrupted"].get<bool>());
  EXPECT_NE(s["error"].get<std::string>().find("dt"), std::string::npos);
  EXPECT_LT(s["simulated_time_s"].get<double>(), 7.0);
}
