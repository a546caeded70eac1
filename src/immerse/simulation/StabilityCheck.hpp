#pragma once
// The check after every accepted step that ends a run as unstable (docs/robustness.md, "exit statuses"): every node
// position and velocity finite and every node speed |U| within time.max_speed, then every fluid velocity within it
// and every pressure finite. Simulation checks the whole state, DistributedSimulation each process's own part;
// both report the first offender with the same words and global indices.
// Verified by: the tests Run/UnstableTest.* (tests/test_run_unstable.cpp) and RunMpi.* (tests/test_run_mpi.cpp).
#include <array>
#include <cstddef>
#include <string>

#include "immerse/core/Vec3.hpp"
#include "immerse/fluid/FluidState.hpp"

namespace immerse {

/// Where the run stands: "unstable at step S, t = T: " begins every message.
struct StepPlace {
  long step = 0;
  double time = 0;
};

/// "" when node `node` of membrane[`membrane`] at x moving at u is fine, else what is wrong with it.
std::string node_instability(const StepPlace& at, std::size_t membrane, std::size_t node, const Vec3& x, const Vec3& u,
                             double max_speed);

/// "" when the fluid is fine on the local z planes [planes[l][0], planes[l][1]) of each layout l (u_x, u_y, u_z,
/// p), else the first face or cell that is not, named by its global index (local plane k is global plane
/// k + plane_offset).
std::string fluid_instability(const StepPlace& at, const FluidState& f, const std::array<std::array<int, 2>, 4>& planes,
                              int plane_offset, double max_speed);

}  // namespace immerse
