// pneuma-cli validate: every check is reported with target, measured value, pass/fail and source, in
// report.json, report.md and a self-contained report.html; the exit code says whether all passed.
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "CliRunner.h"
#include "ToyModelDir.h"

using pneuma::test::freshOutDir;
using pneuma::test::runCli;
using pneuma::test::runReplacingEarlierRun;
using pneuma::test::slurp;
using pneuma::test::toyModelDir;

TEST(CliValidate, ReportHoldsEveryCheckAndExitCodeMatches) {
  // an earlier report in --out: refused, untouched, then replaced with --force
  const std::string out = freshOutDir("validate");
  std::filesystem::create_directories(out);
  std::ofstream(out + "/report.json") << "earlier";
  const std::vector<std::string> args = {"validate", "--quick",     "--dt",  "0.002",
                                         "--model",  toyModelDir(), "--out", out};
  const auto r = runReplacingEarlierRun(args, out, "report.json");
  ASSERT_TRUE(r.exitCode == 0 || r.exitCode == 1) << r.err;

  const nlohmann::json j = nlohmann::json::parse(slurp(out + "/report.json"));
  const auto& checks = j.at("checks");
  ASSERT_GE(checks.size(), 15u);  // four styles, impact, sway
  int failed = 0;
  for (const auto& c : checks) {
    for (const char* key : {"id", "what", "target", "measured", "unit", "passed", "source"})
      EXPECT_TRUE(c.contains(key)) << key;
    EXPECT_FALSE(c["source"].get<std::string>().empty());
    // pass/fail agrees with the bounds
    const double m = c["measured"].get<double>();
    const bool inside = (c["lower"].is_null() || m >= c["lower"].get<double>()) &&
                        (c["upper"].is_null() || m <= c["upper"].get<double>());
    EXPECT_EQ(c["passed"].get<bool>(), inside) << c["id"];
    failed += !c["passed"].get<bool>();
  }
  EXPECT_EQ(j["failed_count"].get<int>(), failed);
  EXPECT_EQ(r.exitCode, failed == 0 ? 0 : 1);
  for (const std::string id : {"calm.tidal_volume", "impact.gut_volume_error", "sway.friction_ratio"}) {
    bool found = false;
    for (const auto& c : checks) found = found || c["id"] == id;
    EXPECT_TRUE(found) << id;
  }

  // report.md: one table row per check; report.html: self-contained (embedded PNGs), one row per check
  const std::string md = slurp(out + "/report.md"), html = slurp(out + "/report.html");
  for (const auto& c : checks) {
    const std::string id = c["id"].get<std::string>();
    EXPECT_NE(md.find("| " + id + " |"), std::string::npos) << id;
    EXPECT_NE(html.find("<td>" + id + "</td>"), std::string::npos) << id;
  }
  EXPECT_NE(html.find("data:image/png;base64,iVBORw0KGgo"), std::string::npos);  // PNG signature in base64
  EXPECT_EQ(html.find("src=\"figure"), std::string::npos);  // no external image references
  EXPECT_NE(slurp(out + "/figure6_lung_volume.svg").find("500 mL"), std::string::npos);
  // the physiology section: every physiology check of report.json is a row of both reports, the calm dome
  // descent beside its published range, its figure report.json's styles.calm.dome_descent_mm
  const nlohmann::json report = nlohmann::json::parse(slurp(out + "/report.json"));
  ASSERT_TRUE(report["styles"]["calm"]["dome_descent_mm"].is_number());
  // the physiology and teaching sections: every check of report.json's list is a row of both reports, and
  // the list's "<section>_within" counts those that passed; teaching has a row per teaching check, 18 of them
  // (the calm reference and six presets, each with its figures)
  ASSERT_TRUE(report["teaching"].is_array());
  EXPECT_EQ(report["teaching"].size(), 18u);
  for (const std::string section : {"physiology", "teaching"}) {
    ASSERT_TRUE(report[section].is_array()) << section;
    int within = 0;
    for (const auto& c : report[section]) {
      const std::string id = c["id"].get<std::string>();
      EXPECT_NE(md.find("| " + id + " |"), std::string::npos) << id;
      EXPECT_NE(html.find("<td>" + id + "</td>"), std::string::npos) << id;
      within += c["passed"].get<bool>();
    }
    EXPECT_EQ(report[section + "_within"].get<int>(), within) << section;
  }
  EXPECT_NE(html.find("<h2>Teaching presets</h2>"), std::string::npos);
  const std::string row =
      "| physiology.calm.dome_descent | dome descent (central tendon, craniocaudal), calm | ";
  const std::size_t at = md.find(row);
  ASSERT_NE(at, std::string::npos);
  EXPECT_NEAR(std::stod(md.substr(at + row.size())),
              report["styles"]["calm"]["dome_descent_mm"].get<double>(),
              1e-3 * std::max(1.0, std::abs(report["styles"]["calm"]["dome_descent_mm"].get<double>())));
  EXPECT_NE(md.find("12 - 25 mm"), std::string::npos);
  EXPECT_NE(html.find("<h2>Physiology</h2>"), std::string::npos);
  // the calm breath's rib motion: a row per rib of report.json in both reports (the motion itself is
  // tested on the default model: Breathing.UpperRibsTurnNearerThePumpHandleEveryRibRises)
  const nlohmann::json& ribs = report["styles"]["calm"]["rib_motion"];
  ASSERT_FALSE(ribs.empty());
  for (const auto& rm : ribs) {
    const std::string rib = rm["rib"].get<std::string>();
    EXPECT_NE(md.find("| " + rib + " | "), std::string::npos) << rib;
    EXPECT_NE(html.find("<td>" + rib + "</td>"), std::string::npos) << rib;
  }
  EXPECT_NE(html.find("<h2>Rib motion, calm</h2>"), std::string::npos);
  // stdout carries the table
  EXPECT_NE(r.out.find("calm.tidal_volume"), std::string::npos);
}

// data loss: validate writes only into a new or empty folder or over an earlier report, never over other
// files
TEST(CliValidate, FolderOfOtherFilesIsRefused) {
  const std::string out = freshOutDir("validate_foreign");
  std::filesystem::create_directories(out);
  std::ofstream(out + "/report.txt") << "mine";
  for (const bool force : {false, true}) {
    std::vector<std::string> args = {"validate", "--quick", "--model", toyModelDir(), "--out", out};
    if (force) args.push_back("--force");
    const auto r = runCli(args);
    EXPECT_EQ(r.exitCode, 2) << r.err;
    EXPECT_NE(r.err.find("holds 'report.txt', which pneuma-cli validate does not write"), std::string::npos)
        << r.err;
    EXPECT_EQ(slurp(out + "/report.txt"), "mine");
    EXPECT_FALSE(std::filesystem::exists(out + "/report.json"));
  }
}

TEST(CliValidate, MissingModelIsBadInput) {
  auto r = runCli({"validate", "--model", "/nonexistent/model", "--out", freshOutDir("validate_bad")});
  EXPECT_EQ(r.exitCode, 2);
  EXPECT_EQ(pneuma::test::lineCount(r.err), 1) << r.err;
}
