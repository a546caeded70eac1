// The rbc_channel scenario (§4.4, Fig. 15) on a coarse grid: 32 cells where Scenario.hpp says, every cell's
// columns and mean_velocity, flow_rate, pressure_drop and relative_viscosity in diagnostics.csv, the fluid starting
// in the discrete Poiseuille flow of the duct (mean velocity = the series value up to O(h^2), relative viscosity 1),
// and the checks of its boundary layout.
#include <gtest/gtest.h>

#include <cmath>

#include "immerse/fluid/ExactSolutions.hpp"
#include "immerse/io/ConfigSchema.hpp"
#include "immerse/scenario/Scenario.hpp"
#include "immerse/simulation/Parameters.hpp"
#include "test_run_support.hpp"

using namespace immerse;
using namespace immerse::testing;

namespace {

const std::vector<std::string> kCoarse{"grid.nx=32",          "grid.ny=64",           "grid.nz=16",
                                       "membrane[0].mesh.level=0", "time.end=9e-4", "output.fields_every=0"};

TEST(RbcChannel, ThirtyTwoCellsInAPoiseuilleDuctWithTheirDiagnostics) {
  ScratchDir dir("channel");
  const auto r = run_immerse(run_args(scenario_file("rbc_channel_quick.toml"), dir / "out", kCoarse), dir / "log");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto rows = read_csv(dir / "out" / "diagnostics.csv");
  ASSERT_EQ(rows.size(), 4u);  // header, steps 0, 1, 2
  const auto& head = rows[0];
  // The membranes' columns, the duct's four, then the energy budget (4 fluid columns, 3 per cell, 2 totals).
  EXPECT_EQ(head[8u + 32u * 14u], "mean_velocity");
  EXPECT_EQ(head[8u + 32u * 14u + 3u], "relative_viscosity");
  EXPECT_EQ(head.back(), "budget_residual");
  EXPECT_EQ(head.size(), 8u + 32u * 14u + 4u + 4u + 32u * 3u + 2u);
  auto column = [&](const std::string& name) {
    const auto it = std::find(head.begin(), head.end(), name);
    EXPECT_NE(it, head.end()) << name;
    return static_cast<std::size_t>(it - head.begin());
  };

  const auto config = apply_scenario(run_schema().parse_file(scenario_file("rbc_channel_quick.toml"), kCoarse));
  ASSERT_EQ(config.count("membrane"), 32u);
  const auto centres = channel_cell_centres(config);
  // Cell m's column `what` ("m7_cx"), built with += (GCC 12 warns falsely on chained string + at -O3).
  auto cell = [&](std::size_t m, const char* what) {
    std::string name = "m";
    name += std::to_string(m);
    name += '_';
    name += what;
    return column(name);
  };
  for (std::size_t m = 0; m < 32; ++m) {
    EXPECT_NEAR(std::stod(rows[1][cell(m, "cx")]), centres[m].x, 1e-12);
    EXPECT_NEAR(std::stod(rows[1][cell(m, "cy")]), centres[m].y, 1e-12);
    EXPECT_NEAR(std::stod(rows[1][cell(m, "cz")]), centres[m].z, 1e-12);
    EXPECT_NEAR(std::stod(rows[1][cell(m, "axial_um")]), 7.82, 1e-9);  // along the flow: the disc's diameter
    EXPECT_EQ(config.entry("membrane", m).get<double>("C10"), 5e-6);      // mu0/2 for every cell
  }
  // Step 0: the cell-free discrete Poiseuille flow, mean velocity = Q / (Lx Lz) of the series (2:1 duct).
  const DuctPoiseuille series{12e-6, 6e-6, 9e4, 4.1e-3};
  const double mean0 = std::stod(rows[1][column("mean_velocity")]), exact = series.flow_rate() / (24e-6 * 12e-6);
  EXPECT_NEAR(mean0 / exact, 1.0, 0.02) << mean0 << " vs " << exact;
  // The flow rate through the 24 x 12 um section, the 9e4 Pa/m body force over the 48 um period, and the cell-free
  // flow's own relative viscosity.
  for (std::size_t row = 1; row < rows.size(); ++row) {
    EXPECT_DOUBLE_EQ(std::stod(rows[row][column("flow_rate")]),
                     std::stod(rows[row][column("mean_velocity")]) * 24e-6 * 12e-6);
    EXPECT_DOUBLE_EQ(std::stod(rows[row][column("pressure_drop")]), 9e4 * 48e-6);
  }
  EXPECT_NEAR(std::stod(rows[1][column("relative_viscosity")]), 1.0, 1e-12);
  // The body force drives the flow (no wall moves) and the fluid dissipates what it puts in, nearly all of it in the
  // Poiseuille flow of step 0 (steady for the cell-free fluid).
  EXPECT_EQ(std::stod(rows[1][column("P_walls")]), 0.0);
  const double power = std::stod(rows[1][column("P_body")]), dissipation = std::stod(rows[1][column("dissipation")]);
  EXPECT_GT(power, 0);
  EXPECT_NEAR(dissipation / power, 1.0, 0.02);
  // The cells are carried downstream (+y) and add dissipation: the mean flow slows.
  EXPECT_GT(std::stod(rows[3][cell(12, "cy")]), centres[12].y);
  EXPECT_LT(std::stod(rows[3][column("mean_velocity")]), mean0);
  const double mean2 = std::stod(rows[3][column("mean_velocity")]);
  EXPECT_NEAR(std::stod(rows[3][column("relative_viscosity")]), mean0 / mean2, 1e-12);
}

// fluid.flow_rate: every step ends at the flow rate, 15 % above the cell-free duct's under the configured force, so
// the first step adds force; as the cells enter the flow the pressure drop rises, and the energy budget takes each
// step's work with the force it added.
TEST(RbcChannel, FlowRateIsHeldWhileThePressureDropRises) {
  ScratchDir dir("channel_flow_rate");
  auto sets = kCoarse;
  sets.push_back("fluid.flow_rate=[0,6e-14,0]");
  sets.push_back("time.end=2.25e-3");
  const auto r = run_immerse(run_args(scenario_file("rbc_channel_quick.toml"), dir / "out", sets), dir / "log");
  ASSERT_EQ(r.status, 0) << r.err;
  const auto rows = read_csv(dir / "out" / "diagnostics.csv");
  ASSERT_EQ(rows.size(), 7u);  // header, steps 0 to 5
  const auto& head = rows[0];
  auto value = [&](std::size_t row, const std::string& name) {
    const auto it = std::find(head.begin(), head.end(), name);
    EXPECT_NE(it, head.end()) << name;
    return std::stod(rows[row][static_cast<std::size_t>(it - head.begin())]);
  };
  EXPECT_NEAR(value(1, "pressure_drop"), 9e4 * 48e-6, 1e-12);  // step 0: the configured force
  double work = 0;  // ∫ P_body dt, by the trapezoidal rule over the rows
  for (std::size_t row = 2; row < rows.size(); ++row) {
    EXPECT_NEAR(value(row, "flow_rate"), 6e-14, 1e-12 * 6e-14) << "step " << row - 1;
    EXPECT_GT(value(row, "pressure_drop"), value(row - 1, "pressure_drop")) << "step " << row - 1;
    work += 0.5 * value(row, "dt") * (value(row - 1, "P_body") + value(row, "P_body"));
    // The scheme's own residual: 0.9 % of the work at step 1 and 0.6 % at step 5 at the constant force.
    EXPECT_LT(std::abs(value(row, "budget_residual")), 2e-2 * work) << "step " << row - 1;
  }
  EXPECT_GT(value(6, "relative_viscosity"), 1.0);
}

TEST(RbcChannel, NeedsWallsAtXAndZAndAPeriodicY) {
  ScratchDir dir("channel_bad");
  auto sets = kCoarse;
  sets.push_back("boundary.y=\"wall\"");
  const auto r = run_immerse(run_args(scenario_file("rbc_channel_quick.toml"), dir / "out", sets), dir / "log");
  EXPECT_EQ(r.status, 2);
  EXPECT_NE(r.err.find("boundary.y"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("\"periodic\" for scenario.kind = \"rbc_channel\""), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out"));
}

}  // namespace
