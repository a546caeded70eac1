#pragma once
// Nodal unit normal and curvature tensor (40) of a surface of six-node triangles by a local least-squares
// quartic fit, for the bending moments (25). Used instead of averaging the element-wise (40) of interpolated
// nodal normals, whose nodal error is only O(h) on a general surface (docs/membrane-bending.md, §2).
//
// Set-up (reference configuration Xbar, once): node i's neighbours p are all the nodes of the elements
// incident to i and of the elements sharing an edge with those (20 for a mid-side node, 30-36 for a vertex).
// They get chart coordinates (s_p, t_p) = ((Xbar_p - Xbar_i).e1, (Xbar_p - Xbar_i).e2) in the tangent plane
// of a first normal estimate e3 (the normalized sum of the incident elements' chord normals), scaled by the
// neighbourhood radius. The least-squares fit of the 14 monomials
// s^a t^b, 1 <= a + b <= 4, to values g_p - g_i is linear in the data: its derivatives at the node are fixed
// weighted sums, g_s = sum_p w^s_p (g_p - g_i) and likewise g_t, g_ss, g_st, g_tt; the weights are stored.
//
// Evaluation (any configuration X): the same weights applied to the positions give X_s, X_t, X_ss, X_st, X_tt
// of the smooth map (s, t) -> X at node i, and
//   normal     N = X_s x X_t / |X_s x X_t|
//   metric     g_ab = X_a . X_b,  dual basis a^a = g^{ab} X_b,  b_ab = N . X_ab
//   (40)       kappa = grad_s N = -b_ab a^a (x) a^b          (kappa = P/R on a sphere, outward normal)
// A degree-4 fit gives second derivatives to O(h^3) and first ones to O(h^4) on a smooth surface. The result
// is a linear function of the positions followed by frame-indifferent algebra, so it is exactly equivariant
// under rigid motions of X (to round-off) and independent of the thread count.
// Verified by: the tests MembraneForce.CurvatureFit* (normal and mean curvature on an ellipsoid converge, kappa
// tangent; a degenerate neighbourhood refused) and the study membrane_bending (linearized load of a Y_lm sphere).
#include <cstddef>
#include <span>
#include <vector>

#include "immerse/core/Mat3.hpp"
#include "immerse/core/Vec3.hpp"
#include "immerse/membrane/Mesh.hpp"

namespace immerse {

class CurvatureFit {
 public:
  /// Neighbourhoods from the connectivity of `mesh`, chart and weights from the reference positions.
  /// InputError naming the node if a neighbourhood does not determine the fit.
  CurvatureFit(const Mesh& mesh, const std::vector<Vec3>& reference);

  /// Unit normal N_i and curvature tensor kappa_i at every node of the configuration X.
  void compute(std::span<const Vec3> X, std::vector<Vec3>& normal, std::vector<Mat3>& kappa) const;

  std::size_t memory_bytes() const {
    return (start_.size() + nbr_.size()) * sizeof(int) + weights_.size() * sizeof(double);
  }

 private:
  std::vector<int> start_;        ///< node i's neighbours are nbr_[start_[i] .. start_[i+1])
  std::vector<int> nbr_;
  std::vector<double> weights_;   ///< per neighbour entry: w^s, w^t, w^ss, w^st, w^tt (5 doubles)
};

}  // namespace immerse
