#pragma once
// Measurements on MAC fields used by the tests and verification studies: discrete divergence, the
// homogeneous operators the fast solvers invert and their residuals, and error norms against exact fields.
#include <functional>

#include "immerse/core/Array3.hpp"
#include "immerse/core/Vec3.hpp"
#include "immerse/fluid/FftHelmholtzSolver.hpp"
#include "immerse/grid/FaceField.hpp"
#include "immerse/grid/Grid.hpp"

namespace immerse {

/// D^MAC u at every cell (wall faces of u are read as stored).
void divergence(const Grid& grid, const FaceField& u, Array3& div);

/// Mean over the wall z = z_lower (upper = false) or z = z_upper of the shear stress μ (1 + χ) ∂u_x/∂z that the
/// viscous term of (9) applies there: ∂u_x/∂z = 2 (u_x(first cell) − U_x) / h at the lower wall and
/// 2 (U_x − u_x(last cell)) / h at the upper one (the ghost 2 U − u of MacStencil_K.hpp; ∂u_z/∂x = 0 on the wall),
/// χ at the wall edge the mean of its two cells (ViscousStress_K.hpp), χ = 0 where chi is null or empty. In plane
/// Couette flow u_x = U_lower + k (z − z_lower) both walls give μ k; the flux is first order in h as a derivative of a
/// curved profile, and in a discrete steady state it is the one that balances the momentum exactly. Needs z walls
/// and a periodic x axis (std::invalid_argument otherwise).
double wall_shear_stress(const Grid& grid, const FaceField& u, const Array3* chi, double mu, bool upper,
                         double wall_velocity_x);
/// The sum over the wall's n_x n_y edges of (1 + χ) ∂u_x/∂z of wall_shear_stress (which is μ times it over n_x n_y),
/// with u_x and χ read at plane k of the arrays: 0 or n_z − 1 of whole-grid arrays, the plane next to the wall of a
/// slab array (a distributed run, whose first and last processes add theirs).
double wall_shear_stress_sum(const Grid& grid, const Array3& ux, const Array3* chi, bool upper, double wall_velocity_x,
                             int k);

/// Largest |value| of velocity over the unknown faces (all components).
double max_abs_velocity(const Grid& grid, const FaceField& u);

/// out = (α I + β ∇_h²) x on the unknowns of `layout` with homogeneous walls (the operator FftHelmholtzSolver inverts;
/// ∇_h² of the pressure is D^MAC G^MAC with Neumann walls). Other entries of out are set to zero.
void apply_operator(const Grid& grid, Layout layout, const Array3& x, double alpha, double beta, Array3& out);

/// max |(α I + β ∇_h²) x − b| / max |b| over the unknowns of `layout`.
double relative_residual(const Grid& grid, Layout layout, const Array3& x, const Array3& b, double alpha, double beta);

struct ErrorNorms {
  double l2 = 0;   ///< root mean square over the points
  double max = 0;  ///< largest absolute value
};

/// Error of u against exact(position) over the unknown faces of all components.
ErrorNorms velocity_error(const Grid& grid, const FaceField& u, const std::function<Vec3(const Vec3&)>& exact);
/// Norms of a − b over the unknown faces.
ErrorNorms velocity_difference(const Grid& grid, const FaceField& a, const FaceField& b);
/// Error of p against exact(position) over the cells, after removing the mean of each (pressure is defined up
/// to a constant).
ErrorNorms pressure_error(const Grid& grid, const Array3& p, const std::function<double(const Vec3&)>& exact);
/// Norms of (a − mean a) − (b − mean b).
ErrorNorms pressure_difference(const Array3& a, const Array3& b);

/// u_d(face) = exact(face position)[d] on every face of every component (wall faces included).
void sample_velocity(const Grid& grid, const std::function<Vec3(const Vec3&)>& exact, FaceField& u);
/// p(cell) = exact(cell centre).
void sample_pressure(const Grid& grid, const std::function<double(const Vec3&)>& exact, Array3& p);

}  // namespace immerse
