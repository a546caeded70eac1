#pragma once
// How many OpenMP threads the coupled step uses, chosen by measurement.
//
// Every result of immerse is bitwise independent of the thread count (the reproducibility tests), so the count may
// change between two evaluations of the coupled residual without changing the run. The adaptive policy uses that:
// it times each evaluation, keeps a running estimate of its cost on one thread and on all available threads, and
// runs on whichever is cheaper, probing the other now and then: at intervals that double while it keeps losing and
// are long enough for the losing probes to cost at most 2 % of the time, and at once when the cost of the current
// choice jumps (e.g. when another process starts sharing the cores). Small
// problems, and any problem on cores shared with other work, so never run slower than on one thread for long; large
// problems on idle cores use them all.
//
// The fixed policy (OMP_NUM_THREADS set, or a single available CPU) leaves OpenMP's thread count alone.
//
// Checked by tests/test_thread_governor.cpp and measured by bench/threads.py (docs/performance.md, "Threads").
#include <cstddef>
#include <string>

namespace immerse {

/// The CPUs this process may use: its CPU affinity mask (as set by taskset, numactl or an MPI launcher's binding),
/// reduced to the cgroup CPU quota (cpu.max of cgroup v2, cfs_quota_us / cfs_period_us of v1) rounded up.
struct AvailableCpus {
  int affinity = 1;     ///< CPUs in the affinity mask
  double quota = 0;     ///< cgroup CPU quota in CPUs (0: none)
  int count() const;    ///< min(affinity, ceil(quota)), at least 1
  static AvailableCpus of_this_process();
  std::string describe() const;  ///< e.g. "2 CPUs: affinity 2, no cgroup quota"
};

class ThreadGovernor {
 public:
  /// Fixed at OpenMP's current thread count: choose() never changes it.
  ThreadGovernor();
  /// Adaptive between 1 and max_threads (>= 2) threads.
  static ThreadGovernor adaptive(int max_threads);
  /// The default for a run: fixed when OMP_NUM_THREADS is set (the user's explicit count) or when only one CPU is
  /// available; otherwise adaptive up to the available CPUs.
  static ThreadGovernor from_environment();
  /// A warning when OMP_NUM_THREADS asks for more than twice the available CPUs (the threads of every parallel loop
  /// then wait for each other), "" otherwise.
  static std::string oversubscription_warning();

  /// Sets OpenMP's thread count for the next evaluation (omp_set_num_threads) and returns it.
  int choose();
  /// Reports the wall time of the evaluation run with the count choose() returned last.
  void record(double seconds);

  bool is_adaptive() const { return adaptive_; }
  int max_threads() const { return max_; }
  /// Evaluations run with one thread and with max_threads so far.
  std::size_t evaluations(int threads) const { return threads == 1 ? count_[0] : count_[1]; }
  /// The policy: "2 (fixed by OMP_NUM_THREADS)" or "1 or 2, chosen by measurement (2 CPUs: ...)".
  std::string policy() const;
  /// One line for the run's summary: the policy and how the evaluations were spread over the thread counts.
  std::string summary() const;

  // Tuning, exposed for the tests.
  static constexpr std::size_t kWarmup = 2;          ///< first evaluations not timed (first touch of the buffers)
  static constexpr std::size_t kInitialSamples = 2; ///< evaluations of each count averaged before the first choice
  static constexpr std::size_t kFirstInterval = 8;   ///< evaluations between probes after a switch
  static constexpr std::size_t kMaxInterval = 1024;  ///< longest interval between probes
  static constexpr double kSwitch = 0.9;             ///< a probe wins when it costs less than this times the estimate
  static constexpr double kProbeShare = 0.02;       ///< at most this share of the time spent on losing probes
  static constexpr double kJump = 1.5;               ///< a cost this much above the estimate at the last decision
                                                     ///< brings the next probe forward

 private:
  int index(int threads) const { return threads == 1 ? 0 : 1; }
  int threads_of(int i) const { return i == 0 ? 1 : max_; }
  std::size_t probe_interval() const;
  std::size_t initial_samples(int i) const;  ///< timed evaluations of count index i so far

  bool adaptive_ = false;
  int max_ = 1;
  int current_ = 1;           // index of the current choice: 0 one thread, 1 max_
  int running_ = 1;           // index the last choose() returned
  double estimate_[2] = {0, 0};  // seconds per evaluation (0: not measured yet)
  double at_decision_ = 0;    // estimate of the current choice when it was last confirmed
  std::size_t count_[2] = {0, 0};
  std::size_t seen_ = 0;          // evaluations recorded
  std::size_t next_probe_ = 0;    // evaluation index of the next probe
  std::size_t interval_ = kFirstInterval;
  std::size_t switches_ = 0;
};

}  // namespace immerse
