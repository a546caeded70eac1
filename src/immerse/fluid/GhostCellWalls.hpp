#pragma once
// The no-slip condition on rigid walls of any shape (WallGeometry) in the Helmholtz problems of the momentum step (9):
// a cut-cell (Shortley–Weller) Dirichlet stencil solved exactly by a capacitance matrix, so that the periodic fast
// solver stays the workhorse (docs/walls.md).
//
// On each velocity component's lattice a point is fluid where φ > 0 and solid otherwise. At a fluid point next to the
// wall (a cut point: a solid neighbour in the 7-point stencil) the Laplacian is Shortley & Weller's (1938, J. Appl.
// Phys. 9:334): along each axis the arms h_l, h_r reach the neighbours, or the wall crossing θh in between, where u = 0
// (θ by bisection on φ along the grid line),
//   ∂²u/∂x_a² ≈ 2/(h_l + h_r) [(u_r − u_0)/h_r − (u_0 − u_l)/h_l],     u_l or u_r = 0 at a wall crossing,
// first-order consistent there and second-order accurate in the solution. The explicit half of the Crank–Nicolson
// viscous term takes the same rows (add_explicit_correction), so that a steady state is the cut-cell solution. Fluid
// points away from the wall keep the periodic rows. Solid points keep them too, with right-hand side 0 (their values
// enter no fluid row), and are then set to 0, the wall's velocity, so that the divergence D u* of the projection sees
// no flux through the wall: with the fictitious values left there the drag on a sphere array was 1.7–2.1 % low, with
// the wall's velocity within 0.1 % (SphereArray.*).
//
// The cut rows change A = αI + β∇_h² by a matrix of rank n_c (the cut count): A = H + E Wᵀ, H the periodic operator, E
// the cut points' unit columns and Wᵀ the cut rows a minus H's. By the Sherman–Morrison–Woodbury identity
//   A⁻¹ b = v − H⁻¹ E C⁻¹ (Wᵀ v),    v = H⁻¹ b,    Wᵀ v = a v − b_c,    C = I + Wᵀ H⁻¹ E = a H⁻¹ E.
// H is translation-invariant on the periodic box, so H⁻¹ E is the shifted lattice Green's function G = H⁻¹ e_0 and C_ij
// = Σ_k a_ik G(q_k − q_j): one fast solve for G, then the n_c × n_c matrix C factored by LAPACK's LU, per (α, β), that
// is per time step size (up to eight kept). Each solve is then two fast solves and a dense triangular solve: exact,
// with no iteration, whatever the Reynolds number and the step. Walls invariant along an axis (tubes along it, P
// planes normal to it) make C block circulant, C_(s,i),(s′,j) = c_ij(s − s′): the DFT along the axis splits it into
// P complex n_ring × n_ring blocks, one per wavenumber (block_solve), with P times less memory and work.
//
// The pressure projection (11)–(12) stays periodic: after it the velocity at the wall differs from zero by (Δt/ρ) G φ,
// which vanishes as the flow becomes steady (φ → 0 in the pressure-increment form), so steady flows meet the cut rows
// exactly. Verified by the tests GhostCellWalls.* (every row of the solve), TubeFlow.* (Poiseuille flow in a tube,
// aligned and at 30° to the grid: the flow rate against π G R⁴ / 8μ and its order) and SphereArray.* (Stokes drag on a
// simple cubic array of spheres against Zick & Homsy 1982).
#include <array>
#include <complex>
#include <cstddef>
#include <cstdint>
#include <vector>

#include "immerse/core/Array3.hpp"
#include "immerse/fluid/FluidEnergy.hpp"
#include "immerse/fluid/FluidParams.hpp"
#include "immerse/grid/FaceField.hpp"
#include "immerse/grid/Grid.hpp"
#include "immerse/walls/WallGeometry.hpp"

namespace immerse {

class FftHelmholtzSolver;

class GhostCellWalls {
 public:
  /// The cut points and rows of each velocity component on `grid`, which must be periodic on every axis (InputError).
  GhostCellWalls(const Grid& grid, const WallGeometry& walls);

  /// Overwrites x (component d; the right-hand side b on entry) with the solution of (α I + β ∇_h²) x = b with the cut
  /// rows at the cut points and b = 0 at solid points, then 0 at the solid points, `fast` being the periodic solver of
  /// component d (it may solve only in x). The capacitance matrices are built at the first call with an (α, β) (all
  /// three components at once).
  void solve(int d, Array3& x, double alpha, double beta, FftHelmholtzSolver& fast);

  /// Adds c (L_c − ∇_h²) u^n at the cut points of rhs (component d): the explicit half of the viscous term of (9),
  /// built with the periodic ∇_h², taken with the cut rows' Laplacian L_c instead (c = μΔt/2ρ).
  void add_explicit_correction(int d, const Array3& un, double c, Array3& rhs) const;

  /// L_c u for component d: the cut rows' Laplacian at the cut points, the 7-point one at the other fluid points, 0 at
  /// the solid points.
  void laplacian(int d, const Array3& u, Array3& out) const;

  /// The steady flow of component d under the uniform body force f (N/m³): μ L_c u = −f at the fluid points, u = 0 in
  /// the walls, by Richardson iterations u −= (α − L_c)⁻¹ (−f/μ − L_c u) with α cycling from 12/h² down by factors
  /// of 4 to below (2.405/φ_max)²/4 (each mode is damped at least twofold by one of them in a cycle), until the
  /// residual is below 1e-12 f/μ. `fast`: a periodic solver of component d.
  void steady_flow(int d, double f, double mu, Array3& u, FftHelmholtzSolver& fast);

  /// The energy measures of u over the fluid points (docs/energy-budget.md, "Walls of any shape"): kinetic ρ/2 Σ u² h³,
  /// body f_body·Σ u h³ and dissipation −μ Σ u·(L_c u) h³ with the cut rows' Laplacian L_c (at a steady state the body
  /// force's work exactly); the rigid walls do no work.
  FluidEnergy energy(const FluidParams& params, const FaceField& u) const;

  /// Whether the fluid points of component d join across the periodic box along axis d (a path of neighbouring fluid
  /// points that winds once around it): a flow along d can pass the walls.
  bool open_along(int d) const;

  /// Whether point i (flat index) of component d is in the fluid (φ > 0).
  bool fluid(int d, std::size_t i) const { return comp_[d].fluid[i] != 0; }
  std::size_t cut_count(int d) const { return comp_[d].cut.size(); }
  /// Largest residual |a x − b| of the cut rows of component d for the last (α, β) solved with.
  double cut_residual(int d, const Array3& x, const Array3& b) const;

 private:
  struct Component {
    std::vector<unsigned char> fluid;    // φ > 0 at each point
    std::vector<std::size_t> cut;        // flat indices of the cut points
    std::vector<std::size_t> solid;      // the solid points
    std::vector<std::size_t> row_start;  // cut row i: entries row_start[i] .. row_start[i + 1]
    std::vector<std::size_t> col;        // their flat indices
    std::vector<double> val;             // the Shortley–Weller Laplacian's coefficients
    std::vector<unsigned char> diag;     // whether the entry is the row's own point (α is added there)
  };
  /// C of every component for (α, β), LU-factored (column-major).
  struct Factorization {
    double alpha = 0, beta = 0;
    std::array<std::vector<double>, 3> lu;
    std::array<std::vector<int>, 3> pivot;
    std::array<std::vector<std::complex<double>>, 3> blocks;  // walls invariant along axis_: Ĉ_m, LU-factored
    std::uint64_t used = 0;  // when it was last asked for
  };
  /// The factorization for (α, β): kept from an earlier call, or G by one fast solve in x (whose values are kept) and C
  /// built and factored, replacing the least recently used beyond 8 (or beyond 1 GB).
  const Factorization& factorization(double alpha, double beta, Array3& x, FftHelmholtzSolver& fast);
  /// rhs_ ← C⁻¹ rhs_ for component d by the blocks of walls invariant along axis_.
  void block_solve(const Factorization& fac, int d);
  /// Row i of the cut rows a (for alpha_, beta_) times u.
  double row_times(const Component& c, std::size_t i, const double* u) const;

  Grid grid_;
  std::array<Component, 3> comp_;
  int axis_ = -1;   // the axis the walls are invariant along (tubes along it), or −1
  int planes_ = 1;  // the planes normal to axis_ (1 without): cut point s·n_ring + i is point i of plane s
  std::vector<Factorization> factors_;
  std::uint64_t uses_ = 0;
  double alpha_, beta_;  // the last (α, β) solved with
  Array3 scratch_;
  std::vector<double> rhs_;
};

}  // namespace immerse
