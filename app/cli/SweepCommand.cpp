/// @file SweepCommand.cpp
/// `pneuma-cli sweep FILE --out DIR`: runs every variant of a sweep file (sim/ParameterSweep.h), each as a
/// `pneuma-cli simulate` child process into its own folder, several at once; then writes one table of every
/// variant's parameters and summary figures and plots of chosen figures against the parameters. With
/// --slurm it writes a Slurm job-array script instead; each array task runs its share (--task-index) and
/// --collect writes the table. docs/cli.md, "sweep".

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <sstream>
#include <string>
#include <thread>
#include <vector>

#include "CliSupport.h"
#include "Commands.h"
#include "Progress.h"
#include "pneuma/sim/Error.h"
#include "pneuma/sim/JsonReader.h"
#include "pneuma/sim/ParameterSweep.h"
#include "viz/AtomicFile.h"
#include "viz/Plot.h"

namespace pneuma::app {

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

struct SweepArgs {
  std::string file;
  std::string out;
  std::string model;
  int jobs = 0;          // parallel simulate processes; 0 = one per core
  bool slurm = false;    // write the job-array script instead of running
  bool submit = false;   // --slurm, then sbatch it
  bool collect = false;  // only write the table from finished variants
  int taskIndex = -1;    // run only the variants i with i % taskCount == taskIndex
  int taskCount = 1;
  std::string partition;
  std::string timeLimit;
};

/// The summary.json figures of the table: the breath, the gut, the motion (writeMotion()'s keys, one rule
/// with summary.json) and the pattern tracking, then the step. No wall-clock figure: a table is the same
/// wherever its variants ran.
std::vector<std::string> tableFigures() {
  std::vector<std::string> keys = {
      "tidal_volume_ml", "breaths_per_minute",       "end_expiratory_volume_ml", "end_inspiratory_volume_ml",
      "cycles",          "max_gut_volume_error_pct", "mean_gut_volume_error_pct"};
  json motion;
  writeMotion(sim::Motion{}, motion);
  std::vector<std::string> motionKeys;
  for (auto it = motion.begin(); it != motion.end(); ++it) motionKeys.push_back(it.key());
  std::sort(motionKeys.begin(), motionKeys.end());
  keys.insert(keys.end(), motionKeys.begin(), motionKeys.end());
  for (const char* k : {"tracking_rms_pct", "dt_s", "steps"}) keys.push_back(k);
  return keys;
}

std::string joined(const std::vector<std::string>& v) {
  std::string s;
  for (const std::string& x : v) s += (s.empty() ? "" : ", ") + x;
  return s;
}

/// "0007": the variant's folder name under variants/, at least 4 digits.
std::string variantName(std::size_t i, std::size_t count) {
  const int width = std::max<int>(4, static_cast<int>(std::to_string(count - 1).size()));
  std::string s = std::to_string(i);
  return std::string(static_cast<std::size_t>(std::max(0, width - static_cast<int>(s.size()))), '0') + s;
}

/// A value of a setting as the table prints it: JSON text, a string without its quotes.
std::string plainValue(const std::string& jsonText) {
  const json v = json::parse(jsonText);
  return v.is_string() ? v.get<std::string>() : jsonText;
}

std::string settingsText(const sim::SweepVariant& v) {
  std::string s;
  for (const auto& [key, value] : v.settings) s += (s.empty() ? "" : " ") + key + "=" + plainValue(value);
  return s;
}

/// The path of this program, for the child processes and the Slurm script.
std::string selfExe() {
  std::error_code ec;
  const fs::path p = fs::read_symlink("/proc/self/exe", ec);
  if (ec) fail(kExitFailed, "cannot find this program's path (/proc/self/exe): " + ec.message());
  return p.string();
}

struct Layout {
  fs::path out;       // --out
  fs::path variants;  // out/variants
  std::size_t count = 0;
  fs::path scenario(std::size_t i) const { return variants / (variantName(i, count) + ".json"); }
  fs::path log(std::size_t i) const { return variants / (variantName(i, count) + ".log"); }
  fs::path folder(std::size_t i) const { return variants / variantName(i, count); }
  fs::path temporary(std::size_t i) const { return variants / (variantName(i, count) + ".tmp"); }
  bool isFinished(std::size_t i) const { return fs::is_regular_file(folder(i) / "summary.json"); }
};

/// The sweep, every relative path in its variants made absolute (so that a variant runs from any folder).
sim::Sweep loadChecked(const SweepArgs& a) {
  sim::Sweep sweep;
  try {
    sweep = sim::loadSweep(a.file);
  } catch (const sim::Error& e) {
    fail(kExitBadInput, e.what());
  }
  const std::vector<std::string> figures = tableFigures();
  for (std::size_t i = 0; i < sweep.outputs.size(); ++i)
    if (std::find(figures.begin(), figures.end(), sweep.outputs[i]) == figures.end())
      fail(kExitBadInput, a.file + ": outputs[" + std::to_string(i) + "]: unknown summary figure '" +
                              sim::excerptOf(sweep.outputs[i]) + "' (valid: " + joined(figures) + ")");
  for (sim::SweepVariant& v : sweep.variants) {
    sim::Scenario& s = v.scenario;
    if (s.model != "default") s.model = fs::absolute(s.model).lexically_normal().string();
    if ((s.controller == sim::ControllerKind::Pattern && s.patternText.empty()) ||
        s.controller == sim::ControllerKind::Trace)
      s.controllerName = fs::absolute(s.controllerName).lexically_normal().string();
  }
  return sweep;
}

/// Prepares --out and writes each variant's scenario file; a variant file that differs from this sweep's
/// (the sweep file changed since the finished variants ran) is refused before anything runs.
Layout prepare(const SweepArgs& a, const sim::Sweep& sweep) {
  // an array task's --out was prepared by --slurm, and its sibling tasks write into it at the same time
  if (a.taskIndex < 0)
    prepareOutputDir(
        a.out, "sweep",
        {"manifest.json", "variants", "table.csv", "table.json", "sweep.sbatch", "slurm", "*.svg"},
        /*force=*/true);  // resuming is the point: an earlier run's variants are kept
  Layout l{fs::path(a.out), fs::path(a.out) / "variants", sweep.variants.size()};
  std::error_code ec;
  fs::create_directories(l.variants, ec);
  if (ec) fail(kExitBadInput, "--out: cannot create '" + l.variants.string() + "': " + ec.message());
  for (std::size_t i = 0; i < l.count; ++i) {
    const std::string text = sim::serializeScenario(sweep.variants[i].scenario);
    const fs::path p = l.scenario(i);
    if (fs::exists(p)) {
      std::string earlier;
      try {
        earlier = sim::readInputFile(p.string());
      } catch (const sim::Error& e) {
        fail(kExitBadInput, e.what());
      }
      if (earlier == text) continue;
      if (l.isFinished(i))
        fail(kExitBadInput, "--out: " + p.string() + " differs from variant " + std::to_string(i) + " of " +
                                a.file + " (" + settingsText(sweep.variants[i]) +
                                "): the sweep changed since it ran; give a new --out");
    }
    viz::writeFileAtomically(p.string(), text);
  }
  return l;
}

/// Starts `pneuma-cli simulate` for variant `i` into its temporary folder, output into its log.
pid_t startVariant(const Layout& l, std::size_t i, const std::string& exe, const std::string& model) {
  std::error_code ec;
  fs::remove_all(l.temporary(i), ec);  // an interrupted earlier attempt
  std::vector<std::string> args = {
      exe, "simulate", "--scenario", l.scenario(i).string(), "--out", l.temporary(i).string()};
  if (!model.empty()) args.insert(args.end(), {"--model", model});
  const std::string log = l.log(i).string();
  const pid_t pid = fork();
  if (pid == 0) {
    FILE* f = std::fopen(log.c_str(), "w");
    if (f != nullptr) {
      dup2(fileno(f), 1);
      dup2(fileno(f), 2);
    }
    std::vector<char*> argv;
    for (std::string& s : args) argv.push_back(s.data());
    argv.push_back(nullptr);
    execv(exe.c_str(), argv.data());
    _exit(127);
  }
  if (pid < 0) fail(kExitFailed, "cannot start a simulate process for variant " + std::to_string(i));
  return pid;
}

/// The last non-empty line of a file (a failed variant's one-line error).
std::string lastLine(const fs::path& p) {
  std::string text, line, last;
  try {
    text = sim::readInputFile(p.string());
  } catch (const sim::Error&) {
    return "";
  }
  std::istringstream in(text);
  while (std::getline(in, line))
    if (!line.empty()) last = line;
  return last;
}

/// Runs the variants `todo` with at most `jobs` at once. Returns the indices that failed. A Ctrl-C
/// (InterruptGuard) is passed on to the running variants, which stop and are discarded; no new one starts.
std::vector<std::size_t> runVariants(const Layout& l, const sim::Sweep& sweep,
                                     const std::vector<std::size_t>& todo, int jobs,
                                     const std::string& model) {
  const std::string exe = selfExe();
  std::map<pid_t, std::pair<std::size_t, std::chrono::steady_clock::time_point>> running;
  std::vector<std::size_t> failed;
  std::size_t next = 0, done = 0;
  bool isForwarded = false;
  while ((next < todo.size() && !InterruptGuard::isInterrupted()) || !running.empty()) {
    // launch while there are free workers and no stop request
    while (!InterruptGuard::isInterrupted() && next < todo.size() &&
           static_cast<int>(running.size()) < jobs) {
      const std::size_t i = todo[next++];
      running[startVariant(l, i, exe, model)] = {i, std::chrono::steady_clock::now()};
    }
    if (InterruptGuard::isInterrupted() && !isForwarded) {
      for (const auto& r : running) kill(r.first, SIGINT);
      isForwarded = true;
    }
    int status = 0;
    const pid_t pid = waitpid(-1, &status, WNOHANG);
    if (pid <= 0) {
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
      continue;
    }
    const auto it = running.find(pid);
    if (it == running.end()) continue;
    const auto [i, started] = it->second;
    running.erase(it);
    ++done;
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    const int code = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
    std::error_code ec;
    if (code == 0) {
      fs::remove_all(l.folder(i), ec);
      fs::rename(l.temporary(i), l.folder(i), ec);  // the variant's outputs appear complete or not at all
      if (ec) {
        failed.push_back(i);
        std::fprintf(stderr, "pneuma-cli: error: variant %s: cannot rename %s: %s\n",
                     variantName(i, l.count).c_str(), l.temporary(i).c_str(), ec.message().c_str());
        continue;
      }
      std::printf("[%zu/%zu] variant %s (%s) finished in %.1f s\n", done, todo.size(),
                  variantName(i, l.count).c_str(), settingsText(sweep.variants[i]).c_str(), seconds);
    } else {
      fs::remove_all(l.temporary(i), ec);
      if (code == kExitInterrupted || InterruptGuard::isInterrupted()) {
        std::printf("[%zu/%zu] variant %s interrupted, discarded\n", done, todo.size(),
                    variantName(i, l.count).c_str());
      } else {
        failed.push_back(i);
        std::printf("[%zu/%zu] variant %s (%s) failed (exit %d): %s\n", done, todo.size(),
                    variantName(i, l.count).c_str(), settingsText(sweep.variants[i]).c_str(), code,
                    lastLine(l.log(i)).c_str());
      }
    }
    std::fflush(stdout);
  }
  std::sort(failed.begin(), failed.end());
  return failed;
}

/// table.csv, table.json and plot_<figure>.svg from the finished variants (all must be).
void writeTable(const Layout& l, const sim::Sweep& sweep) {
  std::vector<std::string> missing;
  for (std::size_t i = 0; i < l.count; ++i)
    if (!l.isFinished(i)) missing.push_back(variantName(i, l.count));
  if (!missing.empty())
    fail(kExitFailed, std::to_string(missing.size()) + " of " + std::to_string(l.count) +
                          " variants not finished (" + joined(missing) +
                          "); run the sweep again (or the remaining array tasks) to finish them");

  const std::vector<std::string> figures = tableFigures();
  std::string csv = "variant";
  for (const std::string& p : sweep.parameters) csv += "," + p;
  for (const std::string& f : figures) csv += "," + f;
  csv += "\n";
  json rows = json::array();
  std::vector<json> summaries;
  for (std::size_t i = 0; i < l.count; ++i) {
    const fs::path file = l.folder(i) / "summary.json";
    json summary;
    try {
      summary = json::parse(sim::readInputFile(file.string()));
    } catch (const std::exception& e) {
      fail(kExitFailed, file.string() + ": " + e.what());
    }
    json row = {{"variant", variantName(i, l.count)}, {"parameters", json::object()}};
    csv += variantName(i, l.count);
    for (const auto& [key, value] : sweep.variants[i].settings) {
      row["parameters"][key] = json::parse(value);
      csv += "," + plainValue(value);
    }
    for (const std::string& f : figures) {
      const json v = summary.contains(f) ? summary[f] : json(nullptr);
      row[f] = v;
      csv += "," + (v.is_number() ? formatNumber(v.get<double>()) : std::string());
    }
    csv += "\n";
    rows.push_back(row);
    summaries.push_back(std::move(summary));
  }
  const json table = {{"sweep", sweep.name}, {"parameters", sweep.parameters}, {"variants", rows}};
  viz::writeFileAtomically((l.out / "table.csv").string(), csv);
  viz::writeFileAtomically((l.out / "table.json").string(), table.dump(2) + "\n");

  // plots: each chosen figure against the first parameter, one line per combination of the others
  const std::string& xKey = sweep.parameters.front();
  for (const std::string& f : sweep.outputs) {
    viz::Plot plot(sweep.name + ": " + f, xKey, f);
    std::map<std::string, std::vector<std::pair<double, double>>> lines;  // others' values -> (x, y)
    for (std::size_t i = 0; i < l.count; ++i) {
      const json x = json::parse(sweep.variants[i].settings.front().second);
      const json& y = summaries[i][f];
      std::string others;
      for (std::size_t k = 1; k < sweep.parameters.size(); ++k)
        others += (others.empty() ? "" : ", ") + sweep.parameters[k] + " " +
                  plainValue(sweep.variants[i].settings[k].second);
      if (sweep.design == sim::SweepDesign::Random) others.clear();  // scattered draws: one line by x
      lines[others].emplace_back(x.is_number() ? x.get<double>() : static_cast<double>(i),
                                 y.is_number() ? y.get<double>() : sim::kNaN);
    }
    for (auto& [label, points] : lines) {
      std::sort(points.begin(), points.end());
      std::vector<double> xs, ys;
      for (const auto& [x, y] : points) xs.push_back(x), ys.push_back(y);
      plot.addSeries(label, xs, ys);
    }
    plot.writeSvg((l.out / ("plot_" + f + ".svg")).string());
  }
  std::printf("wrote %s, %s and %zu plot(s) for %zu variants\n", (l.out / "table.csv").c_str(),
              (l.out / "table.json").c_str(), sweep.outputs.size(), l.count);
}

/// sweep.sbatch (a job array, one task per share of the variants) and manifest.json.
void writeSlurm(const SweepArgs& a, const Layout& l, const sim::Sweep& sweep) {
  const int tasks =
      std::min<int>(a.taskCount > 1 ? a.taskCount : static_cast<int>(l.count), static_cast<int>(l.count));
  const std::string exe = selfExe();
  const std::string file = fs::absolute(a.file).lexically_normal().string();
  const std::string out = fs::absolute(a.out).lexically_normal().string();
  const std::string model = a.model.empty() ? "" : fs::absolute(a.model).lexically_normal().string();
  auto quoted = [](const std::string& s) {
    std::string q = "'";
    for (char c : s) q += c == '\'' ? std::string("'\\''") : std::string(1, c);
    return q + "'";
  };
  std::string script = "#!/bin/bash\n";
  script += "# pneuma-cli sweep " + file + ": " + std::to_string(l.count) + " variants in " +
            std::to_string(tasks) + " array tasks; then: pneuma-cli sweep " + file + " --out " + out +
            " --collect\n";
  script += "#SBATCH --job-name=pneuma-sweep\n";
  script += "#SBATCH --array=0-" + std::to_string(tasks - 1) + "\n";
  script += "#SBATCH --ntasks=1\n#SBATCH --cpus-per-task=1\n";
  script += "#SBATCH --output=" + out + "/slurm/task-%a.out\n";
  if (!a.partition.empty()) script += "#SBATCH --partition=" + a.partition + "\n";
  if (!a.timeLimit.empty()) script += "#SBATCH --time=" + a.timeLimit + "\n";
  script += "exec " + quoted(exe) + " sweep " + quoted(file) + " --out " + quoted(out) +
            (model.empty() ? "" : " --model " + quoted(model)) +
            " --jobs 1 --task-index \"$SLURM_ARRAY_TASK_ID\" --task-count " + std::to_string(tasks) + "\n";
  std::error_code ec;
  fs::create_directories(l.out / "slurm", ec);
  viz::writeFileAtomically((l.out / "sweep.sbatch").string(), script);
  json manifest = {
      {"sweep", file},  {"name", sweep.name},  {"out", out},           {"program", exe},
      {"model", model}, {"variants", l.count}, {"array_tasks", tasks}, {"parameters", sweep.parameters}};
  json variants = json::array();
  for (std::size_t i = 0; i < l.count; ++i) {
    json s = json::object();
    for (const auto& [key, value] : sweep.variants[i].settings) s[key] = json::parse(value);
    variants.push_back({{"variant", variantName(i, l.count)},
                        {"task", static_cast<int>(i % static_cast<std::size_t>(tasks))},
                        {"scenario", fs::absolute(l.scenario(i)).string()},
                        {"settings", s}});
  }
  manifest["variant_list"] = variants;
  viz::writeFileAtomically((l.out / "manifest.json").string(), manifest.dump(2) + "\n");
  std::printf("wrote %s (%d array tasks for %zu variants) and %s\n", (l.out / "sweep.sbatch").c_str(), tasks,
              l.count, (l.out / "manifest.json").c_str());
  if (!a.submit) {
    std::printf("submit with: sbatch %s\nthen: pneuma-cli sweep %s --out %s --collect\n",
                (l.out / "sweep.sbatch").c_str(), file.c_str(), out.c_str());
    return;
  }
  const std::string command = "sbatch --parsable " + quoted((l.out / "sweep.sbatch").string());
  FILE* p = popen((command + " 2>&1").c_str(), "r");
  std::string reply;
  char buf[256];
  while (p != nullptr && std::fgets(buf, sizeof buf, p) != nullptr) reply += buf;
  const int status = p != nullptr ? pclose(p) : -1;
  while (!reply.empty() && (reply.back() == '\n' || reply.back() == '\r')) reply.pop_back();
  if (status != 0) {
    const std::size_t nl = reply.rfind('\n');
    fail(kExitFailed, "--submit: '" + command + "' failed: " +
                          (reply.empty() ? "no answer" : reply.substr(nl == std::string::npos ? 0 : nl + 1)));
  }
  std::printf("submitted job %s\n", reply.c_str());
}

void runSweep(const SweepArgs& a) {
  const int modes = a.slurm + a.collect + (a.taskIndex >= 0);
  if (modes > 1) fail(kExitBadInput, "give at most one of --slurm, --collect and --task-index");
  if (a.submit && !a.slurm) fail(kExitBadInput, "--submit needs --slurm");
  if (a.taskIndex >= 0 && a.taskIndex >= a.taskCount)
    fail(kExitBadInput, "--task-index: must be in [0, " + std::to_string(a.taskCount - 1) + "], got " +
                            std::to_string(a.taskIndex));
  if (!a.model.empty()) resolveModelDir(a.model);
  const sim::Sweep sweep = loadChecked(a);
  const Layout l = prepare(a, sweep);
  if (a.slurm) return writeSlurm(a, l, sweep);
  if (a.collect) return writeTable(l, sweep);

  std::vector<std::size_t> todo;
  std::size_t finished = 0;
  for (std::size_t i = 0; i < l.count; ++i) {
    if (a.taskIndex >= 0 && static_cast<int>(i % static_cast<std::size_t>(a.taskCount)) != a.taskIndex)
      continue;
    if (l.isFinished(i))
      ++finished;
    else
      todo.push_back(i);
  }
  const int cores = static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
  const int jobs = std::max(1, std::min<int>(a.jobs > 0 ? a.jobs : cores, static_cast<int>(todo.size())));
  std::printf("%s: %zu variants%s, %zu finished earlier, %zu to run on %d worker(s)\n", sweep.name.c_str(),
              l.count,
              a.taskIndex >= 0 ? (" (task " + std::to_string(a.taskIndex) + "'s share)").c_str() : "",
              finished, todo.size(), jobs);
  std::fflush(stdout);

  InterruptGuard guard;
  const std::vector<std::size_t> failed = runVariants(l, sweep, todo, jobs, a.model);
  if (InterruptGuard::isInterrupted()) {
    std::printf("interrupted: finished variants are kept; run the same command again to resume\n");
    throw CLI::RuntimeError(kExitInterrupted);
  }
  if (!failed.empty()) {
    std::vector<std::string> names;
    for (std::size_t i : failed) names.push_back(variantName(i, l.count) + " (" + l.log(i).string() + ")");
    fail(kExitFailed, std::to_string(failed.size()) + " variant(s) failed: " + joined(names) +
                          "; run the sweep again to retry them");
  }
  if (a.taskIndex < 0) writeTable(l, sweep);
}

}  // namespace

void addSweepCommand(CLI::App& app) {
  auto args = std::make_shared<SweepArgs>();
  CLI::App* cmd = app.add_subcommand(
      "sweep", "Run every variant of a sweep file (docs/cli.md); write one folder per variant and a table");
  cmd->add_option("FILE", args->file, "Sweep file (JSON, \"format\": \"pneuma-sweep\")")->required();
  cmd->add_option("--out", args->out, "Output directory; an earlier run's finished variants are kept")
      ->required();
  addModelOption(*cmd, args->model);
  cmd->add_option("--jobs", args->jobs, "Variants run at once (default: one per core)")
      ->check(CLI::Range(1, 1024));
  cmd->add_flag("--slurm", args->slurm,
                "Write a Slurm job-array script (sweep.sbatch) and manifest.json instead of running");
  cmd->add_flag("--submit", args->submit, "With --slurm: submit the script with sbatch");
  cmd->add_option("--partition", args->partition, "With --slurm: the Slurm partition");
  cmd->add_option("--time", args->timeLimit, "With --slurm: each array task's time limit (Slurm's format)");
  cmd->add_flag("--collect", args->collect, "Write the table and plots from the finished variants only");
  cmd->add_option("--task-index", args->taskIndex,
                  "Run only the variants i with i mod --task-count = this (a Slurm array task)")
      ->check(CLI::NonNegativeNumber);
  cmd->add_option("--task-count", args->taskCount,
                  "Number of tasks the variants are shared among (with "
                  "--task-index; with --slurm, the array size)")
      ->check(CLI::Range(1, 1000000));
  cmd->callback([args] { runSweep(*args); });
}

}  // namespace pneuma::app
