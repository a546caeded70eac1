// Fluid verification studies (src/immerse/verify/FluidStudies.cpp) in their quick form, the wall-bounded flows:
// every check (convergence orders, divergence, solver residuals, steady states) must pass.
#include <gtest/gtest.h>

#include <iostream>

#include "immerse/verify/StudyRunner.hpp"

using namespace immerse::verify;

class FluidStudy : public ::testing::TestWithParam<std::string> {};

TEST_P(FluidStudy, QuickChecksPass) { EXPECT_TRUE(run_study(find_study(GetParam()), true, std::cout)); }

INSTANTIATE_TEST_SUITE_P(Fluid, FluidStudy, ::testing::Values("couette", "duct_poiseuille", "closed_box_mms"));
