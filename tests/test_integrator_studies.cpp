// The quick forms of the §4.1 integrator studies (Table 1 orders, stability at dt = 4 dx, solver agreement).
#include <gtest/gtest.h>

#include <iostream>

#include "PetscEnvironment.hpp"
#include "immerse/verify/StudyRunner.hpp"

using namespace immerse::verify;

class IntegratorStudy : public ::testing::TestWithParam<std::string> {};

TEST_P(IntegratorStudy, QuickFormPasses) { EXPECT_TRUE(run_study(find_study(GetParam()), true, std::cout)); }

INSTANTIATE_TEST_SUITE_P(Studies, IntegratorStudy,
                         ::testing::Values("oscillating_time_order", "oscillating_stability", "theta_ringing",
                                           "quasi_newton_agreement"));
