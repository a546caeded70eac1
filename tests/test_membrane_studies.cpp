// Every quick mechanics study must pass (the same runs `immerse verify NAME --quick` performs).
#include <gtest/gtest.h>

#include <iostream>

#include "immerse/verify/MechanicsStudies.hpp"
#include "immerse/verify/StudyRunner.hpp"

using namespace immerse::verify;

class MechanicsStudy : public ::testing::TestWithParam<Study> {};

TEST_P(MechanicsStudy, QuickRunPasses) { EXPECT_TRUE(run_study(GetParam(), true, std::cout)); }

INSTANTIATE_TEST_SUITE_P(Membrane, MechanicsStudy, ::testing::ValuesIn(mechanics_studies()),
                         [](const ::testing::TestParamInfo<Study>& p) { return p.param.name; });
