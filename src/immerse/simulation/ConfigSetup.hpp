#pragma once
// The pieces of a run that follow directly from its configuration (already through apply_scenario): the grid, the
// fluid parameters, the contact settings, the implicit schemes' solver settings and the initial fluid state. Shared
// by the one-process run (Simulation) and the distributed one (DistributedSimulation), so both read the same keys the
// same way. The membranes are MembraneSet's.
// Verified by: the tests of Simulation (test_simulation_*) and ParallelRun.* (the distributed run equals the
// one-process run of the same configuration).
#include "immerse/contact/ContactForce.hpp"
#include "immerse/fluid/FftHelmholtzSolver.hpp"
#include "immerse/fluid/FluidParams.hpp"
#include "immerse/fluid/FluidState.hpp"
#include "immerse/grid/Grid.hpp"
#include "immerse/io/Config.hpp"
#include "immerse/timestep/MembraneIntegrator.hpp"

namespace immerse {

/// grid.*, domain.* and boundary.x/y/z.
Grid run_grid(const io::Config& config);
/// fluid.* and the wall velocities; variable_viscosity when a membrane has viscosity_ratio ≠ 1.
FluidParams run_fluid_params(const io::Config& config);
/// fluid.fft_planning.
FftPlanning run_fft_planning(const io::Config& config);
/// contact.*, the walls of [[wall]] (built once, by run_fluid_params) repelling the nodes when contact.walls.
ContactSettings run_contact_settings(const io::Config& config, std::shared_ptr<const WallGeometry> walls);
/// time.theta and solver.*.
SolverSettings run_solver_settings(const io::Config& config);
/// The fluid at t = 0 on the whole grid (fluid.initial: at rest, Poiseuille or Couette flow), wall velocities set.
FluidState run_initial_fluid_state(const io::Config& config, const Grid& grid, const FluidParams& params);

}  // namespace immerse
