#pragma once
// The interior indicator χ of ViscosityIndicator (see ViscosityIndicator.hpp and docs/viscosity-contrast.md) on a grid
// cut into slabs of z planes over MPI processes (SlabDecomposition.hpp), from the membranes each process owns:
//
//   ∇_h² χ = −D_h G,   G = Σ_m (λ_m − 1) Σ_l N_l δ_h(x − X_l),   N_l = ∂V_m/∂X_l,   Σ χ h³ = Σ_m (λ_m − 1) V_m
//
// then χ clipped to [min(0, λ_m − 1), max(0, λ_m − 1)] and values below ViscosityIndicator::kFloor · max_m |λ_m − 1|
// set to zero. Each owner computes N_l and V_m of its membranes and spreads G with SlabIBCoupler; the wall faces of G
// are zeroed, the faces of G_z just below and above the owned cells come from the neighbours (HaloExchange, zero
// beyond a wall), D_h G is taken on the owned cells with the serial kernel, and the Poisson problem is solved by a
// SlabFftHelmholtzSolver of the pressure layout (the fluid's block). The target Σ_m (λ_m − 1) V_m is added in global
// membrane order from the owners' values (MPI_Allgather), as in one process; Σ χ h³ of the Poisson solution is the sum
// of each process's cells (in storage order) over the processes in rank order (Communicator::sum). The result is the
// pressure-layout slab array of χ with valid ghost planes (beyond a wall the copy of the cell inside, the χ_g = χ_0 of
// the stress kernel), ready for SlabNavierStokesSolver::step.
//
// It equals ViscosityIndicator's to round-off (the spreading sums and Σ χ h³ add in another order) and is bitwise the
// same in every run with the same number of processes. compute() is collective. No global state.
// Verified by: the tests ParallelViscosity.IndicatorEqualsTheSerialOneAndRepeatsBitwise
// (tests/test_parallel_viscosity.cpp, 1, 2 and 3 processes: spheres of λ = 5 and 0.2 between z walls and in a periodic
// box, gathered χ against ViscosityIndicator within 1e-12) and ParallelRun.RedCellChannelWithViscosityContrast*.
#include <array>
#include <memory>
#include <span>
#include <vector>

#include "immerse/core/Array3.hpp"
#include "immerse/core/Vec3.hpp"
#include "immerse/coupling/SlabIBCoupler.hpp"
#include "immerse/fluid/MacStencilGrid.hpp"
#include "immerse/fluid/SlabFftHelmholtzSolver.hpp"
#include "immerse/grid/FaceField.hpp"
#include "immerse/parallel/HaloExchange.hpp"

namespace immerse {

/// One owned membrane as the indicator sees it: its global index, elements (six nodes each) and node positions.
struct OwnedIndicatorSurface {
  int id = 0;
  const std::vector<std::array<int, 6>>* elements = nullptr;
  const std::vector<Vec3>* X = nullptr;
};

class SlabViscosityIndicator {
 public:
  /// Spreads with `coupler` (kept by reference, as its decomposition) and plans its own distributed Poisson solver.
  /// `ratio` holds λ of every membrane by global index (the same on every process). Collective.
  SlabViscosityIndicator(SlabIBCoupler& coupler, std::vector<double> ratio);
  SlabViscosityIndicator(const SlabViscosityIndicator&) = delete;
  SlabViscosityIndicator& operator=(const SlabViscosityIndicator&) = delete;

  /// χ of all membranes, from the ones this process owns (`surfaces`, ascending in global index), into the slab array
  /// chi of the pressure layout (made on first use), ghost planes filled. Collective.
  void compute(std::span<const OwnedIndicatorSurface> surfaces, Array3& chi);

  /// Σ_m (λ_m − 1) V_m of the last compute() (the same on every process).
  double target_integral() const { return target_; }

 private:
  SlabIBCoupler& coupler_;
  const SlabDecomposition& slabs_;
  std::vector<double> ratio_;
  HaloExchange halo_;     // homogeneous walls: G_z is zero on a wall face
  MacStencilGrid local_;  // the slab arrays: z periodic with the slab's planes (as SlabNavierStokesSolver's)
  Array3 work_;           // the Poisson solver's right-hand side and solution (pressure slab)
  std::unique_ptr<SlabFftHelmholtzSolver> solver_;
  FaceField normals_;        // G on the faces (slab)
  std::vector<Vec3> X_, N_;  // nodes and weighted normals of the owned contributing membranes
  double target_ = 0;
};

}  // namespace immerse
