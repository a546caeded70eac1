#pragma once
// The memory a process may use: the smallest of the machine's physical memory, what the address-space limit
// (ulimit -v) leaves beside the address space already mapped, and the memory limit of its cgroup (v2 memory.max,
// v1 memory.limit_in_bytes) and the cgroup's ancestors; and the peak resident memory a run reports at its end.
// Verified by the tests MemoryLimits.* and BadInputMemory.GridBeyondTheAddressSpaceLimitIsRefused.
#include <optional>
#include <string>
#include <vector>

namespace immerse {

struct MemoryLimit {
  double bytes;
  std::string what;  ///< e.g. "this machine's memory (25.3 GB)"
};

/// "4.19 GB".
std::string gigabytes(double bytes);

/// The smallest memory limit of the cgroup at `dir` (relative to the hierarchy mounted at `root`) and its ancestors,
/// read from `file` ("max", or a value of 1e18 bytes or more, meaning none).
std::optional<MemoryLimit> cgroup_memory_limit(const std::string& root, std::string dir, const std::string& file);

/// Every limit that applies to this process (physical memory, ulimit -v, cgroups); the smallest is the one to keep.
std::vector<MemoryLimit> memory_limits();

/// The largest resident memory of this process so far (VmHWM of /proc/self/status), in bytes; empty where the
/// system does not report it.
std::optional<double> peak_resident_bytes();

}  // namespace immerse
