// Fluid verification studies (src/immerse/verify/FluidStudies.cpp) in their quick form, the solver checks and the
// periodic flows: every check (convergence orders, divergence, solver residuals, steady states) must pass.
#include <gtest/gtest.h>

#include <iostream>

#include "immerse/verify/Study.hpp"
#include "immerse/verify/StudyRunner.hpp"

using namespace immerse::verify;

class FluidStudy : public ::testing::TestWithParam<std::string> {};

TEST_P(FluidStudy, QuickChecksPass) { EXPECT_TRUE(run_study(find_study(GetParam()), true, std::cout)); }

INSTANTIATE_TEST_SUITE_P(Fluid, FluidStudy,
                         ::testing::Values("fluid_divergence", "fluid_solvers", "taylor_green", "abc_flow"));

TEST(FluidStudies, AllSevenAreRegistered) {
  const auto studies = fluid_studies();
  ASSERT_EQ(studies.size(), 7u);
  for (const auto& s : studies) EXPECT_NO_THROW(find_study(s.name));
}
