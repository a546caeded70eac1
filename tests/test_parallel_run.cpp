// Tests of a whole coupled run distributed over MPI (DistributedSimulation, DistributedOperator), run by ctest through
// mpiexec with 1, 2, 3 and 4 processes (tests ParallelRun.np1 … np4).
//
// The quick red-cell channel (scenarios/rbc_channel_quick.toml: 48 x 96 x 24 cells, walls along x and z, periodic y,
// 32 biconcave cells of 642 nodes, Yeoh law, body force, contact within one grid spacing) with the explicit midpoint
// RK2 scheme at dt = kDt, and with forward Euler for a few steps: the positions gathered from the processes equal the
// one-process Simulation of the same configuration (on rank 0) within 1e-10 relative, and so do the velocity field
// and its mean along the flow; the distributed run repeated gives the same bits. The implicit schemes JFNK, Anderson
// and L-BFGS (PETSc MPI vectors) take the same iterations at every step as the one-process run, with positions within
// 1e-10 and the stored guess errors of the initial guess close to the one-process ones. Along z the 24 cell planes give
// slabs of 12/12 planes on 2 processes, 8/8/8 on 3 and 6/6/6/6 on 4: the middle layer of cells lies at z = Lz/2, on
// the slab boundary of 2 and 4 processes, where cells change owner as they move. The same channel with λ = 5 cells
// and the volume correction (normal shift) checks the distributed viscosity contrast and the shift of the owned cells.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "MpiEnvironment.hpp"  // first: MPI starts before PETSc and ends after it
#include "PetscEnvironment.hpp"
#include "immerse/contact/ContactForce.hpp"
#include "immerse/core/Error.hpp"
#include "immerse/membrane/VolumeAreaConstraint.hpp"
#include "immerse/parallel/Communicator.hpp"
#include "immerse/scenario/Scenario.hpp"
#include "immerse/simulation/ConfigSetup.hpp"
#include "immerse/simulation/DistributedSimulation.hpp"
#include "immerse/simulation/MembraneSet.hpp"
#include "immerse/simulation/Parameters.hpp"
#include "immerse/simulation/Simulation.hpp"
#include "immerse/timestep/GuessErrorPredictor.hpp"

using namespace immerse;

namespace {

// A step of the explicit scheme well inside its stability limit on this channel (see docs/parallel.md).
constexpr double kDt = 2e-5;
#if defined(__SANITIZE_ADDRESS__)
// Under the sanitizers (some thirty times slower) the same comparisons over fewer steps; the optimized build takes
// the 20 steps of the goal.
constexpr int kRk2Steps = 3;
constexpr int kEulerSteps = 2;
constexpr int kContactSteps = 2;
constexpr int kViscositySteps = 2;
#else
constexpr int kRk2Steps = 20;
constexpr int kEulerSteps = 5;
constexpr int kContactSteps = 10;
constexpr int kViscositySteps = 8;
#endif
// The implicit schemes at the same step, with a Newton tolerance tight enough that every step iterates (at 1e-8 the
// extrapolated guess already meets it at this step) and the guess errors the initial guess is corrected by are not
// zero. The six cells that change owner on 2 and 4 processes do so in the first step, with X^{n-1} (the guess
// errors, which move the same way, are checked in ParallelCoupling.MigrationMovesMembranesToTheirNewOwners).
constexpr double kImplicitDt = kDt;
const std::string kImplicitTolerance = "solver.newton_rtol=1e-11";
#if defined(__SANITIZE_ADDRESS__)
constexpr int kJfnkSteps = 2;  // the second step's guess uses X^{n-1} of the cells that changed owner in the first
constexpr int kAndersonSteps = 2;
constexpr int kLbfgsSteps = 2;
constexpr int kHalvingSteps = 3;
#else
constexpr int kJfnkSteps = 20;
constexpr int kAndersonSteps = 10;
constexpr int kLbfgsSteps = 5;
constexpr int kHalvingSteps = 6;
#endif

io::Config channel(const std::string& scheme, int steps, const std::vector<std::string>& more = {}, double dt = kDt) {
  char step[32], end[32];
  std::snprintf(step, sizeof step, "%.12g", dt);
  std::snprintf(end, sizeof end, "%.12g", steps * dt);
  std::vector<std::string> sets{"time.scheme=\"" + scheme + "\"", std::string("time.dt=") + step,
                                std::string("time.end=") + end};
  sets.insert(sets.end(), more.begin(), more.end());
  return apply_scenario(
      run_schema().parse_file(std::string(IMMERSE_SOURCE_DIR) + "/scenarios/rbc_channel_quick.toml", sets));
}

double seconds_since(std::chrono::steady_clock::time_point t0) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
}

struct DistributedResult {
  std::vector<std::vector<Vec3>> positions;
  FluidState fluid;
  int migrations = 0;
  double seconds = 0;
  double chi_max = 0;  // the largest |χ| of the last trial over the processes (0 without a viscosity contrast)
};

DistributedResult run_distributed(const io::Config& config, int steps) {
  const auto t0 = std::chrono::steady_clock::now();
  DistributedSimulation sim(config, Communicator::world());
  for (int s = 0; s < steps; ++s) sim.advance();
  EXPECT_EQ(sim.step(), steps);
  double chi_max = 0;
  for (const double v : sim.op().viscosity_indicator().values()) chi_max = std::max(chi_max, std::abs(v));
  const std::vector<double> all = Communicator::world().all_gather(std::vector<double>{chi_max});
  return {sim.gather_positions(), sim.gather_fluid_state(), sim.migrations(), seconds_since(t0),
          *std::ranges::max_element(all)};
}

double max_abs(const Array3& a) {
  double m = 0;
  for (double v : a.values()) m = std::max(m, std::abs(v));
  return m;
}

double mean(const Array3& a) {
  double s = 0;
  for (double v : a.values()) s += v;
  return s / static_cast<double>(a.values().size());
}

// The distributed run against the serial one and itself; prints the differences on rank 0. Returns the distributed
// result (on every process).
DistributedResult compare_with_serial(const std::string& scheme, int steps, const std::vector<std::string>& more = {}) {
  const Communicator comm = Communicator::world();
  const io::Config config = channel(scheme, steps, more);
  const DistributedResult a = run_distributed(config, steps);
  const DistributedResult b = run_distributed(config, steps);
  // Bitwise repetition, on every process.
  bool same = a.positions.size() == b.positions.size();
  for (std::size_t m = 0; m < a.positions.size() && same; ++m) {
    same = a.positions[m].size() == b.positions[m].size();
    for (std::size_t i = 0; i < a.positions[m].size() && same; ++i)
      for (int k = 0; k < 3; ++k) same = same && a.positions[m][i][k] == b.positions[m][i][k];
  }
  for (int d = 0; d < 3; ++d) same = same && a.fluid.u[d].values() == b.fluid.u[d].values();
  EXPECT_TRUE(same) << "the repeated run differs";
  EXPECT_EQ(a.migrations, b.migrations);
  // The middle layer starts on the slab boundary of 2 and 4 processes: some of its cells change owner.
  if (comm.size() == 2 || comm.size() == 4) {
    EXPECT_GT(a.migrations, 0);
  }
  if (comm.rank() != 0) return a;

  const auto t0 = std::chrono::steady_clock::now();
  Simulation serial(config);
  const std::vector<std::vector<Vec3>> start = [&] {
    std::vector<std::vector<Vec3>> X;
    for (std::size_t m = 0; m < serial.num_membranes(); ++m) X.push_back(serial.op().membrane_positions(m));
    return X;
  }();
  for (int s = 0; s < steps; ++s) serial.advance([](const std::string&) {});
  const double serial_seconds = seconds_since(t0);
  EXPECT_EQ(serial.num_membranes(), a.positions.size());
  if (serial.num_membranes() != a.positions.size()) return a;
  EXPECT_NEAR(serial.time(), steps * kDt, 1e-12 * kDt);

  // Positions: relative to the largest coordinate, and the displacements relative to the largest displacement.
  double x_max = 0, dx = 0, moved = 0, d_moved = 0;
  for (std::size_t m = 0; m < serial.num_membranes(); ++m) {
    const auto X = serial.op().membrane_positions(m);
    EXPECT_EQ(X.size(), a.positions[m].size());
    if (X.size() != a.positions[m].size()) return a;
    for (std::size_t i = 0; i < X.size(); ++i) {
      x_max = std::max(x_max, norm(X[i]));
      dx = std::max(dx, norm(a.positions[m][i] - X[i]));
      moved = std::max(moved, norm(X[i] - start[m][i]));
      d_moved = std::max(d_moved, norm((a.positions[m][i] - start[m][i]) - (X[i] - start[m][i])));
    }
  }
  // The velocity field and its mean along the flow (y).
  const FluidState& f = serial.op().fluid_state();
  double u_max = 0, du = 0;
  for (int d = 0; d < 3; ++d) {
    u_max = std::max(u_max, max_abs(f.u[d]));
    EXPECT_EQ(f.u[d].values().size(), a.fluid.u[d].values().size());
    if (f.u[d].values().size() != a.fluid.u[d].values().size()) return a;
    for (std::size_t i = 0; i < f.u[d].values().size(); ++i)
      du = std::max(du, std::abs(a.fluid.u[d].values()[i] - f.u[d].values()[i]));
  }
  const double mean_serial = mean(f.u[1]), mean_distributed = mean(a.fluid.u[1]);
  std::printf(
      "[ParallelRun] %s%s, %d steps of %g s on %d processes: positions %.2e (relative to the largest "
      "coordinate), displacements %.2e (relative to the largest, %.3e m), velocity %.2e (relative to the "
      "largest), mean u_y %.6e m/s vs %.6e m/s (relative difference %.2e); cells that changed owner: %d; "
      "distributed %.1f s per run, serial %.1f s\n",
      scheme.c_str(), more.empty() ? "" : (" " + more[0]).c_str(), steps, kDt, comm.size(), dx / x_max,
      d_moved / moved, moved, du / u_max, mean_distributed, mean_serial, std::abs(mean_distributed - mean_serial) / std::abs(mean_serial), a.migrations, a.seconds,
      serial_seconds);
  EXPECT_GT(moved, 0.0);
  EXPECT_LE(dx / x_max, 1e-10);
  EXPECT_LE(d_moved / moved, 1e-10);
  EXPECT_LE(du / u_max, 1e-10);
  EXPECT_LE(std::abs(mean_distributed - mean_serial), 1e-10 * std::abs(mean_serial));
  EXPECT_GT(mean_serial, 0.0);  // the body force drives the flow along +y
  return a;
}

}  // namespace

TEST(ParallelRun, RedCellChannelRk2EqualsTheOneProcessRun) { compare_with_serial("rk2", kRk2Steps); }

TEST(ParallelRun, RedCellChannelEulerEqualsTheOneProcessRun) { compare_with_serial("euler", kEulerSteps); }

// The flow rate held by the force each step adds (fluid.flow_rate): its mean over the slabs, summed over the processes.
TEST(ParallelRun, RedCellChannelAtAFlowRateEqualsTheOneProcessRun) {
  compare_with_serial("rk2", kEulerSteps, {"fluid.flow_rate=[0,6e-14,0]"});
}

// Contact between the layers of cells: with a range of 1.5 um (3 h) the nodes of the cells of neighbouring layers,
// owned by different processes on 2, 3 and 4 processes, and those of the outer layers and the walls repel each other
// from the first step on.
TEST(ParallelRun, RedCellChannelWithContactAcrossProcessesEqualsTheOneProcessRun) {
  const std::string range = "contact.range=1.5e-6";
  const io::Config config = channel("rk2", kContactSteps, {range});
  const Communicator comm = Communicator::world();
  if (comm.rank() == 0) {
    // The pairs of nodes of different membranes within the range at the start, and those whose membranes have
    // different owners (the slab of the centroid, B cell planes per process).
    const Simulation start(config);
    std::vector<std::size_t> offsets{0};
    std::vector<Vec3> X;
    std::vector<int> owner;
    const Grid& g = start.grid();
    const int block = (g.n(2) + comm.size() - 1) / comm.size();
    for (std::size_t m = 0; m < start.num_membranes(); ++m) {
      const auto Xm = start.op().membrane_positions(m);
      X.insert(X.end(), Xm.begin(), Xm.end());
      offsets.push_back(X.size());
      Vec3 c{};
      for (const Vec3& x : Xm) c = c + x;
      c = c / double(Xm.size());
      owner.push_back(std::clamp(int(std::floor((c.z - g.origin().z) / g.h())), 0, g.n(2) - 1) / block);
    }
    ContactForce contact(g, {1.5e-6, 1.0, false, {}}, offsets, std::vector<double>(offsets.size() - 1, 1.0));
    const auto near = contact.neighbours(X);
    std::size_t pairs = 0, across = 0;
    for (std::size_t i = 0; i < X.size(); ++i) {
      const auto a = std::upper_bound(offsets.begin(), offsets.end(), i) - offsets.begin() - 1;
      for (std::size_t j : near[i]) {
        const auto b = std::upper_bound(offsets.begin(), offsets.end(), j) - offsets.begin() - 1;
        ++pairs;
        if (owner[std::size_t(a)] != owner[std::size_t(b)]) ++across;
      }
    }
    std::printf("[ParallelRun] %s: %zu node pairs of different membranes in range at the start, %zu of membranes of "
                "different processes\n",
                range.c_str(), pairs / 2, across / 2);
    EXPECT_GT(pairs, 0U);
    if (comm.size() > 1) {
      EXPECT_GT(across, 0U);
    }
  }
  compare_with_serial("rk2", kContactSteps, {range});
}

// Red cells with a viscous interior, λ = 5 (every cell: the scenario copies membrane[0]), and their volume restored by
// the normal shift after every step: the indicator at each stage's midpoint, the variable-viscosity fluid step and
// the shift of the owned cells.
TEST(ParallelRun, RedCellChannelWithViscosityContrastAndVolumeCorrectionEqualsTheOneProcessRun) {
  const std::vector<std::string> sets{"membrane[0].viscosity_ratio=5.0",
                                      "membrane[0].volume_correction=\"normal_shift\""};
  const DistributedResult a = compare_with_serial("rk2", kViscositySteps, sets);
  EXPECT_NEAR(a.chi_max, 4.0, 1e-12);  // λ − 1 inside the cells
  if (Communicator::world().rank() != 0) return;
  // Every cell of the distributed run keeps its initial volume.
  const io::Config config = channel("rk2", kViscositySteps, sets);
  const MembraneSet set = build_membrane_set(config, run_grid(config), nullptr);
  ASSERT_EQ(set.meshes.size(), a.positions.size());
  double error = 0;
  for (std::size_t m = 0; m < a.positions.size(); ++m) {
    ASSERT_TRUE(set.corrected_volume[m].has_value());
    const double V = surface_gradients(set.meshes[m].elements, a.positions[m], false).volume;
    error = std::max(error, std::abs(V - *set.corrected_volume[m]) / *set.corrected_volume[m]);
  }
  std::printf("[ParallelRun] viscosity contrast: largest |chi| %.6f, largest relative volume error %.2e\n", a.chi_max,
              error);
  EXPECT_LE(error, 1e-12);
}

namespace {

// The implicit schemes: per accepted step what the solver did, which must be the one-process run's.
struct StepCounts {
  double dt = 0;
  int rejected = 0, newton = 0, gmres = 0;
  std::size_t solves = 0;
  bool operator==(const StepCounts&) const = default;
};

struct ImplicitResult {
  std::vector<std::vector<Vec3>> positions;
  FluidState fluid;
  std::vector<StepCounts> counts;
  std::vector<double> guess_errors;  // those GuessErrorPredictor holds at the end, oldest first, in membrane order
  int migrations = 0;
  double seconds = 0;
};

ImplicitResult run_implicit_distributed(const io::Config& config, int steps) {
  const auto t0 = std::chrono::steady_clock::now();
  DistributedSimulation sim(config, Communicator::world());
  ImplicitResult r;
  for (int s = 0; s < steps; ++s) {
    const StepRecord rec = sim.advance();
    r.counts.push_back({rec.dt, rec.rejected, rec.stats.newton_its, rec.stats.gmres_its, rec.stats.fluid_solves});
  }
  r.positions = sim.gather_positions();
  r.fluid = sim.gather_fluid_state();
  const GuessErrorPredictor& errors = sim.integrator().guess_errors();
  const std::vector<double> e = errors.errors();
  const std::size_t n = sim.op().size();
  for (std::size_t k = 0; k < errors.count(); ++k) {
    const std::vector<Vec3> all =
        sim.op().ownership().gather({reinterpret_cast<const Vec3*>(e.data() + k * n), n / 3});
    for (const Vec3& v : all) r.guess_errors.insert(r.guess_errors.end(), {v[0], v[1], v[2]});
  }
  r.migrations = sim.migrations();
  r.seconds = seconds_since(t0);
  return r;
}

std::string totals(const std::vector<StepCounts>& c) {
  int newton = 0, gmres = 0, rejected = 0;
  std::size_t solves = 0;
  for (const StepCounts& s : c) {
    newton += s.newton;
    gmres += s.gmres;
    rejected += s.rejected;
    solves += s.solves;
  }
  return std::to_string(newton) + " nonlinear and " + std::to_string(gmres) + " GMRES iterations, " +
         std::to_string(solves) + " fluid solves, " + std::to_string(rejected) + " rejected";
}

// Agreement with the one-process run beyond the positions' 1e-10 (relative to the largest coordinate): of the
// displacements and the velocity (relative to the largest), and of the stored guess errors (relative to the largest).
struct Tolerances {
  double displacement, guess_error;
};
// Anderson and L-BFGS combine values of g: the round-off of the distributed sums stays round-off.
constexpr Tolerances kRoundOff{1e-10, 1e-7};
// JFNK differentiates g by finite differences (eq. 37): a position differing in its last bit changes the rounding of
// X + eps y, by about ulp(X) / (eps |y_i|) ~ 1e-6 of each component of the product (|X| ~ 100 h, eps ~ 2e-6 h over
// 6e4 unknowns). The Newton corrections then differ by that fraction, the converged positions by about 1e-9 of the
// displacement, the guess errors (the corrections beyond the extrapolation) by about 1e-6.
constexpr Tolerances kFiniteDifference{1e-8, 1e-5};

// An implicit scheme distributed against the one-process Simulation: positions and velocities within 1e-10, the
// same steps and iteration counts, and the same bits when repeated.
// Returns the steps rejected (on rank 0, of the one-process run; 0 elsewhere).
int compare_implicit_with_serial(const std::string& scheme, int steps, const Tolerances& tol,
                                 const std::string& also = "") {
  const double dt = kImplicitDt;
  std::vector<std::string> more{kImplicitTolerance};
  if (!also.empty()) more.push_back(also);
  const Communicator comm = Communicator::world();
  // time.end one step beyond: every step has the same dt (the recurrence of the initial guess needs that).
  const io::Config config = channel(scheme, steps + 1, more, dt);
  const ImplicitResult a = run_implicit_distributed(config, steps);
  const ImplicitResult b = run_implicit_distributed(config, steps);
  EXPECT_EQ(a.positions.size(), b.positions.size());
  for (std::size_t m = 0; m < a.positions.size() && m < b.positions.size(); ++m)
    for (std::size_t i = 0; i < a.positions[m].size(); ++i)
      for (int k = 0; k < 3; ++k) EXPECT_EQ(a.positions[m][i][k], b.positions[m][i][k]) << "membrane " << m;
  for (int d = 0; d < 3; ++d) EXPECT_EQ(a.fluid.u[d].values(), b.fluid.u[d].values()) << "u_" << d;
  EXPECT_TRUE(a.counts == b.counts);
  EXPECT_EQ(a.migrations, b.migrations);
  if (comm.size() == 2 || comm.size() == 4) {
    EXPECT_GT(a.migrations, 0);
  }
  if (comm.rank() != 0) return 0;

  const auto t0 = std::chrono::steady_clock::now();
  Simulation serial(config);
  std::vector<std::vector<Vec3>> start;
  for (std::size_t m = 0; m < serial.num_membranes(); ++m) start.push_back(serial.op().membrane_positions(m));
  std::vector<StepCounts> counts;
  for (int s = 0; s < steps; ++s) {
    const StepRecord rec = serial.advance([](const std::string&) {});
    counts.push_back({rec.dt, rec.rejected, rec.stats.newton_its, rec.stats.gmres_its, rec.stats.fluid_solves});
  }
  const double serial_seconds = seconds_since(t0);
  int rejected = 0;
  for (const StepCounts& c : counts) rejected += c.rejected;
  EXPECT_EQ(counts.size(), a.counts.size());
  for (std::size_t s = 0; s < counts.size() && s < a.counts.size(); ++s) {
    EXPECT_EQ(a.counts[s].dt, counts[s].dt) << "step " << s + 1;
    EXPECT_EQ(a.counts[s].rejected, counts[s].rejected) << "step " << s + 1;
    EXPECT_EQ(a.counts[s].newton, counts[s].newton) << "step " << s + 1;
    EXPECT_EQ(a.counts[s].gmres, counts[s].gmres) << "step " << s + 1;
    EXPECT_EQ(a.counts[s].solves, counts[s].solves) << "step " << s + 1;
  }
  // The errors of the extrapolated initial guesses that the recurrence predicts from (GuessErrorPredictor): those
  // of every membrane followed it to its new owner, so they are the one-process run's.
  const io::Checkpoint ck = serial.checkpoint();
  const std::vector<double>& serial_errors = ck.array("integrator.guess_errors");
  EXPECT_FALSE(serial_errors.empty());
  EXPECT_EQ(a.guess_errors.size(), serial_errors.size());
  double e_max = 0, de = 0;
  for (std::size_t i = 0; i < serial_errors.size() && i < a.guess_errors.size(); ++i) {
    e_max = std::max(e_max, std::abs(serial_errors[i]));
    de = std::max(de, std::abs(a.guess_errors[i] - serial_errors[i]));
  }

  double x_max = 0, dx = 0, moved = 0, d_moved = 0;
  for (std::size_t m = 0; m < serial.num_membranes(); ++m) {
    const auto X = serial.op().membrane_positions(m);
    if (X.size() != a.positions[m].size()) return rejected;  // the sizes were reported above
    for (std::size_t i = 0; i < X.size(); ++i) {
      x_max = std::max(x_max, norm(X[i]));
      dx = std::max(dx, norm(a.positions[m][i] - X[i]));
      moved = std::max(moved, norm(X[i] - start[m][i]));
      d_moved = std::max(d_moved, norm((a.positions[m][i] - start[m][i]) - (X[i] - start[m][i])));
    }
  }
  const FluidState& f = serial.op().fluid_state();
  double u_max = 0, du = 0;
  for (int d = 0; d < 3; ++d) {
    u_max = std::max(u_max, max_abs(f.u[d]));
    EXPECT_EQ(f.u[d].values().size(), a.fluid.u[d].values().size());
    for (std::size_t i = 0; i < f.u[d].values().size() && i < a.fluid.u[d].values().size(); ++i)
      du = std::max(du, std::abs(a.fluid.u[d].values()[i] - f.u[d].values()[i]));
  }
  std::printf(
      "[ParallelRun] %s, %d steps of %g s on %d processes: positions %.2e (relative to the largest coordinate), "
      "displacements %.2e (relative to the largest, %.3e m), velocity %.2e (relative to the largest), guess errors "
      "%.2e (relative to the largest, %.3e m); %s (one process: %s); cells that changed owner: %d; distributed %.1f "
      "s per run, serial %.1f s\n",
      (scheme + (also.empty() ? "" : " " + also)).c_str(), steps, dt, comm.size(), dx / x_max, d_moved / moved, moved, du / u_max, de / e_max, e_max,
      totals(a.counts).c_str(), totals(counts).c_str(), a.migrations, a.seconds, serial_seconds);
  EXPECT_GT(moved, 0.0);
  EXPECT_LE(dx / x_max, 1e-10);
  EXPECT_LE(d_moved / moved, tol.displacement);
  EXPECT_LE(du / u_max, tol.displacement);
  EXPECT_LE(de / e_max, tol.guess_error);
  return rejected;
}

}  // namespace

TEST(ParallelRun, RedCellChannelJfnkEqualsTheOneProcessRun) {
  compare_implicit_with_serial("jfnk", kJfnkSteps, kFiniteDifference);
}

TEST(ParallelRun, RedCellChannelAndersonEqualsTheOneProcessRun) {
  compare_implicit_with_serial("anderson", kAndersonSteps, kRoundOff);
}

TEST(ParallelRun, RedCellChannelLbfgsEqualsTheOneProcessRun) {
  compare_implicit_with_serial("lbfgs", kLbfgsSteps, kRoundOff);
}

// Anderson needs three iterations at some steps of this channel: allowed two, those steps fail, are halved and
// retried, and the step grows back after four accepted ones (AdaptiveStepper), on every process as in one.
TEST(ParallelRun, AFailedImplicitStepIsHalvedAsInTheOneProcessRun) {
  const int rejected = compare_implicit_with_serial("anderson", kHalvingSteps, kRoundOff, "solver.max_newton_its=2");
  if (Communicator::world().rank() == 0) {
    EXPECT_GT(rejected, 0);
  }
}

// A bound on the speed below the flow's: every process stops with a SimulationError (the owners naming the node).
TEST(ParallelRun, AnUnstableRunStopsOnEveryProcess) {
  DistributedSimulation sim(channel("rk2", 2, {"time.max_speed=1e-5"}), Communicator::world());
  try {
    sim.advance();
    ADD_FAILURE() << "a speed above time.max_speed was not reported";
  } catch (const SimulationError& e) {
    EXPECT_NE(std::string(e.what()).find("unstable at step 1"), std::string::npos) << e.what();
  }
}

TEST(ParallelRun, RefusesTheDenseQuasiNewtonScheme) {
  const Communicator world = Communicator::world();
  // The dense quasi-Newton matrix spans all unknowns: one line naming the key and the schemes that run distributed.
  try {
    DistributedSimulation sim(channel("bfgs", 1), world);
    ADD_FAILURE() << "time.scheme = \"bfgs\" was not refused";
  } catch (const InputError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("time.scheme = \"bfgs\""), std::string::npos) << what;
    EXPECT_NE(what.find("\"jfnk\", \"anderson\" or \"lbfgs\""), std::string::npos) << what;
    EXPECT_EQ(what.find('\n'), std::string::npos) << what;
  }
}
