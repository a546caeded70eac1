// The capsule_constriction scenario through `immerse run`: the flow rate held through the constriction at every step,
// the capsule carried into the throat and squeezed there (its extent across the throat below the throat's width,
// its length along the channel grown, its volume kept), the walls written for ParaView, and bad input about the
// constriction (exit 2, one line, nothing written).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "test_run_support.hpp"

using namespace immerse;
using namespace immerse::testing;

namespace {

// The quick scenario (20 steps, 0.5 ms) with the capsule started 2a before the throat's centre, its front at the
// throat's entry: the flow rate held at every step, the capsule carried on and drawn into the throat (narrower across
// it, longer along the channel), its volume kept, and the pressure gradient rising as it plugs the throat.
TEST(CapsuleConstriction, CapsuleIsDrawnIntoTheThroatAtTheFlowRate) {
  ScratchDir dir("capsule_constriction");
  const auto r = run_immerse(run_args(scenario_file("capsule_constriction_quick.toml"), dir / "out",
                                      {"membrane[0].center=[1.5e-5,1.25e-5,1.25e-5]"}),
                             dir / "log");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto rows = read_csv(dir / "out" / "diagnostics.csv");
  ASSERT_GE(rows.size(), 22u);  // header, steps 0 .. 20 or more (a step the implicit solve rejects is halved)
  const auto& head = rows[0];
  const auto value = [&](std::size_t row, const std::string& name) { return std::stod(rows[row][column(head, name)]); };
  EXPECT_NEAR(value(rows.size() - 1, "time"), 5e-4, 1e-12);
  EXPECT_NEAR(value(1, "throat_position"), -1e-5, 1e-9);
  EXPECT_NEAR(value(1, "length_y"), 1e-5, 1e-7);
  for (std::size_t i = 2; i < rows.size(); ++i) {
    EXPECT_NEAR(value(i, "flow_rate") / 4e-13, 1.0, 1e-9) << i;
    EXPECT_GT(value(i, "throat_position"), value(i - 1, "throat_position")) << i;
  }
  const std::size_t last = rows.size() - 1;
  std::printf(
      "after 0.5 ms: centroid %.3f a from the throat's centre, l_x/2a = %.4f, l_y/2a = %.4f, l_z/2a = %.4f, "
      "pressure gradient %.4g Pa/m (%.4g after the first step)\n",
      value(last, "throat_position") / 5e-6, value(last, "length_x") / 1e-5, value(last, "length_y") / 1e-5,
      value(last, "length_z") / 1e-5, value(last, "pressure_gradient"), value(2, "pressure_gradient"));
  EXPECT_LT(value(last, "length_y"), 0.99e-5);  // drawn into the throat
  EXPECT_GT(value(last, "length_x"), 1.01e-5);  // and out along the channel
  EXPECT_EQ(value(last, "in_throat"), 0.0);
  EXPECT_GT(value(last, "pressure_gradient"), value(2, "pressure_gradient"));
  EXPECT_NEAR(value(last, "volume") / value(1, "volume"), 1.0, 0.01);
  const std::string walls = read_text(dir / "out" / "walls.xdmf");
  EXPECT_NE(walls.find("<Attribute Name=\"wall\""), std::string::npos);
}

struct BadConstriction {
  std::string name;
  std::vector<std::string> sets;
  std::string message;
};

void PrintTo(const BadConstriction& b, std::ostream* os) { *os << b.name; }

class CapsuleConstrictionBadInput : public ::testing::TestWithParam<BadConstriction> {};

TEST_P(CapsuleConstrictionBadInput, ExitsWithStatus2AndOneLineBeforeWritingAnything) {
  const BadConstriction& b = GetParam();
  ScratchDir dir("constriction_bad_" + b.name);
  const auto r =
      run_immerse(run_args(scenario_file("capsule_constriction_quick.toml"), dir / "out", b.sets), dir / "log");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find(b.message), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out"));
}

INSTANTIATE_TEST_SUITE_P(
    Walls, CapsuleConstrictionBadInput,
    ::testing::Values(
        BadConstriction{"axis_not_a_coordinate_axis",
                        {"wall[0].axis=[1,1,0]"},
                        "wall[0].axis = [1, 1, 0]: a constriction's channel runs along a coordinate axis"},
        BadConstriction{"throat_wider_than_the_channel",
                        {"wall[0].throat=[1e-5,2.2e-5,2e-5]"},
                        "wall[0].throat = [1e-05, 2.2e-05, 2e-05]: wider than the channel"},
        BadConstriction{
            "throat_as_long_as_the_box", {"wall[0].throat=[5e-5,1e-5,2e-5]"}, "the throat's length along x"},
        BadConstriction{"flow_across_the_channel",
                        {"fluid.flow_rate=[0,4e-13,0]"},
                        "scenario.kind = \"capsule_constriction\" holds a flow rate along the constriction's axis"},
        BadConstriction{"not_a_constriction",
                        {"wall[0].shape=\"box\"", "wall[0].inside=\"fluid\""},
                        "wall[0].shape: must be \"constriction\" for scenario.kind = \"capsule_constriction\""},
        BadConstriction{"key_of_another_shape",
                        {"wall[0].radius=1e-6"},
                        "wall[0].radius: does not apply to shape = \"constriction\" (its keys: axis, center, size, "
                        "throat)"},
        BadConstriction{"capsule_in_the_throat_s_frame",
                        {"membrane[0].center=[2.5e-5,5e-6,1.25e-5]", "membrane[0].radius=1e-6",
                         "membrane[0].reference_radius=1e-6"},
                        "membrane[0] starts inside a [[wall]]"}),
    [](const ::testing::TestParamInfo<BadConstriction>& p) { return p.param.name; });

}  // namespace
