// The thread governor runs each evaluation on the cheaper thread count, spends little on probing the other, follows
// a change of costs (another process starting to share the cores), and leaves an explicit OMP_NUM_THREADS alone.
#include <gtest/gtest.h>
#include <omp.h>

#include <cstdlib>
#include <functional>

#include "immerse/core/ThreadGovernor.hpp"

using namespace immerse;

namespace {

/// Feeds `evaluations` evaluations whose cost is cost(threads, index) and returns the total simulated seconds.
double drive(ThreadGovernor& g, int evaluations, const std::function<double(int, int)>& cost) {
  double total = 0;
  for (int e = 0; e < evaluations; ++e) {
    const int t = g.choose();
    EXPECT_EQ(omp_get_max_threads(), t);
    const double s = cost(t, e);
    total += s;
    g.record(s);
  }
  return total;
}

/// Restores OpenMP's thread count after a test that lets the governor change it.
struct KeepThreadCount {
  int saved = omp_get_max_threads();
  ~KeepThreadCount() { omp_set_num_threads(saved); }
};

}  // namespace

TEST(ThreadGovernor, RunsOnOneThreadWhenTwoAreSlowerAndProbesRarely) {
  KeepThreadCount keep;
  auto g = ThreadGovernor::adaptive(2);
  // Two threads 8 times slower (a core busy with another process): the cost over 600 evaluations stays within 10 %
  // of the one-thread cost although every probe pays the factor 8.
  const double total = drive(g, 600, [](int t, int) { return t == 1 ? 1e-3 : 8e-3; });
  EXPECT_LT(total, 1.1 * 600 * 1e-3);
  EXPECT_GT(g.evaluations(1), 580u);
  EXPECT_EQ(g.evaluations(1) + g.evaluations(2), 600u);
}

TEST(ThreadGovernor, RunsOnAllThreadsWhenTheyAreFaster) {
  KeepThreadCount keep;
  auto g = ThreadGovernor::adaptive(2);
  const double total = drive(g, 600, [](int t, int) { return t == 1 ? 2e-3 : 1.1e-3; });
  EXPECT_LT(total, 1.05 * 600 * 1.1e-3);
  EXPECT_GT(g.evaluations(2), 590u);
}

TEST(ThreadGovernor, FollowsACostThatChangesDuringTheRun) {
  KeepThreadCount keep;
  auto g = ThreadGovernor::adaptive(2);
  // Idle cores for 2,000 evaluations (two threads twice as fast), then another process takes a core (two threads
  // six times slower than one), then the cores are idle again.
  auto cost = [](int t, int e) {
    const bool busy = e >= 2000 && e < 4000;
    return t == 1 ? 2e-3 : (busy ? 12e-3 : 1e-3);
  };
  drive(g, 2000, cost);
  const auto two_before = g.evaluations(2);
  EXPECT_GT(two_before, 1950u);
  drive(g, 2000, [&](int t, int e) { return cost(t, e + 2000); });
  // The jump of the estimate brings the next probe forward: two threads are left within a few evaluations.
  EXPECT_LT(g.evaluations(2) - two_before, 30u);
  const auto one_before = g.evaluations(1);
  drive(g, 2000, [&](int t, int e) { return cost(t, e + 4000); });
  // Back to two threads once a probe finds them faster again (probes at most 1024 evaluations apart).
  EXPECT_LT(g.evaluations(1) - one_before, 1100u);
  EXPECT_GT(g.evaluations(2), two_before + 800u);
}

TEST(ThreadGovernor, FixedPolicyLeavesTheThreadCountAlone) {
  KeepThreadCount keep;
  omp_set_num_threads(3);
  ThreadGovernor g;
  EXPECT_FALSE(g.is_adaptive());
  for (int e = 0; e < 20; ++e) {
    EXPECT_EQ(g.choose(), 3);
    g.record(1e-3);
  }
  EXPECT_EQ(omp_get_max_threads(), 3);
  EXPECT_EQ(g.evaluations(3), 20u);
}

TEST(ThreadGovernor, AnExplicitOmpNumThreadsFixesTheCount) {
  KeepThreadCount keep;
  const char* old = std::getenv("OMP_NUM_THREADS");
  const std::string saved = old ? old : "";
  setenv("OMP_NUM_THREADS", "2", 1);
  omp_set_num_threads(2);
  const auto g = ThreadGovernor::from_environment();
  EXPECT_FALSE(g.is_adaptive());
  EXPECT_EQ(g.max_threads(), 2);
  EXPECT_NE(g.summary().find("fixed by OMP_NUM_THREADS"), std::string::npos) << g.summary();
  unsetenv("OMP_NUM_THREADS");
  const auto h = ThreadGovernor::from_environment();
  EXPECT_EQ(h.is_adaptive(), AvailableCpus::of_this_process().count() > 1);
  EXPECT_EQ(h.max_threads(), AvailableCpus::of_this_process().count());
  if (old) setenv("OMP_NUM_THREADS", saved.c_str(), 1);
}

TEST(AvailableCpus, TheCgroupQuotaRoundedUpLimitsTheAffinity) {
  EXPECT_EQ((AvailableCpus{4, 0}.count()), 4);
  EXPECT_EQ((AvailableCpus{4, 1.0}.count()), 1);
  EXPECT_EQ((AvailableCpus{4, 1.5}.count()), 2);
  EXPECT_EQ((AvailableCpus{2, 8.0}.count()), 2);
  EXPECT_EQ((AvailableCpus{2, 0.2}.count()), 1);
  const auto here = AvailableCpus::of_this_process();
  EXPECT_GE(here.affinity, 1);
  EXPECT_GE(here.count(), 1);
  EXPECT_LE(here.count(), here.affinity);
}
