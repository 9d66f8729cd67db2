// A bound on a process's DDS teardown once its results are on disk (every bbw_ccu and
// bbw_corner). In about 30 lockstep standby runs (issue 16), twice a process that had finished
// its run and written its stats and logs did not return from Fast DDS 2.9's entity deletion, and
// once a corner of a plain realtime run across network namespaces (SystemNetns, UDP) did the same
// (not found where; docs/faults.md "Left"): its results were complete, the test killed it 15 s
// later. bound_teardown() starts a detached thread: if the process is still there after
// `limit`, it says so on stderr and ends with _exit(exit_code) (its results are written already).
// A process that tears down in time exits normally and the thread goes with it.
#pragma once

#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <string>
#include <thread>

namespace bbw::runtime {

inline void bound_teardown(const std::string& name, std::chrono::milliseconds limit, int exit_code) {
  std::thread([name, limit, exit_code] {
    std::this_thread::sleep_for(limit);  // a bound, not a synchronisation: normally main returns first
    std::fprintf(stderr, "%s: Fast DDS teardown did not finish within %lld ms; exiting with %d (results written)\n",
                 name.c_str(), static_cast<long long>(limit.count()), exit_code);
    std::fflush(stderr);
    ::_exit(exit_code);
  }).detach();
}

}  // namespace bbw::runtime
