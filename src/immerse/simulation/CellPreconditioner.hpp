#pragma once
// A two-level preconditioner of the implicit step's Jacobian, one cell at a time.
//
// The residual g(X) = X − X^n − dt [(1 − θ) U^n + θ J u^{n+1}] (eq. 31), driven by θ S f(X), has the Jacobian
//   A = I + c M K,    c = θ² dt,   M = J L⁻¹ S the mobility of one fluid step,   K = −∂f/∂X the membrane stiffness,
// (the terms from the motion of the kernel neglected). GMRES pays for K's stiff smooth modes. On each cell's coarse
// points X_c = R X (the nodes of a lower subdivision level, CouplingPoints.hpp) the preconditioner builds
//   A_c = I + c M_c K_c,
// K_c the stiffness of the cell's coarse finite-element model (the same law on the coarse mesh, reference R X_ref;
// finite differences of its forces) and M_c the Rotne–Prager–Yamakawa mobility of blobs of the kernel's
// hydrodynamic radius (Stokes flow, free space: walls and periodic images are left out), and applies
//   P⁻¹ v = v + P_c (A_c⁻¹ − I) R v,
// the coarse correction (P_c the quadratic interpolation from the points, R the injection); the cell's mesh-scale
// modes pass unchanged. Kallemov, Bhalla, Griffith & Donev (2016, CAMCoS 11:79) precondition the rigid-body IB
// problem with the same kind of mobility.
#include <cstddef>
#include <memory>
#include <span>
#include <vector>

#include "immerse/core/Vec3.hpp"
#include "immerse/coupling/CouplingPoints.hpp"
#include "immerse/membrane/ElasticMembrane.hpp"

namespace immerse {

class CellPreconditioner {
 public:
  struct Cell {
    CouplingPoints points;                    ///< the cell's nodes and its coarse points
    std::unique_ptr<ElasticMembrane> coarse;  ///< the coarse finite-element model on the points
  };
  /// `mu` the fluid's viscosity (Pa s), `radius` the blobs' hydrodynamic radius (m).
  CellPreconditioner(std::vector<Cell> cells, double mu, double radius);

  /// Builds and factors A_c of every cell at the positions X (cells concatenated, cell m at offsets[m]).
  void prepare(std::span<const Vec3> X, std::span<const std::size_t> offsets, double c);
  /// z = P⁻¹ v (cells as in prepare).
  void apply(std::span<const Vec3> v, std::span<Vec3> z);
  std::size_t num_cells() const { return cells_.size(); }

 private:
  struct Factor {
    std::vector<double> lu;       ///< A_c, factored in place (row-major)
    std::vector<int> pivot;
    std::vector<double> gram;     ///< PᵀP (one component), factored (LU, in place)
    std::vector<int> gram_pivot;
  };
  void prepare_cell(std::size_t m, std::span<const Vec3> X, double c);

  std::vector<Cell> cells_;
  double mu_, radius_;
  std::vector<std::size_t> offsets_;
  std::vector<Factor> factors_;
};

}  // namespace immerse
