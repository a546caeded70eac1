// Every mesh verification study, quick form, must pass.
#include <gtest/gtest.h>

#include <iostream>

#include "immerse/verify/MeshStudies.hpp"
#include "immerse/verify/StudyRunner.hpp"

using namespace immerse::verify;

class MeshStudy : public ::testing::TestWithParam<Study> {};

TEST_P(MeshStudy, QuickFormPasses) { EXPECT_TRUE(run_study(GetParam(), true, std::cout)); }

std::string study_name(const ::testing::TestParamInfo<Study>& p) { return p.param.name; }

INSTANTIATE_TEST_SUITE_P(Quick, MeshStudy, ::testing::ValuesIn(mesh_studies()), study_name);

TEST(MeshStudies, AreRegisteredUnderTheirPublicNames) {
  EXPECT_EQ(find_study("mesh_counts").name, "mesh_counts");
  EXPECT_EQ(find_study("sphere_geometry").name, "sphere_geometry");
}
