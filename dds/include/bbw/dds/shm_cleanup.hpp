// Removal of Fast DDS shared-memory files that killed processes leave in /dev/shm.
//
// Fast DDS keeps, next to each segment `fastrtps_X`, a lock file `fastrtps_X_el` that its
// owner holds with flock(LOCK_EX) while alive, and next to each port `fastrtps_portN` a file
// `fastrtps_portN_sl` that every user holds with flock(LOCK_SH). The kernel drops those locks
// when a process dies. A file is stale only when we can take the exclusive lock ourselves
// (nobody alive holds it) and it is older than `min_age` (so a process that is creating its
// files right now is never disturbed). Files of live processes are never touched.
//
// Fast DDS 2.9 also leaves port segments and their semaphores (fastrtps_portN,
// sem.fastrtps_portN_mutex) with no lock file beside them (issue 17: 8 of each after a killed
// CCU). Such a file is stale when no process maps it (/proc/<pid>/maps of every process this
// user may read: its own Fast DDS processes always) and it is older than `min_age`.
#pragma once

#include <chrono>
#include <string>
#include <vector>

namespace bbw::dds {

struct ShmCleanupReport {
  std::vector<std::string> removed;  // file names removed
  std::size_t kept_live = 0;         // lock files held by a live process
  std::size_t kept_young = 0;        // stale-looking but younger than min_age
};

ShmCleanupReport cleanup_stale_shm(const std::string& dir = "/dev/shm",
                                   std::chrono::seconds min_age = std::chrono::seconds(5));

}  // namespace bbw::dds
