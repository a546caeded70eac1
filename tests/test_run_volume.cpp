// The volume correction in a run: the immersed boundary method leaks volume at every step (the interpolated
// velocity is not exactly divergence-free); with volume_correction = "normal_shift" the diagnostics' volume is the
// initial one to round-off after every step.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "test_run_support.hpp"

using namespace immerse::testing;

namespace {

/// The volume column of diagnostics.csv, one value per row (step 0 first).
std::vector<double> volumes(const fs::path& csv) {
  const auto rows = read_csv(csv);
  const auto column = std::find(rows.at(0).begin(), rows.at(0).end(), "volume") - rows.at(0).begin();
  std::vector<double> v;
  for (std::size_t r = 1; r < rows.size(); ++r) v.push_back(std::stod(rows[r].at(std::size_t(column))));
  return v;
}

}  // namespace

TEST(RunVolume, NormalShiftRestoresTheInitialVolumeAfterEveryStepOfALeakingRun) {
  ScratchDir dir("volume");
  const fs::path file = scenario_file("oscillating_membrane_quick.toml");
  const auto sets = small_membrane_sets(4);
  auto with = sets;
  with.push_back("membrane[0].volume_correction=\"normal_shift\"");
  ASSERT_EQ(run_immerse(run_args(file, dir / "leaking", sets), dir / "leaking").status, 0);
  const auto r = run_immerse(run_args(file, dir / "corrected", with), dir / "corrected");
  ASSERT_EQ(r.status, 0) << r.err;

  const auto leaking = volumes(dir / "leaking" / "diagnostics.csv"), corrected = volumes(dir / "corrected" / "diagnostics.csv");
  ASSERT_EQ(leaking.size(), 5u);
  ASSERT_EQ(corrected.size(), 5u);
  const double V0 = leaking[0];
  EXPECT_EQ(corrected[0], V0);
  EXPECT_GT(std::abs(leaking.back() - V0), 1e-8 * V0);  // the leak the correction undoes
  for (std::size_t n = 1; n < corrected.size(); ++n) EXPECT_LT(std::abs(corrected[n] - V0), 1e-12 * V0) << "step " << n;
}
