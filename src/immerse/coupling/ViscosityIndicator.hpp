#pragma once
// The interior of the membranes on the grid, weighted by their viscosity contrast (Tryggvason et al. 2001,
// J. Comput. Phys. 169; Unverdi & Tryggvason 1992, J. Comput. Phys. 100): χ(x) = Σ_m (λ_m − 1) I_m(x), I_m the
// indicator of membrane m's interior, so that μ(x) = μ_out (1 + χ(x)) (docs/viscosity-contrast.md). Since
// ∇I_m = −n δ_{S_m} (n outward),
//
//   ∇_h² χ = −D_h G,   G = Σ_m (λ_m − 1) Σ_l N_l δ_h(x − X_l),   N_l = ∫ φ_l n dA = ∂V_m/∂X_l
//
// with D_h the MAC divergence, G spread to the faces by the force-spreading kernel (IBCoupler, eq. 6) and the
// Poisson problem solved by the pressure layout's fast solver (periodic, or Neumann at walls, where the G spread onto
// the wall faces is dropped). Its free constant is fixed so that Σ χ h³ = Σ_m (λ_m − 1) V_m (V_m from the mesh,
// exact for the curved elements); then χ is clipped to [min(0, λ_m − 1), max(0, λ_m − 1)] over the membranes, and
// values below kFloor · max_m |λ_m − 1| in magnitude (the discretization error of the far field) are set to zero, so
// that χ vanishes exactly away from the membranes.
// Bitwise independent of the thread count (the spreading is; the sums are serial).
// Verified by: the test ViscosityContrast.IndicatorOfASphereIsTheContrastInsideAndZeroOutside (a sphere, λ = 5 and
// 0.2: χ inside, outside and its integral) and the capsule of ViscosityContrastShear.*.
#include <array>
#include <memory>
#include <span>
#include <vector>

#include "immerse/core/Array3.hpp"
#include "immerse/core/Vec3.hpp"
#include "immerse/coupling/IBCoupler.hpp"
#include "immerse/fluid/FftHelmholtzSolver.hpp"
#include "immerse/grid/FaceField.hpp"

namespace immerse {

/// One membrane as the indicator sees it: its elements (six nodes each), node positions and viscosity ratio λ.
struct IndicatorSurface {
  const std::vector<std::array<int, 6>>* elements;
  const std::vector<Vec3>* X;
  double ratio = 1;
};

class ViscosityIndicator {
 public:
  /// Relative magnitude below which χ is set to zero.
  static constexpr double kFloor = 1e-2;

  /// Plans its own Poisson solver on the grid of `coupler` (which it uses to spread).
  ViscosityIndicator(IBCoupler& coupler, FftPlanning planning = FftPlanning::Estimate);
  ViscosityIndicator(const ViscosityIndicator&) = delete;
  ViscosityIndicator& operator=(const ViscosityIndicator&) = delete;

  /// χ of the surfaces (membranes with λ = 1 contribute nothing) into chi (sized to the cells on first use).
  void compute(std::span<const IndicatorSurface> surfaces, Array3& chi);

  /// Σ_m (λ_m − 1) V_m of the last compute().
  double target_integral() const { return target_; }

 private:
  IBCoupler& coupler_;
  Array3 work_;  // the Poisson solver's own array
  std::unique_ptr<FftHelmholtzSolver> solver_;
  FaceField normals_;             // G on the faces
  std::vector<Vec3> X_, N_;       // nodes and weighted normals of all contributing membranes
  double target_ = 0;
};

}  // namespace immerse
