#pragma once
// Global volume and area constraints of a closed membrane, as penalty energies (the red-cell models' global terms,
// Fedosov, Caswell & Karniadakis 2010, Biophys. J. 98, 2215):
//   E_V = k_V (V - V0)^2 / (2 V0),   E_A = k_A (A - A0)^2 / (2 A0),
//   F_i = -dE/dX_i = -k_V (V - V0)/V0 dV/dX_i - k_A (A - A0)/A0 dA/dX_i   (newtons),
// k_V in Pa (J/m^3), k_A in N/m (J/m^2): k_V ΔV/V0 is the pressure jump the constraint adds across the membrane,
// k_A ΔA/A0 an isotropic tension. V0, A0 are those of the positions given at construction (in a run: the initial
// shape, not the stress-free reference, which for a red cell may be a sphere of another volume).
// V and A are the quadratures of Geometry.hpp on the six-node elements (7-point rule; the area on the element's
// four sub-triangles), and the gradients are those of these quadratures exactly. With r = sum_i N_i x_i,
// a_alpha = sum_i dN_i/dalpha x_i, J = a_xi x a_eta, n = J/|J| at each point of weight w:
//   V = (1/3) sum_q w r.J,      dV/dx_i = (1/3) sum_q w [N_i J + dN_i/dxi (a_eta x r) + dN_i/deta (r x a_xi)]
//   A = sum_q w |J|,            dA/dx_i = sum_q w [dN_i/dxi (a_eta x n) + dN_i/deta (n x a_xi)]
// (r taken from the mean node position against cancellation; V does not depend on that origin, the closed surface
// having sum_q w J = 0). E_V and E_A are invariant under rigid motions, so the forces have no net force nor torque.
// Verification: tests/test_membrane_constraint.cpp (gradients against finite differences of Geometry's V and A,
// zero force at V0 and A0, zero net force and torque, an inflated sphere relaxing back).
#include <array>
#include <cstddef>
#include <span>
#include <vector>

#include "immerse/core/Vec3.hpp"
#include "immerse/membrane/Mesh.hpp"

namespace immerse {

/// The moduli of the global constraints; 0 switches a constraint off.
struct ConstraintModuli {
  double volume = 0;  ///< k_V, Pa
  double area = 0;    ///< k_A, N/m
};

/// Volume and area of a closed surface of six-node elements with their gradients with respect to the node positions.
struct SurfaceGradients {
  double volume = 0, area = 0;
  std::vector<Vec3> d_volume;  ///< dV/dX_i (m^2)
  std::vector<Vec3> d_area;    ///< dA/dX_i (m); empty unless asked for
};

/// V, A (the values of Geometry's volume() and area() up to round-off) and dV/dX, and dA/dX when `with_area`.
/// Independent of the thread count.
SurfaceGradients surface_gradients(const std::vector<std::array<int, 6>>& elements, std::span<const Vec3> X,
                                   bool with_area);

class VolumeAreaConstraint {
 public:
  /// V0, A0 from the positions X0 (indexed like mesh.nodes). InputError when a modulus is negative or not finite.
  VolumeAreaConstraint(const Mesh& mesh, const std::vector<Vec3>& X0, ConstraintModuli moduli);

  /// F_i += -dE/dX_i for E = E_V + E_A at X.
  void add_force(std::span<const Vec3> X, std::vector<Vec3>& F) const;
  /// E_V + E_A (J) at X.
  double energy(std::span<const Vec3> X) const;

  double volume0() const { return V0_; }
  double area0() const { return A0_; }
  const ConstraintModuli& moduli() const { return moduli_; }
  std::size_t memory_bytes() const { return elements_.size() * sizeof(std::array<int, 6>); }

 private:
  std::vector<std::array<int, 6>> elements_;
  ConstraintModuli moduli_;
  double V0_ = 0, A0_ = 0;
};

}  // namespace immerse
