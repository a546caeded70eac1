#pragma once
// The points through which a membrane's nodes meet the fluid, and the transfer between nodes and points.
//
// Coupling at every node is the paper's (eqs. 6 and 14): the points are the nodes. Coupling through the nodes of a
// coarser mesh of the same surface (a generated sphere mesh at a lower subdivision level, whose nodes are a subset of
// the fine mesh's) keeps the finite-element mechanics on the fine mesh and meets the fluid through points about one
// to two grid cells apart (Griffith & Luo 2017, Int. J. Numer. Meth. Biomed. Eng. 33:e2888, on decoupling the
// coupling density from the mesh):
//
//   X_c = X|points            the points are nodes, so they move with their nodes
//   U   = P U_c               node velocities: the coarse quadratic elements' interpolant of the points' velocities
//   F_c = Pᵀ F                the nodal forces gathered onto the points
//
// P_ik = N_k(ξ_i), the coarse element's six quadratic shape functions at the parametric position ξ_i of node i on
// the unit sphere the meshes are generated on (P is the identity on the points' own nodes). Because F_c = Pᵀ F, the
// transfer is adjoint: Σ_k F_c,k · U_c,k = Σ_i F_i · U_i for every U_c, so the power the membrane gives the fluid
// is the power its forces do on the nodes, and with Σ_k P_ik = 1 the total force is kept (Σ F_c = Σ F) and uniform
// translations are exact.
// Verified by: the tests CouplingPoints.* (points a subset, identity rows, adjointness, partition of unity,
// quadratic reproduction, concatenation).
#include <cstddef>
#include <span>
#include <vector>

#include "immerse/core/Vec3.hpp"
#include "immerse/membrane/Mesh.hpp"

namespace immerse {

class CouplingPoints {
 public:
  /// Coupling at each of `num_nodes` nodes (P = I).
  explicit CouplingPoints(std::size_t num_nodes = 0);
  /// Coupling through the nodes of `coarse`: both meshes on the unit sphere, every node of `coarse` a node of
  /// `fine` (the generated meshes of one family at two levels). Throws std::invalid_argument otherwise.
  CouplingPoints(const Mesh& fine, const Mesh& coarse);
  /// The membranes' transfers one after the other, as their nodes are concatenated.
  static CouplingPoints concatenate(std::span<const CouplingPoints* const> parts);

  /// True when every node is a point (P = I).
  bool every_node() const { return every_node_; }
  std::size_t num_nodes() const { return row_.size() - 1; }
  std::size_t num_points() const { return point_node_.size(); }
  /// The node of each point.
  const std::vector<std::size_t>& point_nodes() const { return point_node_; }

  /// Xc[k] = X[point_nodes()[k]].
  void gather(std::span<const Vec3> X, std::span<Vec3> Xc) const;
  /// Fc = Pᵀ F.
  void restrict_forces(std::span<const Vec3> F, std::span<Vec3> Fc) const;
  /// U = P Uc.
  void prolong(std::span<const Vec3> Uc, std::span<Vec3> U) const;
  /// Spreading through the points, f = S(X_c) Pᵀ F, by `coupler` (IBCoupler or SlabIBCoupler): X, F at the nodes.
  template <class Coupler, class Field>
  void spread(Coupler& coupler, std::span<const Vec3> X, std::span<const Vec3> F, Field& f) {
    if (every_node_) return coupler.spread_force(X, F, f);
    Xc_.resize(num_points());
    Fc_.resize(num_points());
    gather(X, Xc_);
    restrict_forces(F, Fc_);
    coupler.spread_force(Xc_, Fc_, f);
  }
  /// Interpolation through the points, U = P J(X_c) u, by `coupler`: X, U at the nodes.
  template <class Coupler, class Field>
  void interpolate(Coupler& coupler, const Field& u, std::span<const Vec3> X, std::span<Vec3> U) {
    if (every_node_) return coupler.interpolate_velocity(u, X, U);
    Xc_.resize(num_points());
    Uc_.resize(num_points());
    gather(X, Xc_);
    coupler.interpolate_velocity(u, Xc_, Uc_);
    prolong(Uc_, U);
  }

  /// The weights of node i: P_ik for k = columns(i)[j], weights(i)[j].
  std::span<const std::size_t> columns(std::size_t i) const {
    return {col_.data() + row_[i], row_[i + 1] - row_[i]};
  }
  std::span<const double> weights(std::size_t i) const { return {w_.data() + row_[i], row_[i + 1] - row_[i]}; }

 private:
  bool every_node_ = true;
  std::vector<std::size_t> point_node_;
  std::vector<std::size_t> row_{0};  ///< node i's entries are [row_[i], row_[i + 1])
  std::vector<std::size_t> col_;
  std::vector<double> w_;
  std::vector<Vec3> Xc_, Fc_, Uc_;  ///< work arrays of spread and interpolate
};

}  // namespace immerse
