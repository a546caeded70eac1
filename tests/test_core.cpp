#include <gtest/gtest.h>

#include "immerse/core/Error.hpp"
#include "immerse/core/Mat3.hpp"
#include "immerse/grid/Grid.hpp"

using namespace immerse;

TEST(Mat3, InverseTimesMatrixIsIdentity) {
  Mat3 m = Mat3::from_rows({2, 1, 0.5}, {-1, 3, 0.25}, {0.1, 0.2, 4});
  Mat3 p = inverse(m) * m;
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) EXPECT_NEAR(p(i, j), i == j ? 1.0 : 0.0, 1e-15);
}

TEST(Grid, RejectsNonCubicCellsAndBadCounts) {
  const std::array<Boundary, 3> per{Boundary::Periodic, Boundary::Periodic, Boundary::Periodic};
  EXPECT_THROW(Grid({8, 8, 8}, {1, 1, 2}, per), InputError);
  EXPECT_THROW(Grid({0, 8, 8}, {1, 1, 1}, per), InputError);
  EXPECT_THROW(Grid({8, 8, 8}, {-1, 1, 1}, per), InputError);
  try {
    Grid({1, 8, 8}, {1, 1, 1}, per);
    FAIL();
  } catch (const InputError& e) {
    EXPECT_STREQ(e.what(), "grid.nx = 1: must be an integer >= 2");
  }
}

TEST(Grid, FaceLayoutFollowsBoundaries) {
  Grid g({4, 8, 2}, {1, 2, 0.5}, {Boundary::Periodic, Boundary::Wall, Boundary::Periodic});
  EXPECT_DOUBLE_EQ(g.h(), 0.25);
  EXPECT_EQ(g.face_shape(0), (std::array<int, 3>{4, 8, 2}));
  EXPECT_EQ(g.face_shape(1), (std::array<int, 3>{4, 9, 2}));
  const Vec3 p = g.face_position(1, 1, 8, 0);
  EXPECT_DOUBLE_EQ(p.x, 0.375);
  EXPECT_DOUBLE_EQ(p.y, 2.0);
  EXPECT_DOUBLE_EQ(p.z, 0.125);
}
