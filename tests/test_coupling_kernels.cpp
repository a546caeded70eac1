// Discrete delta kernels (paper eqs. 7–8) and the coupling verification studies.
#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "immerse/core/Error.hpp"
#include "immerse/coupling/DeltaKernel.hpp"
#include "immerse/verify/Study.hpp"
#include "immerse/verify/StudyRunner.hpp"

using namespace immerse;

TEST(DeltaKernel, SelectedByName) {
  EXPECT_EQ(kernel_name(delta_kernel("roma3")), "roma3");
  EXPECT_EQ(kernel_name(delta_kernel("peskin4")), "peskin4");
  EXPECT_EQ(kernel_width(delta_kernel("roma3")), 3);
  EXPECT_EQ(kernel_width(delta_kernel("peskin4")), 4);
  try {
    delta_kernel("cosine");
    FAIL() << "no InputError";
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "coupling.kernel = 'cosine': must be one of roma3, peskin4");
  }
}

TEST(DeltaKernel, PointValuesOfEq8AndPeskin4) {
  EXPECT_NEAR(roma3_phi(0.0), 2.0 / 3.0, 1e-16);
  EXPECT_NEAR(roma3_phi(0.5), 0.5, 1e-16);
  EXPECT_NEAR(roma3_phi(-1.0), 1.0 / 6.0, 1e-16);
  EXPECT_EQ(roma3_phi(1.5), 0.0);
  EXPECT_EQ(roma3_phi(-7.0), 0.0);
  EXPECT_NEAR(peskin4_phi(0.0), 0.5, 1e-16);
  EXPECT_NEAR(peskin4_phi(-1.0), 0.25, 1e-16);
  EXPECT_EQ(peskin4_phi(2.0), 0.0);
}

TEST(DeltaKernel, ContinuousAcrossTheBranchPoints) {
  for (const double r : {0.5, 1.5}) EXPECT_NEAR(roma3_phi(r - 1e-12), roma3_phi(r + 1e-12), 1e-11) << r;
  for (const double r : {1.0, 2.0}) EXPECT_NEAR(peskin4_phi(r - 1e-12), peskin4_phi(r + 1e-12), 1e-11) << r;
}

TEST(DeltaKernel, ThreeDimensionalDeltaIsTheScaledTensorProduct) {
  // Eq. (7): Σ over a lattice of spacing h of D_h(x − X) h³ = 1 for any X.
  const DeltaKernel k = RomaPeskin3{};
  const double h = 0.1;
  const Vec3 X{0.0123, -0.047, 0.031};
  double sum = 0;
  for (int i = -3; i <= 3; ++i)
    for (int j = -3; j <= 3; ++j)
      for (int l = -3; l <= 3; ++l) sum += delta_h(k, Vec3{i * h, j * h, l * h} - X, h) * h * h * h;
  EXPECT_NEAR(sum, 1.0, 1e-14);
  EXPECT_NEAR(delta_h(k, {0, 0, 0}, h), std::pow(2.0 / 3.0, 3) / (h * h * h), 1e-10);
}

class CouplingStudy : public ::testing::TestWithParam<verify::Study> {};

TEST_P(CouplingStudy, QuickFormPasses) { EXPECT_TRUE(verify::run_study(GetParam(), true, std::cout)); }

INSTANTIATE_TEST_SUITE_P(Coupling, CouplingStudy, ::testing::ValuesIn(verify::coupling_studies()),
                         [](const auto& i) { return i.param.name; });

TEST(CouplingStudies, AllThreeAreRegistered) {
  for (const char* name : {"delta_moments", "ib_adjointness", "ib_interpolation_order"})
    EXPECT_EQ(verify::find_study(name).name, name);
}
