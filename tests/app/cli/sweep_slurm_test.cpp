// pneuma-cli sweep --slurm on a real single-node Slurm (Debian's slurm-wlm with munge): the test writes a
// slurm.conf for this host, a munge key, starts munged, slurmctld and slurmd (as root, everything under its
// temporary folder, on ports of its own), submits the 3 x 3 sweep as a job array, waits, collects and
// compares the table with the same sweep run locally, bit for bit; then stops the daemons.
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <chrono>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <thread>

#include "CliRunner.h"
#include "SweepFiles.h"
#include "ToyModelDir.h"

using pneuma::test::freshOutDir;
using pneuma::test::gainGridSweep;
using pneuma::test::lineCount;
using pneuma::test::runCli;
using pneuma::test::slurp;
using pneuma::test::toyModelDir;
namespace fs = std::filesystem;

namespace {

// the output of a shell command (stderr included)
std::string shell(const std::string& command) {
  std::string out;
  FILE* p = popen((command + " 2>&1").c_str(), "r");
  char buf[512];
  while (p != nullptr && std::fgets(buf, sizeof buf, p) != nullptr) out += buf;
  if (p != nullptr) pclose(p);
  return out;
}

std::string lastLines(const std::string& path, int n = 3) {
  return shell("tail -n " + std::to_string(n) + " '" + path + "'");
}

/// munged, slurmctld and slurmd for this host, stopped by the destructor.
class LocalSlurm {
 public:
  LocalSlurm() : m_dir(freshOutDir("slurm")) {
    fs::create_directories(m_dir + "/munge");
    for (const char* d : {"state", "spool", "log"}) fs::create_directories(m_dir + "/" + d);
    chmod((m_dir + "/munge").c_str(), 0700);
    shell("dd if=/dev/urandom of='" + m_dir + "/munge/munge.key' bs=1024 count=1");
    chmod((m_dir + "/munge/munge.key").c_str(), 0400);
    char host[256] = {0};
    gethostname(host, sizeof host - 1);
    std::string node = host;
    node = node.substr(0, node.find('.'));
    const int port = 20000 + static_cast<int>(getpid() % 20000) * 2 % 20000;  // two ports of this test's own
    std::ofstream(m_dir + "/slurm.conf")
        << "ClusterName=pneumatest\nSlurmctldHost=" << node << "\nSlurmUser=root\nSlurmdUser=root\n"
        << "SlurmctldPort=" << port << "\nSlurmdPort=" << port + 1 << "\n"
        << "AuthType=auth/munge\nCredType=cred/munge\nAuthInfo=socket=" << m_dir << "/munge/munge.sock\n"
        << "StateSaveLocation=" << m_dir << "/state\nSlurmdSpoolDir=" << m_dir << "/spool\n"
        << "SlurmctldPidFile=" << m_dir << "/slurmctld.pid\nSlurmdPidFile=" << m_dir << "/slurmd.pid\n"
        << "SlurmctldLogFile=" << m_dir << "/log/slurmctld.log\nSlurmdLogFile=" << m_dir
        << "/log/slurmd.log\n"
        << "ProctrackType=proctrack/linuxproc\nTaskPlugin=task/none\n"
        << "SelectType=select/cons_tres\nSelectTypeParameters=CR_CPU\nSchedulerType=sched/backfill\n"
        << "MpiDefault=none\nReturnToService=2\nJobAcctGatherType=jobacct_gather/none\n"
        << "AccountingStorageType=accounting_storage/none\nJobCompType=jobcomp/none\n"
        << "PlugStackConfig=" << m_dir << "/plugstack.conf\n"
        << "NodeName=" << node << " NodeAddr=127.0.0.1 CPUs=" << std::thread::hardware_concurrency()
        << " State=UNKNOWN\nPartitionName=pneuma Nodes=" << node
        << " Default=YES MaxTime=INFINITE State=UP\n";
    std::ofstream(m_dir + "/plugstack.conf");
    m_env = "SLURM_CONF=" + m_dir + "/slurm.conf";

    // munged, then the controller and the node daemon
    const std::string munge =
        shell("/usr/sbin/munged -f --socket='" + m_dir + "/munge/munge.sock' --key-file='" + m_dir +
              "/munge/munge.key' --log-file='" + m_dir + "/log/munged.log' --pid-file='" + m_dir +
              "/munge/munged.pid' --seed-file='" + m_dir + "/munge/munged.seed'");
    if (!fs::exists(m_dir + "/munge/munged.pid")) {
      m_problem = "munged did not start: " + munge + lastLines(m_dir + "/log/munged.log");
      return;
    }
    const std::string conf = " -f '" + m_dir + "/slurm.conf'";
    shell(m_env + " /usr/sbin/slurmctld" + conf);
    shell(m_env + " /usr/sbin/slurmd" + conf);
    // the node is up when sinfo reports it idle
    for (int i = 0; i < 150; ++i) {
      m_state = shell(m_env + " sinfo -h -o %T");
      if (m_state.rfind("idle", 0) == 0) return;
      std::this_thread::sleep_for(std::chrono::milliseconds(200));
    }
    m_problem = "the node did not come up (sinfo: " + m_state +
                "); slurmctld: " + lastLines(m_dir + "/log/slurmctld.log") +
                "; slurmd: " + lastLines(m_dir + "/log/slurmd.log");
  }

  ~LocalSlurm() {
    shell(m_env + " scontrol shutdown");
    // stop whatever did not go with the shutdown, by its pid file
    for (const char* pidFile : {"/slurmd.pid", "/slurmctld.pid"}) {
      std::this_thread::sleep_for(std::chrono::milliseconds(500));
      const std::string pid = slurp(m_dir + pidFile);
      if (!pid.empty() && std::atoi(pid.c_str()) > 1 && kill(std::atoi(pid.c_str()), 0) == 0)
        kill(std::atoi(pid.c_str()), SIGTERM);
    }
    shell("/usr/sbin/munged -s --socket='" + m_dir + "/munge/munge.sock'");
  }

  /// Why the cluster is not usable ("" when it is).
  const std::string& problem() const { return m_problem; }
  /// "SLURM_CONF=<its slurm.conf>", for the commands that talk to it.
  const std::string& env() const { return m_env; }

  /// Waits until job `id` has left the queue (at most `seconds`); false on timeout.
  bool waitFor(const std::string& id, double seconds) const {
    const auto end = std::chrono::steady_clock::now() + std::chrono::duration<double>(seconds);
    while (std::chrono::steady_clock::now() < end) {
      if (shell(m_env + " squeue -h -j " + id).find_first_not_of(" \n") == std::string::npos) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(500));
    }
    return false;
  }

 private:
  std::string m_dir;
  std::string m_env;
  std::string m_state;
  std::string m_problem;
};

}  // namespace

TEST(CliSweepSlurm, JobArrayOnASingleNodeSlurmGivesTheLocalTableBitForBit) {
  if (geteuid() != 0)
    GTEST_SKIP() << "the single-node Slurm runs slurmd as root; this test runs as uid " << geteuid();
  for (const char* program : {"/usr/sbin/munged", "/usr/sbin/slurmctld", "/usr/sbin/slurmd",
                              "/usr/bin/sbatch", "/usr/bin/squeue", "/usr/bin/sinfo", "/usr/bin/scontrol"})
    if (!fs::exists(program)) GTEST_SKIP() << program << " is missing (Debian packages slurm-wlm and munge)";

  const std::string file = gainGridSweep();
  const std::string local = freshOutDir("slurm_local");
  const auto l = runCli({"sweep", file, "--out", local, "--model", toyModelDir(), "--jobs", "2"});
  ASSERT_EQ(l.exitCode, 0) << l.err << l.out;

  LocalSlurm slurm;
  if (!slurm.problem().empty()) GTEST_SKIP() << "Slurm could not be started here: " << slurm.problem();
  const std::string out = freshOutDir("slurm_sweep");
  const auto submit = runCli({"sweep", file, "--out", out, "--model", toyModelDir(), "--slurm", "--submit"},
                             0.0, {slurm.env()});
  ASSERT_EQ(submit.exitCode, 0) << submit.err << submit.out;
  const std::size_t at = submit.out.find("submitted job ");
  ASSERT_NE(at, std::string::npos) << submit.out;
  const std::string job = submit.out.substr(at + 14, submit.out.find('\n', at) - at - 14);
  ASSERT_TRUE(slurm.waitFor(job, 600)) << "job " << job << " still queued after 600 s";

  // every array task ran its variant on the cluster
  for (int i = 0; i < 9; ++i) {
    EXPECT_TRUE(fs::exists(out + "/slurm/task-" + std::to_string(i) + ".out")) << i;
    EXPECT_TRUE(fs::exists(out + "/variants/000" + std::to_string(i) + "/summary.json"))
        << i << ": " << slurp(out + "/slurm/task-" + std::to_string(i) + ".out");
  }
  const auto collect = runCli({"sweep", file, "--out", out, "--model", toyModelDir(), "--collect"});
  ASSERT_EQ(collect.exitCode, 0) << collect.err;
  EXPECT_EQ(slurp(out + "/table.csv"), slurp(local + "/table.csv"));
  EXPECT_EQ(slurp(out + "/table.json"), slurp(local + "/table.json"));
}

TEST(CliSweepSlurm, SubmittingToAnUnreachableSlurmIsOneLineNamingTheCommand) {
  if (!fs::exists("/usr/bin/sbatch")) GTEST_SKIP() << "/usr/bin/sbatch is missing (Debian package slurm-wlm)";
  // a controller on a port nobody listens on, with no authentication to reach
  const std::string dir = freshOutDir("slurm_unreachable");
  fs::create_directories(dir);
  std::ofstream(dir + "/slurm.conf") << "ClusterName=nowhere\nSlurmctldHost=localhost\nSlurmctldPort=9\n"
                                     << "AuthType=auth/none\nNodeName=localhost CPUs=1\n"
                                     << "PartitionName=p Nodes=localhost Default=YES\nMessageTimeout=2\n";
  const std::string out = freshOutDir("slurm_unreachable_out");
  const auto r =
      runCli({"sweep", gainGridSweep(), "--out", out, "--model", toyModelDir(), "--slurm", "--submit"}, 0.0,
             {"SLURM_CONF=" + dir + "/slurm.conf"});
  EXPECT_EQ(r.exitCode, 1) << r.out;
  EXPECT_EQ(lineCount(r.err), 1) << r.err;
  EXPECT_NE(r.err.find("--submit: 'sbatch --parsable"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out + "/variants/0000"));  // nothing ran
}
