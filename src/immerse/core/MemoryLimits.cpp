#include "immerse/core/MemoryLimits.hpp"

#include <sys/resource.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <fstream>
#include <iomanip>
#include <sstream>

namespace immerse {

std::string gigabytes(double bytes) {
  std::ostringstream s;
  s << std::setprecision(3) << std::max(bytes, 0.0) / 1e9 << " GB";
  return s.str();
}

std::optional<MemoryLimit> cgroup_memory_limit(const std::string& root, std::string dir, const std::string& file) {
  std::optional<MemoryLimit> limit;
  while (true) {
    std::ifstream in(root + dir + "/" + file);
    std::string text;
    if (in >> text && text != "max") {
      const double bytes = std::strtod(text.c_str(), nullptr);
      if (bytes > 0 && bytes < 1e18 && (!limit || bytes < limit->bytes))
        limit = MemoryLimit{bytes, "the cgroup memory limit (" + gigabytes(bytes) + ", " + root + dir + "/" + file + ")"};
    }
    if (dir.empty() || dir == "/") break;
    dir = dir.substr(0, dir.find_last_of('/'));
  }
  return limit;
}

std::vector<MemoryLimit> memory_limits() {
  std::vector<MemoryLimit> limits;
  if (const double memory = double(sysconf(_SC_PHYS_PAGES)) * double(sysconf(_SC_PAGESIZE)); memory > 0)
    limits.push_back({memory, "this machine's memory (" + gigabytes(memory) + ")"});
  if (rlimit as{}; getrlimit(RLIMIT_AS, &as) == 0 && as.rlim_cur != RLIM_INFINITY) {
    double mapped_pages = 0;
    std::ifstream("/proc/self/statm") >> mapped_pages;
    const double left = double(as.rlim_cur) - mapped_pages * double(sysconf(_SC_PAGESIZE));
    limits.push_back({left, "the " + gigabytes(left) + " that the address-space limit (ulimit -v = " +
                                gigabytes(double(as.rlim_cur)) + ") leaves this process"});
  }
  // /proc/self/cgroup: "0::/path" (v2) or "N:...memory...:/path" (v1).
  std::ifstream in("/proc/self/cgroup");
  for (std::string line; std::getline(in, line);) {
    const auto a = line.find(':'), b = line.find(':', a + 1);
    if (a == std::string::npos || b == std::string::npos) continue;
    const std::string controllers = line.substr(a + 1, b - a - 1), path = line.substr(b + 1);
    std::optional<MemoryLimit> limit;
    if (controllers.empty())
      limit = cgroup_memory_limit("/sys/fs/cgroup", path, "memory.max");
    else if (("," + controllers + ",").find(",memory,") != std::string::npos)
      limit = cgroup_memory_limit("/sys/fs/cgroup/memory", path, "memory.limit_in_bytes");
    if (limit) limits.push_back(*limit);
  }
  return limits;
}

std::optional<double> peak_resident_bytes() {
  std::ifstream in("/proc/self/status");
  for (std::string line; std::getline(in, line);)
    if (line.rfind("VmHWM:", 0) == 0) {
      std::istringstream value(line.substr(6));
      double kilobytes = 0;
      if (value >> kilobytes) return kilobytes * 1024.0;
    }
  return std::nullopt;
}

}  // namespace immerse
