#pragma once
/// CPU time of this process and of one of its threads, for `pneuma --measure`: the CPU a rendered frame costs
/// is less sensitive to the machine's load than its wall time (on a shared machine a render waits for a
/// core). Linux: the process's clock (CLOCK_PROCESS_CPUTIME_ID, every thread, the exited ones too) and a
/// thread's utime + stime from /proc/self/task/<tid>/stat, found by the name the thread was given (QThread's
/// objectName). Elsewhere both read 0.
#include <string>

namespace pneuma::app {

/// [s] CPU time of the whole process so far (all threads: the GUI, the simulation, the OpenGL driver's).
double processCpuSeconds();

/// [s] CPU time so far of the threads of this process named `name` (the first 15 characters, as Linux keeps
/// them); 0 when there is none.
double threadCpuSeconds(const std::string& name);

}  // namespace pneuma::app
