#pragma once
// Discrete bending energy of a closed membrane with an exact gradient: the mean-curvature energy of Jülicher
// (1996, J. Phys. II France 6:1797) on the flat sub-triangulation of the six-node elements (tri6::kSubTriangles,
// four flat triangles per element, every mesh node a vertex).
//
//   E_B = (kappa_B / 2) sum_i A_i (2H_i - 2Hbar_i)^2,   2H_i = M_i / (2 A_i),   M_i = sum_{edges e at i} l_e theta_e
//
// A_i is a third of the area of the flat triangles at node i, l_e an edge's length and theta_e its signed dihedral
// angle (DihedralAngle_K.hpp, positive where convex). By Steiner's formula sum_e l_e theta_e / 2 is the integral of
// the mean curvature H over a smooth surface the triangulation approximates, so E_B approximates
// (kappa_B / 2) oint (2H - 2Hbar)^2 dA: for Hbar = 0 the energy whose first variation is the load of the moments (25)
// with kappa_m^R = 0 (the two differ by the Gaussian-curvature integral, a topological constant), 8 pi kappa_B for
// a sphere. Hbar_i = 0 (ReferenceCurvature::Zero) or H_i of the reference shape (ReferenceCurvature::RestShape): the
// rest shape is then a minimum, E_B = 0 and no force, exactly. F_i = -dE_B/dX_i sums to zero and exerts no torque.
// Verified by: the study membrane_bending, the tests MeanCurvatureBending.* (gradient against central
// differences, sphere energy, rest shape force-free, momentum) and MembraneAtRest.*.
#include <array>
#include <cstddef>
#include <span>
#include <vector>

#include "immerse/core/Vec3.hpp"
#include "immerse/membrane/Mesh.hpp"

namespace immerse {

/// Reference mean curvature kappa_m^R of eq. (25): zero, or per node that of the reference (rest) shape.
enum class ReferenceCurvature { Zero, RestShape };

struct Bending {
  double kappa_B = 0;  ///< bending modulus, J (N m); 0 switches bending off
  ReferenceCurvature reference = ReferenceCurvature::Zero;
};

class MeanCurvatureBending {
 public:
  /// InputError if an edge of the sub-triangulation is shared by more than two triangles or by two triangles of
  /// opposite orientation, or a reference triangle is degenerate. Edges of one triangle (an open surface) carry
  /// no hinge.
  MeanCurvatureBending(const Mesh& mesh, std::span<const Vec3> reference, Bending bending, bool threaded);

  /// F_i += -dE_B/dX_i (N). SimulationError naming the element if a flat triangle degenerates.
  void add_force(std::span<const Vec3> X, std::vector<Vec3>& F) const;
  /// E_B (J) at X.
  double energy(std::span<const Vec3> X) const;
  /// 2Hbar_i per node (1/m).
  const std::vector<double>& reference_curvature() const { return c_ref_; }
  std::size_t num_edges() const { return edges_.size(); }
  std::size_t memory_bytes() const;

 private:
  struct Hinge {
    int i, j, k, l;  ///< edge (i, j), opposite vertices k (triangle i, j, k) and l (triangle j, i, l)
    int node(std::size_t s) const { return s == 0 ? i : s == 1 ? j : s == 2 ? k : l; }
  };
  struct Work;
  static Work& workspace();
  void curvature(std::span<const Vec3> X, Work& w, bool with_gradient) const;

  double kappa_B_;
  std::vector<std::array<int, 3>> tris_;  ///< flat triangles, 4 per element (element = index / 4)
  std::vector<Hinge> edges_;              ///< interior edges, ascending in (min, max) node index
  std::vector<int> edge_start_, edge_slot_;  ///< node i's hinge slots 4 e + s (s: i, j, k, l), ascending in e
  std::vector<int> tri_start_, tri_slot_;    ///< node i's triangle slots 3 t + s, ascending in t
  std::vector<double> c_ref_;                ///< 2Hbar_i
  bool threaded_;
};

}  // namespace immerse
