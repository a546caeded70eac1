// The tube_flow scenario: walls of any shape through `immerse run` — Poiseuille's flow rate in its columns, the energy
// budget at the steady state, a bitwise restart, and bad input about walls (exit 2, one line, nothing written).
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

#include "test_run_support.hpp"

using namespace immerse;
using namespace immerse::testing;

namespace {

TEST(TubeFlow, ScenarioReachesPoiseuilleFlowRate) {
  ScratchDir dir("tube_flow");
  const auto r =
      run_immerse(run_args(scenario_file("tube_flow.toml"), dir / "out", {"output.fields_every=0"}), dir / "log");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto rows = read_csv(dir / "out" / "diagnostics.csv");
  ASSERT_EQ(rows.size(), 32u);  // header, steps 0, 10, ..., 300
  const auto& head = rows[0];
  const auto& last = rows.back();
  const double q = std::stod(last[column(head, "flow_rate")]);
  const double exact = std::stod(last[column(head, "poiseuille_flow_rate")]);
  const double mu_app = std::stod(last[column(head, "relative_viscosity")]);
  EXPECT_NEAR(exact, M_PI * 1e5 * std::pow(4e-6, 4) / (8 * 1.2e-3), 1e-25);
  EXPECT_NEAR(q / exact, 1.0, 0.01);  // +0.09 % at D = 16h
  EXPECT_NEAR(mu_app * q / exact, 1.0, 1e-12);
  // Steady: the body force's work is the dissipation, and the kinetic energy no longer changes.
  const double body = std::stod(last[column(head, "P_body")]), diss = std::stod(last[column(head, "dissipation")]);
  EXPECT_NEAR(diss / body, 1.0, 1e-6);
  const auto& before = rows[rows.size() - 2];
  EXPECT_NEAR(std::stod(before[column(head, "flow_rate")]) / q, 1.0, 1e-9);
  // The wall for ParaView: the tube's cylinder over one period, 51 points around (2πR/h) by 5 rings.
  const std::string walls = read_text(dir / "out" / "walls.xdmf");
  EXPECT_NE(walls.find("<Topology TopologyType=\"Triangle\" NumberOfElements=\"408\">"), std::string::npos);
  EXPECT_NE(walls.find("<Attribute Name=\"wall\""), std::string::npos);
}

// fluid.initial = "poiseuille" in a tube: the steady flow of the cut-cell step from step 0 (the flow rate of the run
// from rest at its end, and unchanged by the steps).
TEST(TubeFlow, PoiseuilleInitialFlowIsTheSteadyState) {
  ScratchDir dir("tube_poiseuille");
  const auto r = run_immerse(run_args(scenario_file("tube_flow.toml"), dir / "out",
                                      {"fluid.initial=\"poiseuille\"", "time.end=4e-6", "output.diagnostics_every=1",
                                       "output.fields_every=0"}),
                             dir / "log");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto rows = read_csv(dir / "out" / "diagnostics.csv");
  ASSERT_EQ(rows.size(), 12u);
  const std::size_t q = column(rows[0], "flow_rate");
  for (std::size_t i = 1; i < rows.size(); ++i)
    EXPECT_NEAR(std::stod(rows[i][q]) / 8.3854166666660729e-15, 1.0, 1e-11) << i;  // the run from rest at t = 0.12 ms
}

// fluid.flow_rate along the tube: every step ends at the flow rate through the tube, and the steady state is the one
// the body force of tube_flow.toml reaches (the step is linear in the force), so the same apparent viscosity.
TEST(TubeFlow, FlowRateIsHeldThroughTheTube) {
  ScratchDir dir("tube_flow_rate");
  const auto r = run_immerse(run_args(scenario_file("tube_flow.toml"), dir / "out",
                                      {"fluid.body_force=[0,0,0]", "fluid.flow_rate=[0,0,8.385416666666e-15]",
                                       "output.fields_every=0"}),
                             dir / "log");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto rows = read_csv(dir / "out" / "diagnostics.csv");
  ASSERT_EQ(rows.size(), 32u);
  const auto& head = rows[0];
  for (std::size_t i = 2; i < rows.size(); ++i)
    EXPECT_NEAR(std::stod(rows[i][column(head, "flow_rate")]) / 8.385416666666e-15, 1.0, 1e-12) << i;
  EXPECT_NEAR(std::stod(rows.back()[column(head, "relative_viscosity")]), 0.9990654898, 1e-8);
}

TEST(TubeFlow, RestartContinuesBitwise) {
  ScratchDir dir("tube_restart");
  const std::vector<std::string> sets{"output.fields_every=0", "output.checkpoint_every=20", "time.end=1.6e-5"};
  auto half = sets;
  half.back() = "time.end=8e-6";
  ASSERT_EQ(run_immerse(run_args(scenario_file("tube_flow.toml"), dir / "whole", sets), dir / "a").status, 0);
  ASSERT_EQ(run_immerse(run_args(scenario_file("tube_flow.toml"), dir / "half", half), dir / "b").status, 0);
  const auto r = run_immerse(
      run_args(scenario_file("tube_flow.toml"), dir / "rest", sets, dir / "half" / "checkpoint.h5"), dir / "c");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto whole = without_wall_clock(read_csv(dir / "whole" / "diagnostics.csv"));
  const auto rest = without_wall_clock(read_csv(dir / "rest" / "diagnostics.csv"));
  ASSERT_GE(rest.size(), 2u);
  EXPECT_EQ(rest.back(), whole.back());
}

struct BadWall {
  std::string name;
  std::vector<std::string> sets;
  std::string message;
};

void PrintTo(const BadWall& b, std::ostream* os) { *os << b.name; }

class TubeFlowBadInput : public ::testing::TestWithParam<BadWall> {};

TEST_P(TubeFlowBadInput, ExitsWithStatus2AndOneLineBeforeWritingAnything) {
  const BadWall& b = GetParam();
  ScratchDir dir("tube_bad_" + b.name);
  fs::path file = scenario_file("tube_flow.toml");
  if (b.name == "membrane_inside_wall" || b.name == "membrane_near_wall") {
    file = dir / "tube_cell.toml";
    std::ofstream f(file);
    f << read_text(scenario_file("tube_flow.toml"))
      << "\n[[membrane]]\nshape = \"sphere\"\nradius = 4e-7\nmesh.level = 1\n"
      << (b.name == "membrane_inside_wall" ? "center = [5e-7, 5e-7, 1e-6]\n" : "center = [5e-6, 1.6e-6, 1e-6]\n");
  }
  if (b.name.rfind("surface_", 0) == 0) {
    // The tube replaced by a closed-or-not surface of tetrahedra (µm), written here.
    const auto facet = [](std::ostream& o, Vec3 p, Vec3 q, Vec3 c) {
      o << "facet normal 0 0 0\nouter loop\n";
      for (const Vec3& v : {p, q, c}) o << "vertex " << v.x << " " << v.y << " " << v.z << "\n";
      o << "endloop\nendfacet\n";
    };
    const auto tetra = [&](std::ostream& o, Vec3 q, bool all) {
      const Vec3 a = q, e = q + Vec3{2, 0, 0}, c = q + Vec3{0, 2, 0}, d = q + Vec3{0, 0, 1};
      facet(o, a, c, e);
      facet(o, a, e, d);
      facet(o, a, d, c);
      if (all) facet(o, e, c, d);
    };
    std::ofstream stl(dir / "wall.stl");
    stl << "solid w\n";
    tetra(stl, {4, 4, 0.5}, b.name != "surface_open");
    if (b.name == "surface_self_intersecting") tetra(stl, {4.5, 4.5, 0.7}, true);
    stl << "endsolid w\n";
    stl.close();
    std::string text = read_text(scenario_file("tube_flow.toml"));
    text = text.substr(0, text.find("\n[[wall]]") + 1);
    text.replace(text.find("kind = \"tube_flow\""), 18, "kind = \"custom\"");
    file = dir / "surface.toml";
    std::ofstream(file) << text << "[[wall]]\nshape = \"surface\"\nfile = \"wall.stl\"\nscale = 1e-6\n";
  }
  const auto r = run_immerse(run_args(file, dir / "out", b.sets), dir / "log");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find(b.message), std::string::npos) << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out"));
}

INSTANTIATE_TEST_SUITE_P(Walls, TubeFlowBadInput,
                         ::testing::Values(BadWall{"wall_axis_not_periodic",
                                                   {"boundary.z=\"wall\""},
                                                   "boundary.z = \"wall\": [[wall]] needs a box periodic along "
                                                   "every axis"},
                                           BadWall{"tube_does_not_close",
                                                   {"wall[0].axis=[0.1234567,0,1]"},
                                                   "wall[0].axis = [0.123457, 0, 1]: a tube must close on itself "
                                                   "across the box"},
                                           BadWall{"tube_meets_its_image",
                                                   {"wall[0].radius=5.5e-6"},
                                                   "wall[0].radius = 5.5e-06: the tube meets its periodic image"},
                                           BadWall{"wall_outside_the_box",
                                                   {"wall[0].center=[5e-6,5e-6,3e-6]"},
                                                   "wall[0].center = [5e-06, 5e-06, 3e-06]: must lie in the box"},
                                           BadWall{"tube_flow_without_a_tube",
                                                   {"wall[0].shape=\"sphere\"", "wall[0].radius=1e-6"},
                                                   "wall[0].shape: must be \"tube\" for scenario.kind = "
                                                   "\"tube_flow\""},
                                           BadWall{"flow_rate_across_the_tube",
                                                   {"fluid.flow_rate=[1e-15,0,0]"},
                                                   "fluid.flow_rate.x: the [[wall]] shapes leave the fluid no path "
                                                   "across the box along x"},
                                           BadWall{"surface_open", {}, "/wall.stl: the surface is open: edge"},
                                           BadWall{"surface_self_intersecting", {}, "intersect: the surface crosses itself"},
                                           BadWall{"membrane_inside_wall", {}, "membrane[0] starts inside a [[wall]]"},
                                           BadWall{"membrane_near_wall", {}, "membrane[0] comes within"}),
                         [](const ::testing::TestParamInfo<BadWall>& p) { return p.param.name; });

}  // namespace
