// The energy budget (docs/energy-budget.md). FluidEnergy.*: the dissipation and the power of the walls are the
// viscous operator of the step summed by parts (random fields, every combination of periodic axes and moving walls,
// constant and variable viscosity; the sums of slabs are the whole grid's bit for bit); a decaying Taylor-Green
// vortex, whose budget closes at second order in the step; Couette flow, whose walls put in what the fluid dissipates
// once it is steady. EnergyBudgetRun.*: whole runs of a relaxing capsule, whose total energy never rises and whose
// residual falls at second order in the step; a restart into another folder continues the integrals bit for bit, and
// a restart from a checkpoint without them says so and counts from its step.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <map>
#include <numbers>
#include <random>
#include <sstream>
#include <string>
#include <vector>

#include "PetscEnvironment.hpp"
#include "immerse/cli/RunCommand.hpp"
#include "immerse/fluid/ExactSolutions.hpp"
#include "immerse/fluid/FluidDiagnostics.hpp"
#include "immerse/fluid/FluidEnergy.hpp"
#include "immerse/fluid/MacStencil_K.hpp"
#include "immerse/fluid/NavierStokesSolver.hpp"
#include "immerse/fluid/ViscousStress_K.hpp"
#include "immerse/io/Checkpoint.hpp"
#include "immerse/simulation/EnergyBudget.hpp"
#include "test_run_support.hpp"

using namespace immerse;
using namespace immerse::testing;

namespace {

constexpr Boundary P = Boundary::Periodic, W = Boundary::Wall;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

std::string bc_name(const std::array<Boundary, 3>& bc) {
  std::string s;
  for (Boundary b : bc) s += b == P ? 'P' : 'W';
  return s;
}

/// Random wall velocities (the normal one the same at both walls of an axis, as FluidParams requires), body force
/// and χ > −1 at the cells.
struct RandomCase {
  Grid grid;
  FluidParams params;
  FaceField u;
  Array3 chi;
};

RandomCase random_case(const std::array<Boundary, 3>& bc, std::mt19937& rng) {
  std::uniform_real_distribution<double> U(-1, 1);
  const double h = 0.1;
  const std::array<int, 3> n{6, 5, 7};
  RandomCase c{Grid(n, {n[0] * h, n[1] * h, n[2] * h}, bc), {}, {}, {}};
  c.params.rho = 1.3;
  c.params.mu = 0.7;
  c.params.body_force = {U(rng), U(rng), U(rng)};
  for (int a = 0; a < 3; ++a) {
    if (bc[a] == P) continue;
    c.params.wall_lower[a] = {U(rng), U(rng), U(rng)};
    c.params.wall_upper[a] = {U(rng), U(rng), U(rng)};
    c.params.wall_upper[a][a] = c.params.wall_lower[a][a];
  }
  c.u = FaceField(c.grid);
  for (int d = 0; d < 3; ++d) {
    for (double& v : c.u[d].values()) v = U(rng);
    // The wall faces are never read: the operator takes the wall velocity there.
    if (bc[d] == W)
      for (int k = 0; k < c.u[d].nz(); ++k)
        for (int j = 0; j < c.u[d].ny(); ++j)
          for (int i = 0; i < c.u[d].nx(); ++i) {
            const std::array<int, 3> q{i, j, k};
            if (q[d] == 0 || q[d] == n[d]) c.u[d](i, j, k) = kNaN;
          }
  }
  c.chi = Array3(n[0], n[1], n[2]);
  for (double& v : c.chi.values()) v = 1.5 * (U(rng) + 1);
  return c;
}

/// The slab array of planes z0 − 1 … z1 + 1 of a whole-grid array with `planes` planes along z (n_z + 1 for u_z on a
/// wall axis), wrapped on a periodic z, NaN where SlabDecomposition leaves a plane unused or beyond a wall.
Array3 slab_of(const Array3& whole, int z0, int z1, int nz, bool periodic, bool face_z) {
  Array3 s(whole.nx(), whole.ny(), z1 - z0 + 3, kNaN);
  for (int k = 0; k < s.nz(); ++k) {
    int g = z0 - 1 + k;
    if (!periodic && face_z && k == 0) continue;            // u_z on a wall axis: plane z0 − 1 unused
    if (!periodic && !face_z && k == s.nz() - 1) continue;  // cell-centred on a wall axis: plane z1 + 1 unused
    if (periodic) g = (g + nz) % nz;
    if (g < 0 || g >= whole.nz()) continue;
    for (int j = 0; j < s.ny(); ++j)
      for (int i = 0; i < s.nx(); ++i) s(i, j, k) = whole(i, j, g);
  }
  return s;
}

}  // namespace

// Σ u·(L u) h³ over the unknowns, with L the step's viscous operator (μ ∇_h², plus μ ∇_h·(χ S) with a variable
// viscosity), is −dissipation + walls to round-off; E_kinetic and P_body are their sums; the wall faces are never
// read (NaN there). Cut into slabs with ghost planes (NaN where unused), the plane sums add up to the whole grid's.
TEST(FluidEnergy, DissipationAndWallPowerAreTheViscousOperatorSummedByParts) {
  std::mt19937 rng(7);
  int cases = 0;
  for (int b = 0; b < 8; ++b) {
    const std::array<Boundary, 3> bc{b & 1 ? W : P, b & 2 ? W : P, b & 4 ? W : P};
    for (const bool variable : {false, true}) {
      SCOPED_TRACE(bc_name(bc) + (variable ? " variable viscosity" : " constant viscosity"));
      const RandomCase c = random_case(bc, rng);
      const MacStencilGrid g(c.grid, c.params);
      const double h3 = std::pow(c.grid.h(), 3), mu = c.params.mu;
      double operator_sum = 0, kinetic = 0, body = 0;
      for (int d = 0; d < 3; ++d)
        for (int k = g.first(d, 2); k < g.n[2]; ++k)
          for (int j = g.first(d, 1); j < g.n[1]; ++j)
            for (int i = g.first(d, 0); i < g.n[0]; ++i) {
              const mac::Index q{i, j, k};
              const double v = c.u[d](i, j, k);
              double Lu = mu * mac::laplacian_face(c.u[d], g, d, q);
              if (variable) Lu += mu * mac::stress_divergence(c.u, c.chi, g, d, q);
              operator_sum += v * Lu * h3;
              kinetic += 0.5 * c.params.rho * v * v * h3;
              body += c.params.body_force[d] * v * h3;
            }
      const FluidEnergy e = fluid_energy(c.grid, c.params, c.u, variable ? &c.chi : nullptr);
      EXPECT_GT(e.dissipation, 0);
      const double scale = e.dissipation + std::abs(e.walls);
      EXPECT_NEAR(operator_sum, -e.dissipation + e.walls, 1e-13 * scale);
      EXPECT_NEAR(e.kinetic, kinetic, 1e-13 * kinetic);
      EXPECT_NEAR(e.body, body, 1e-13 * scale);
      if (b == 0) {
        EXPECT_EQ(e.walls, 0.0);
      } else {
        EXPECT_GT(std::abs(e.walls), 1e-3 * e.dissipation);
      }

      const int nz = c.grid.n(2);
      const bool periodic = bc[2] == P;
      const std::vector<double> whole =
          fluid_energy_planes(c.grid, c.params, c.u, variable ? &c.chi : nullptr, 0, nz, 0);
      for (const std::vector<int>& cuts : {std::vector<int>{0, 7}, {0, 3, 7}, {0, 1, 2, 5, 7}}) {
        std::vector<double> sum(whole.size(), 0.0);
        for (std::size_t s = 0; s + 1 < cuts.size(); ++s) {
          const int z0 = cuts[s], z1 = cuts[s + 1];
          FaceField us(c.grid);
          for (int d = 0; d < 3; ++d) us[d] = slab_of(c.u[d], z0, z1, nz, periodic, d == 2);
          const Array3 chis = slab_of(c.chi, z0, z1, nz, periodic, false);
          const auto part = fluid_energy_planes(c.grid, c.params, us, variable ? &chis : nullptr, z0, z1, z0 - 1);
          for (std::size_t i = 0; i < sum.size(); ++i) sum[i] += part[i];
        }
        EXPECT_EQ(sum, whole) << cuts.size() - 1 << " slabs";
      }
      ++cases;
    }
  }
  EXPECT_EQ(cases, 16);
}

namespace {

struct TaylorGreenBudget {
  double kinetic0 = 0, kinetic = 0, residual = 0;
  bool decays = true;
};

/// The 2D Taylor-Green vortex (k = 2π in the unit square, extruded over two cells, ν = 0.02) from the exact u(0) and
/// p(−Δt/2) to t = 0.2 in steps of dt, its budget kept by EnergyBudget.
TaylorGreenBudget taylor_green_budget(double dt) {
  const TaylorGreen tg{2 * std::numbers::pi, 1.0, 0.02};
  const int n = 32;
  const Grid grid({n, n, 2}, {1.0, 1.0, 2.0 / n}, {P, P, P});
  FluidParams params;
  params.rho = tg.rho;
  params.mu = tg.mu;
  NavierStokesSolver ns(grid, params, FftPlanning::Estimate);
  FluidState a = ns.initial_state(), b;
  sample_velocity(
      grid, [&](const Vec3& x) { return tg.velocity(x, 0.0); }, a.u);
  sample_pressure(
      grid, [&](const Vec3& x) { return tg.pressure(x, -0.5 * dt); }, a.p);
  const FaceField force(grid);
  EnergyBudget budget;
  FluidEnergy e = fluid_energy(grid, params, a.u, nullptr);
  budget.start(e.kinetic, e);
  TaylorGreenBudget r;
  r.kinetic0 = e.kinetic;
  const int steps = static_cast<int>(std::lround(0.2 / dt));
  for (int s = 0; s < steps; ++s) {
    ns.step(a, force, dt, b);
    std::swap(a, b);
    const FluidEnergy next = fluid_energy(grid, params, a.u, nullptr);
    r.decays = r.decays && next.kinetic < e.kinetic;
    e = next;
    budget.advance(dt, e);
  }
  r.kinetic = e.kinetic;
  r.residual = budget.residual(e.kinetic);
  return r;
}

}  // namespace

// E_kinetic decays as exp(−4νk²t) (the 32² grid's O(h²) error aside), the dissipation (measured, no walls, no body
// force) accounts for it, and the budget's residual, the error of the time discretization and of the trapezoidal
// rule, falls by 4 when the step is halved. Observed: residual / E_kinetic(0) = 1.16e-4, 2.89e-5, 7.24e-6 at
// dt = 0.02, 0.01, 0.005 (E_kinetic(T) / E_kinetic(0) = 0.53279 against exp(-4 nu k^2 T) = 0.53171).
TEST(FluidEnergy, TaylorGreenVortexDecaysAndItsBudgetClosesAtSecondOrder) {
  const double nu = 0.02, k = 2 * std::numbers::pi;
  std::vector<double> relative;
  for (const double dt : {0.02, 0.01, 0.005}) {
    const TaylorGreenBudget r = taylor_green_budget(dt);
    EXPECT_TRUE(r.decays) << "dt = " << dt;
    EXPECT_NEAR(r.kinetic / r.kinetic0, std::exp(-4 * nu * k * k * 0.2), 0.01 * r.kinetic / r.kinetic0);
    relative.push_back(std::abs(r.residual) / r.kinetic0);
    std::printf(
        "[FluidEnergy] Taylor-Green to t = 0.2, dt = %g: E_kinetic(T) / E_kinetic(0) = %.6f (exact %.6f), "
        "budget_residual / E_kinetic(0) = %.3g\n",
        dt, r.kinetic / r.kinetic0, std::exp(-4 * nu * k * k * 0.2), r.residual / r.kinetic0);
  }
  EXPECT_LT(relative[0], 3e-4);
  EXPECT_GT(relative[0] / relative[1], 3.5);
  EXPECT_GT(relative[1] / relative[2], 3.5);
}

// Plane Couette flow between z walls sliding in x and y, started from rest: once steady (the linear profile, which
// the discrete operator holds exactly) the walls put in what the fluid dissipates, μ |ΔU|² A / L, to round-off, the
// kinetic energy stays constant and so does the budget's residual. The residual is made in the first steps, where
// the walls' impulsive start changes the velocity next to them within a step (h² / ν = 0.8 dt): observed 3.9e-3 J
// after the first step, 4.4e-3 J from the third on, against 7.3e-3 J of work of the walls in the first step.
TEST(FluidEnergy, CouetteFlowAtSteadyStateTheWallsPutInWhatTheFluidDissipates) {
  const Grid grid({4, 4, 16}, {0.25, 0.25, 1.0}, {P, P, W});
  FluidParams params;
  params.rho = 1.0;
  params.mu = 0.5;
  params.wall_lower[2] = {-0.5, 0.2, 0.0};
  params.wall_upper[2] = {1.0, -0.3, 0.0};
  NavierStokesSolver ns(grid, params, FftPlanning::Estimate);
  FluidState a = ns.initial_state(), b;
  const FaceField force(grid);
  EnergyBudget budget;
  FluidEnergy e = fluid_energy(grid, params, a.u, nullptr);
  budget.start(e.kinetic, e);
  const double dt = 0.01;
  double early = 0;
  for (int s = 0; s < 1500; ++s) {  // to t = 15: 7.5 times the slowest mode's decay time L² / (π² ν)
    ns.step(a, force, dt, b);
    std::swap(a, b);
    e = fluid_energy(grid, params, a.u, nullptr);
    budget.advance(dt, e);
    if (s == 1000) early = budget.residual(e.kinetic);
  }
  const Vec3 dU = params.wall_upper[2] - params.wall_lower[2];
  const double area = 0.25 * 0.25, steady = params.mu * dot(dU, dU) / 1.0 * area;
  const double residual = budget.residual(e.kinetic);
  std::printf(
      "[FluidEnergy] steady Couette flow: P_walls = %.17g W, dissipation = %.17g W (mu |dU|^2 A / L = %.17g), "
      "budget_residual %.6g J (at t = 10: %.6g J)\n",
      e.walls, e.dissipation, steady, residual, early);
  EXPECT_NEAR(e.walls, e.dissipation, 1e-12 * steady);
  EXPECT_NEAR(e.dissipation, steady, 1e-11 * steady);
  EXPECT_NEAR(residual, early, 1e-12 * budget.walls_work());
  EXPECT_LT(std::abs(residual), 1e-2);
  ns.step(a, force, dt, b);
  const FluidEnergy after = fluid_energy(grid, params, b.u, nullptr);
  EXPECT_NEAR(after.kinetic, e.kinetic, 1e-13 * e.kinetic);
  EXPECT_NEAR(after.walls, e.walls, 1e-12 * steady);
}

namespace {

using Table = std::vector<std::map<std::string, double>>;

/// The rows of a diagnostics.csv by column name.
Table read_table(const fs::path& path) {
  const auto cells = read_csv(path);
  Table rows;
  for (std::size_t r = 1; r < cells.size(); ++r) {
    std::map<std::string, double> row;
    for (std::size_t c = 0; c < cells[0].size(); ++c) row[cells[0][c]] = std::stod(cells[r][c]);
    rows.push_back(row);
  }
  return rows;
}

/// `immerse run` of oscillating_membrane_quick.toml (the stretched capsule relaxing in a closed box) with `sets`,
/// in this process; returns the exit status, the log in `log`.
int run_capsule(const fs::path& out, const std::vector<std::string>& sets, const fs::path& restart = {},
                std::string* log = nullptr) {
  std::ostringstream out_log, err;
  CommandLine o;
  o.file = scenario_file("oscillating_membrane_quick.toml");
  o.sets = sets;
  o.out = out;
  o.restart = restart;
  const int status = run_command(o, out_log, err);
  EXPECT_EQ(err.str(), "");
  if (log) *log = out_log.str();
  return status;
}

}  // namespace

// The capsule of §4.1 (32³, 1,026 nodes, forces −∂E/∂X) relaxing to t = 1: its total energy (fluid and membrane)
// never rises from one row to the next, the columns add up to E_total, and the residual of the budget is the scheme's
// time-step error: observed 1.42e-2 and 3.58e-3 of the initial elastic energy at dt = 1/16 and 1/32.
TEST(EnergyBudgetRun, RelaxingCapsuleLosesEnergyAndItsBudgetClosesAtSecondOrder) {
  ScratchDir dir("budget");
  std::vector<double> relative;
  for (const double dt : {0.0625, 0.03125}) {
    const fs::path out = dir / ("dt" + std::to_string(dt));
    ASSERT_EQ(run_capsule(out, {"time.end=1", "time.dt=" + std::to_string(dt), "membrane[0].force=\"energy\"",
                                "output.fields_every=0", "output.checkpoint_every=0"}),
              0);
    const Table rows = read_table(out / "diagnostics.csv");
    ASSERT_EQ(rows.size(), static_cast<std::size_t>(std::lround(1 / dt)) + 1);
    const double E0 = rows[0].at("E_elastic");
    EXPECT_GT(E0, 0);
    EXPECT_EQ(rows[0].at("budget_residual"), 0.0);
    EXPECT_EQ(rows[0].at("E_kinetic"), 0.0);
    double largest_rise = -1;
    for (std::size_t r = 0; r < rows.size(); ++r) {
      const auto& row = rows[r];
      EXPECT_EQ(row.at("E_bending"), 0.0);
      EXPECT_EQ(row.at("E_constraint"), 0.0);
      EXPECT_EQ(row.at("P_walls"), 0.0);  // walls at rest
      EXPECT_EQ(row.at("P_body"), 0.0);
      EXPECT_NEAR(row.at("E_total"), row.at("E_kinetic") + row.at("E_elastic"), 1e-15 * E0);
      if (r == 0) continue;
      EXPECT_GT(row.at("dissipation"), 0);
      const double rise = row.at("E_total") - rows[r - 1].at("E_total");
      EXPECT_LE(rise, 1e-12 * E0) << "step " << r;
      largest_rise = std::max(largest_rise, rise);
    }
    const double residual = rows.back().at("budget_residual") / E0;
    relative.push_back(std::abs(residual));
    std::printf(
        "[EnergyBudgetRun] capsule to t = 1, dt = %g: E_total from %.6g to %.6g J, largest rise from row to "
        "row %.3g E0, budget_residual / E_elastic(0) = %.3g\n",
        dt, rows[0].at("E_total"), rows.back().at("E_total"), largest_rise / E0, residual);
  }
  EXPECT_LT(relative[0], 2e-2);
  EXPECT_LT(relative[1], 5e-3);
  EXPECT_GT(relative[0] / relative[1], 3.5);
}

// A run of 8 steps against 4 steps and a restart of its checkpoint into another folder (a new series from step 4):
// the energy columns of steps 4 to 8 are bit for bit the uninterrupted run's, volume and area constraints included.
// The same checkpoint with its energy entries removed (as one written before they existed) restarts with the
// integrals at zero, which one log line says: the residual then counts from step 4.
TEST(EnergyBudgetRun, RestartContinuesTheIntegralsAndAnOlderCheckpointCountsFromItsStep) {
  ScratchDir dir("budget_restart");
  const auto sets = [](int steps) {
    auto s = small_membrane_sets(steps);
    s.insert(s.end(), {"membrane[0].force=\"energy\"", "membrane[0].volume_modulus=5", "membrane[0].area_modulus=0.1"});
    return s;
  };
  ASSERT_EQ(run_capsule(dir / "whole", sets(8)), 0);
  ASSERT_EQ(run_capsule(dir / "half", sets(4)), 0);
  const io::Checkpoint half = io::Checkpoint::read(dir / "half" / "checkpoint.h5");
  ASSERT_EQ(half.get_int("step"), 4);
  for (const auto& [name, value] : EnergyBudget().entries()) EXPECT_TRUE(half.has(name)) << name;
  std::string log;
  ASSERT_EQ(run_capsule(dir / "branch", sets(8), dir / "half" / "checkpoint.h5", &log), 0);
  EXPECT_EQ(log.find("energy budget"), std::string::npos) << log;

  const auto whole = read_csv(dir / "whole" / "diagnostics.csv");
  const auto branch = read_csv(dir / "branch" / "diagnostics.csv");
  ASSERT_EQ(whole.size(), 10u);  // header, steps 0 to 8
  ASSERT_EQ(branch.size(), 6u);  // header, steps 4 to 8
  ASSERT_EQ(branch[0], whole[0]);
  const auto first =
      static_cast<std::size_t>(std::find(whole[0].begin(), whole[0].end(), "E_kinetic") - whole[0].begin());
  ASSERT_EQ(whole[0].back(), "budget_residual");
  for (std::size_t r = 1; r < branch.size(); ++r)
    for (std::size_t c = first; c < whole[0].size(); ++c)
      EXPECT_EQ(branch[r][c], whole[r + 4][c]) << whole[0][c] << " at step " << r + 3;
  const Table rows = read_table(dir / "whole" / "diagnostics.csv");
  EXPECT_GT(rows.back().at("E_constraint"), 0);
  EXPECT_NE(rows[4].at("budget_residual"), 0.0);

  io::Checkpoint older = half;
  for (const auto& [name, value] : EnergyBudget().entries()) older.erase(name);
  fs::create_directories(dir / "older");
  older.write(dir / "older" / "checkpoint.h5");
  ASSERT_EQ(run_capsule(dir / "from_older", sets(8), dir / "older" / "checkpoint.h5", &log), 0);
  const auto note = log.find("# energy budget: ");
  ASSERT_NE(note, std::string::npos) << log;
  EXPECT_EQ(log.find("# energy budget: ", note + 1), std::string::npos) << log;
  EXPECT_NE(log.find("start again at its step 4, t = 0.5\n", note), std::string::npos) << log;
  const Table restarted = read_table(dir / "from_older" / "diagnostics.csv");
  ASSERT_EQ(restarted.size(), 5u);
  EXPECT_EQ(restarted[0].at("budget_residual"), 0.0);
  for (std::size_t r = 0; r < restarted.size(); ++r)
    EXPECT_NEAR(restarted[r].at("budget_residual"), rows[r + 4].at("budget_residual") - rows[4].at("budget_residual"),
                1e-14 * rows[0].at("E_total"))
        << "step " << r + 4;
}
