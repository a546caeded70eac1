#pragma once
// One step of NavierStokesSolver (paper §2.2, eqs. 9–13; see NavierStokesSolver.hpp) on a grid cut into slabs of
// z planes over MPI processes:
//
//   (9)   (I − (μ_p Δt/2ρ) ∇_h²) u* = u^n + (Δt/ρ)(−ρ A^{n+1/2} − G p + (μ/2) ∇_h² u^n + F^{n+1/2} + f_body)
//   (10)  A^{n+1/2} = (1 + r/2) (u·∇_h u)^n − (r/2) (u·∇_h u)^{n−1}   (forward Euler on the first step)
//   (11)  ∇_h² φ = (ρ/Δt) D u*,  n·∇φ = 0 on walls
//   (12)  u^{n+1} = u* − (Δt/ρ) G φ
//   (13)  p^{n+1/2} = p + φ − (μ_p/2) D u*
//
// with p = p^{n−1/2}, or its extrapolation p̃ (FluidParams::pressure), as in the serial step. Periodic and wall axes,
// moving walls and the uniform body force as there. μ_p = μ for a constant viscosity. With a variable viscosity
// (FluidParams::variable_viscosity, μ(x) = μ (1 + χ(x)), docs/viscosity-contrast.md) as in the serial step:
// μ_p = implicit_ratio · μ, the explicit terms of (9) take (μ_p − μ) ∇_h²(u^n/2 − ũ) (homogeneous walls) and
// (Δt/ρ) μ ∇_h·(χ S(ũ)) is added to its right-hand side (ViscousStress_K.hpp), ũ = u^n + (r/2)(u^n − u^{n−1});
// u^{n−1} is kept in the state (u_prev, with its ghost planes). ũ and u^n/2 − ũ get their ghost planes from the
// halo exchange (real and homogeneous walls), χ comes with its own (SlabViscosityIndicator), so the stress kernel
// reads the serial operands on every owned face; a face near a z wall reads the ghost planes instead of the serial
// wall values, which are the same numbers.
//
// Decomposition (SlabDecomposition.hpp). Process r owns the cell planes [r B, (r + 1) B), B = ⌈N_z / P⌉, and of each
// layout the planes of unknowns of the same block indices, which is the distribution of the four SlabFftHelmholtzSolver
// made with block B: each solves (9) and (11) in place on the process's own planes. A slab state is a FluidState
// whose arrays are slab arrays (z1 − z0 + 3 planes, local plane k = global plane k + z0 − 1): u, p and p_prev carry
// valid ghost planes (HaloExchange) — scatter() and step() leave them so; exchange_ghosts() restores them after an
// in-place change of the owned planes. The MAC kernels run on the slabs through a local geometry that is periodic
// along z with the slab's planes: no read ever wraps (the ghost planes hold what lies beyond), and beyond a wall the
// ghosts hold the values the serial kernels construct, so every face sees the serial operands; the wall sources of
// (9) along z are taken with the global indices. Per step: (9) on the owned faces, three solves, halo of u*_z, D u*,
// the solve (11), halo of φ, (12)–(13), halos of u^{n+1} and p^{n+1/2}.
//
// The result equals the serial step's to round-off (the distributed transforms need not be planned like the serial
// ones; on the test grids they give the same bits) and is bitwise the same on every run with the same number of
// processes (FFTW_ESTIMATE plans by default, one thread per process, fixed message order). Construction, scatter/gather and
// step() are collective over the communicator. No global state.
// Verified by: the tests ParallelFluidStep.* (tests/test_parallel_fluid_step.cpp, run with 1, 2 and 3 processes: five
// steps in a periodic box, between moving z walls and in a channel equal the serial steps within 1e-12, repeat
// bitwise, and leave D u^{n+1} ≤ 1e-12) and ParallelViscosity.VariableViscosityStepsEqualTheSerialStepsAndRepeatBitwise
// (tests/test_parallel_viscosity.cpp, 1, 2 and 3 processes: the same three cases with χ ≠ 0 reaching the walls).
#include <array>
#include <memory>

#include "immerse/core/Array3.hpp"
#include "immerse/fluid/FluidParams.hpp"
#include "immerse/fluid/FluidState.hpp"
#include "immerse/fluid/MacStencilGrid.hpp"
#include "immerse/fluid/NavierStokesStep_K.hpp"
#include "immerse/fluid/SlabFftHelmholtzSolver.hpp"
#include "immerse/grid/FaceField.hpp"
#include "immerse/grid/Grid.hpp"
#include "immerse/parallel/Communicator.hpp"
#include "immerse/parallel/HaloExchange.hpp"
#include "immerse/parallel/SlabDecomposition.hpp"

namespace immerse {

class SlabNavierStokesSolver {
 public:
  /// Validates the parameters (InputError), refuses a cut that leaves a process without planes
  /// (std::invalid_argument), and plans the four distributed solvers (`planning`: as NavierStokesSolver's).
  /// Collective.
  SlabNavierStokesSolver(const Grid& grid, const FluidParams& params, Communicator comm,
                         FftPlanning planning = FftPlanning::Estimate);
  SlabNavierStokesSolver(const SlabNavierStokesSolver&) = delete;  // its halo exchange refers to its decomposition
  SlabNavierStokesSolver& operator=(const SlabNavierStokesSolver&) = delete;

  const Grid& grid() const { return grid_; }
  const FluidParams& params() const { return params_; }
  const SlabDecomposition& decomposition() const { return slabs_; }

  /// Writes into the slab state `out` the state one step of size dt after the slab state `in` under the slab force
  /// `force` (as NavierStokesSolver::step; wall faces of the force ignored). `in` is only read and must carry valid
  /// ghost planes; `out` must be another object (sized on first use). Collective. Not reentrant (work arrays).
  /// With a variable viscosity, chi is χ on the pressure layout's slab array with valid ghost planes (null: χ = 0).
  void step(const FluidState& in, const FaceField& force, double dt, FluidState& out, const Array3* chi = nullptr);

  /// This process's slab state of a whole-grid state (every process passes the same one), ghosts filled. Collective.
  FluidState scatter(const FluidState& global) const;
  /// This process's slab field of a whole-grid face field (no ghosts: a force is read at its own faces only).
  FaceField scatter(const FaceField& global) const;
  /// The whole-grid state assembled from the slab states, on every process. Collective.
  FluidState gather(const FluidState& local) const;
  /// The whole-grid face field assembled from the slab fields, on every process. Collective.
  FaceField gather(const FaceField& local) const;
  /// Refills the ghost planes of u, p, p_prev (and u_prev, when kept) of a slab state from its owned planes.
  /// Collective.
  void exchange_ghosts(FluidState& s) const;

 private:
  /// fluid.flow_rate (NavierStokesSolver.hpp, "Flow rate"): adds ΔG w to the flow axis's velocity of `out`, w the
  /// step's response to a unit body force along it (cached for the step size), so that its mean over the box (summed
  /// over the processes) is FluidParams::flow_mean_velocity; out.flow_force = ΔG.
  void hold_flow_rate(double dt, FluidState& out);
  bool is_slab(const FaceField& f) const;
  void check(const FluidState& in, double dt, const FaceField& force) const;
  /// The wall velocities on the x and y walls of the velocity slabs (the z walls are the halo's).
  void apply_wall_values(FaceField& u) const;
  /// Sizes every array of a slab state to the slab shapes (zero-filled when remade).
  void ensure_slabs(FluidState& s) const;
  /// With a variable viscosity: ũ into utilde_ (ghosts filled) and (μ_p − μ) ∇_h²(u^n/2 − ũ) added to explicit_.
  void prepare_variable(const FluidState& in, double dt);
  /// Adds (Δt/ρ) μ ∇_h·(χ S(ũ)) to u*_d on the owned faces whose stencil reads a non-zero χ.
  void add_variable_stress(const Array3& chi, double dt, int d);

  Grid grid_;
  FluidParams params_;
  Array3 flow_response_;           // w, for steps of flow_response_dt_
  double flow_response_dt_ = 0;
  double flow_response_mean_ = 0;  // its mean over the box
  SlabDecomposition slabs_;
  HaloExchange halo_;
  MacStencilGrid geom_;   // the whole grid: wall sources and the loops' x and y ranges
  MacStencilGrid local_;  // the slab arrays: z periodic with the slab's planes (see above)
  MacStencilGrid local0_;  // local_ with homogeneous walls (the remainder of a variable viscosity)
  HaloExchange halo0_;     // homogeneous z walls
  double mu_implicit_;     // μ_p
  std::array<step_kernels::BuildRegion, 3> region_{};  // where (9) is built for each component, local indices
  std::array<std::unique_ptr<SlabFftHelmholtzSolver>, 4> solvers_;
  FaceField ustar_;  // u*
  Array3 div_;       // D u*
  Array3 phi_;       // φ
  Array3 ptilde_;    // p̃, when extrapolated
  FaceField explicit_;  // the explicit terms of (9), with a variable viscosity
  FaceField utilde_;    // ũ, with a variable viscosity
};

}  // namespace immerse
