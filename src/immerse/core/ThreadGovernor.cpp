#include "immerse/core/ThreadGovernor.hpp"

#include <omp.h>
#include <sched.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace immerse {

namespace {

/// The quota in CPUs of the cgroup (v2 "cpu.max", v1 "cpu.cfs_quota_us"/"cpu.cfs_period_us") at `dir` and its
/// ancestors below `root`, the smallest one found; 0 when none is set.
double cgroup_quota(const std::string& root, std::string dir, bool v2) {
  double quota = 0;
  while (true) {
    double q = 0;
    if (v2) {
      std::ifstream in(root + dir + "/cpu.max");
      std::string max;
      double period = 0;
      if (in >> max >> period && max != "max" && period > 0) q = std::strtod(max.c_str(), nullptr) / period;
    } else {
      std::ifstream a(root + dir + "/cpu.cfs_quota_us"), b(root + dir + "/cpu.cfs_period_us");
      double us = 0, period = 0;
      if (a >> us && b >> period && us > 0 && period > 0) q = us / period;
    }
    if (q > 0) quota = quota > 0 ? std::min(quota, q) : q;
    if (dir.empty() || dir == "/") break;
    dir = dir.substr(0, dir.find_last_of('/'));
  }
  return quota;
}

}  // namespace

int AvailableCpus::count() const {
  int n = std::max(affinity, 1);
  if (quota > 0) n = std::min(n, static_cast<int>(std::ceil(quota - 1e-9)));
  return std::max(n, 1);
}

AvailableCpus AvailableCpus::of_this_process() {
  AvailableCpus c;
  cpu_set_t set;
  CPU_ZERO(&set);
  c.affinity = sched_getaffinity(0, sizeof(set), &set) == 0 ? CPU_COUNT(&set) : omp_get_num_procs();
  // /proc/self/cgroup: "0::/path" (v2) or "N:cpu,cpuacct:/path" (v1).
  std::ifstream in("/proc/self/cgroup");
  std::string line;
  while (std::getline(in, line)) {
    const auto a = line.find(':'), b = line.find(':', a + 1);
    if (a == std::string::npos || b == std::string::npos) continue;
    const std::string controllers = line.substr(a + 1, b - a - 1), path = line.substr(b + 1);
    if (controllers.empty()) {
      c.quota = cgroup_quota("/sys/fs/cgroup", path, true);
    } else if (("," + controllers + ",").find(",cpu,") != std::string::npos) {
      for (const char* root : {"/sys/fs/cgroup/cpu,cpuacct", "/sys/fs/cgroup/cpu"}) {
        const double q = cgroup_quota(root, path, false);
        if (q > 0) c.quota = q;
      }
    }
    if (c.quota > 0) break;
  }
  return c;
}

std::string AvailableCpus::describe() const {
  std::ostringstream s;
  s << count() << (count() == 1 ? " CPU" : " CPUs") << ": affinity " << affinity << ", ";
  if (quota > 0)
    s << "cgroup quota " << quota;
  else
    s << "no cgroup quota";
  return s.str();
}

ThreadGovernor::ThreadGovernor() : max_(omp_get_max_threads()) {}

ThreadGovernor ThreadGovernor::adaptive(int max_threads) {
  ThreadGovernor g;
  g.max_ = std::max(max_threads, 1);
  g.adaptive_ = g.max_ > 1;
  g.current_ = g.running_ = g.adaptive_ ? 1 : 0;
  return g;
}

ThreadGovernor ThreadGovernor::from_environment() {
  const char* env = std::getenv("OMP_NUM_THREADS");
  if (env != nullptr && *env != '\0') return ThreadGovernor();
  const int cpus = AvailableCpus::of_this_process().count();
  omp_set_num_threads(cpus);
  return cpus > 1 ? adaptive(cpus) : ThreadGovernor();
}

std::string ThreadGovernor::oversubscription_warning() {
  const char* env = std::getenv("OMP_NUM_THREADS");
  if (env == nullptr) return "";
  const long threads = std::strtol(env, nullptr, 10);  // "4,2" (nested levels): the outer count
  const int cpus = AvailableCpus::of_this_process().count();
  if (threads <= 2L * cpus) return "";
  std::ostringstream s;
  s << "OMP_NUM_THREADS = " << threads << " but " << cpus << (cpus == 1 ? " CPU is" : " CPUs are")
    << " available: the threads will wait for each other on every step and the run will be much slower than with "
    << "OMP_NUM_THREADS = " << cpus << " (or unset: chosen by measurement)";
  return s.str();
}

std::size_t ThreadGovernor::initial_samples(int i) const {
  return i == 0 ? count_[0] : count_[1] - std::min(count_[1], kWarmup);
}

int ThreadGovernor::choose() {
  if (!adaptive_) return omp_get_max_threads();
  int i = current_;
  if (seen_ < kWarmup)
    i = 1;
  else if (initial_samples(1) < kInitialSamples || initial_samples(0) < kInitialSamples)
    i = initial_samples(1) <= initial_samples(0) ? 1 : 0;  // alternate until both have their samples
  else if (seen_ >= next_probe_)
    i = 1 - current_;
  running_ = i;
  omp_set_num_threads(threads_of(i));
  return threads_of(i);
}

void ThreadGovernor::record(double seconds) {
  if (!adaptive_) {
    ++count_[index(omp_get_max_threads())];
    return;
  }
  ++count_[running_];
  ++seen_;
  if (seen_ <= kWarmup) return;
  double& est = estimate_[running_];
  if (const std::size_t n = initial_samples(running_); n <= kInitialSamples) {
    // The first measurements of each count, averaged (one alone is at the mercy of the scheduler); then run on
    // the cheaper.
    est += (seconds - est) / static_cast<double>(n);
    if (initial_samples(0) >= kInitialSamples && initial_samples(1) >= kInitialSamples) {
      current_ = estimate_[0] <= estimate_[1] ? 0 : 1;
      at_decision_ = estimate_[current_];
      next_probe_ = seen_ + probe_interval();
    }
    return;
  }
  if (running_ == current_) {
    est = 0.8 * est + 0.2 * seconds;
    if (est > kJump * at_decision_ && next_probe_ > seen_) {
      interval_ = kFirstInterval;
      next_probe_ = seen_;
    }
    return;
  }
  est = seconds;  // a probe: a fresh measurement replaces an estimate that may be old
  if (seconds < kSwitch * estimate_[current_]) {
    current_ = running_;
    ++switches_;
    interval_ = kFirstInterval;
  } else {
    interval_ = std::min(2 * interval_, kMaxInterval);
  }
  at_decision_ = estimate_[current_];
  next_probe_ = seen_ + probe_interval();
}

std::size_t ThreadGovernor::probe_interval() const {
  // A probe costs the difference of the two estimates; spacing probes by (ratio - 1) / kProbeShare evaluations
  // keeps their cost below that share of the run's time.
  const double ratio = estimate_[1 - current_] / estimate_[current_];
  const double budget = std::isfinite(ratio) && ratio > 1 ? std::ceil((ratio - 1) / kProbeShare) : 0.0;
  return std::max(interval_, static_cast<std::size_t>(std::min(budget, double(kMaxInterval))));
}

std::string ThreadGovernor::policy() const {
  std::ostringstream s;
  if (!adaptive_)
    s << max_ << " (fixed" << (std::getenv("OMP_NUM_THREADS") ? " by OMP_NUM_THREADS" : "") << ")";
  else
    s << "1 or " << max_ << ", chosen by measurement (" << AvailableCpus::of_this_process().describe() << ")";
  return s.str();
}

std::string ThreadGovernor::summary() const {
  std::ostringstream s;
  const std::size_t total = count_[0] + count_[1];
  s << "threads: " << policy();
  if (!adaptive_) return s.str();
  if (total > 0) {
    const double one = 100.0 * static_cast<double>(count_[0]) / static_cast<double>(total);
    s.precision(3);
    s << ": 1 thread for " << one << " % of " << total << " evaluations, " << max_ << " for " << 100.0 - one
      << " %, " << switches_ << (switches_ == 1 ? " switch" : " switches");
  }
  return s.str();
}

}  // namespace immerse
