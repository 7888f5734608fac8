#include "gui/CpuClock.h"

#include <ctime>
#include <filesystem>
#include <fstream>
#include <sstream>

#if defined(__linux__)
#include <unistd.h>
#endif

namespace pneuma::app {

double processCpuSeconds() {
#if defined(__linux__)
  timespec t{};
  if (clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t) != 0) return 0.0;
  return static_cast<double>(t.tv_sec) + 1e-9 * static_cast<double>(t.tv_nsec);
#else
  return 0.0;
#endif
}

double threadCpuSeconds(const std::string& name) {
#if defined(__linux__)
  const std::string wanted = name.substr(0, 15);  // the kernel keeps 15 characters of a thread's name
  const double tick = 1.0 / static_cast<double>(sysconf(_SC_CLK_TCK));  // [s]
  double seconds = 0.0;
  std::error_code error;
  for (const auto& task : std::filesystem::directory_iterator("/proc/self/task", error)) {
    std::ifstream in(task.path() / "stat");
    std::string line;
    if (!std::getline(in, line)) continue;
    // "<tid> (<comm>) <state> ...": comm may hold spaces and parentheses, so split at the last ')'
    const auto open = line.find('('), close = line.rfind(')');
    if (open == std::string::npos || close == std::string::npos || close < open) continue;
    if (line.compare(open + 1, close - open - 1, wanted) != 0) continue;
    std::istringstream fields(line.substr(close + 2));
    std::string field;
    // fields 3..13 of proc(5), then utime (14) and stime (15), in clock ticks
    for (int i = 3; i <= 13 && fields >> field; ++i) {
    }
    double user = 0.0, system = 0.0;
    if (fields >> user >> system) seconds += (user + system) * tick;
  }
  return seconds;
#else
  (void)name;
  return 0.0;
#endif
}

}  // namespace pneuma::app
