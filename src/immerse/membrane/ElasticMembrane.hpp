#pragma once
// Elastic forces of a closed capsule membrane of six-node curved triangles (paper §2.3, §3, eqs. 15-27, 38-42).
//
// In-plane: the law W(A1, A2) (MaterialLaw) gives the tension tau (18) from B = A A^T (17), A from (39).
// Bending:  m = kappa_B (kappa - kappa_m^R P) (25), kappa = grad_s N (40) at the nodes from a local quartic fit
//           (CurvatureFit), K = (P.grad) m from (41), q from (27).
// Two ways to turn these into nodal forces (newtons, ready for spreading with eq. 6):
//   ForceMethod::Contour  eq. (42): per element F_e = oint [b.tau + (b.q) n] dl along the three curved edges
//                         (3-point Gauss on each quadratic edge), with tau, q, n interpolated from nodal values
//                         that are averages over the elements sharing a node. F_e = S_e fbar_e is then shared
//                         among the element's six nodes in proportion to their lumped areas (node_area).
//   ForceMethod::Energy   F_i = -dE/dX_i of E = sum_e sum_gp W(A1, A2) Jbar w + E_B (6-point rule on each curved
//                         element, A from the element's own interpolation; E_B the discrete mean-curvature energy
//                         of MeanCurvatureBending): exact linear and angular momentum, and an implicit step that
//                         cannot create energy (docs/energy-budget.md).
// Optionally the global volume and area constraints of VolumeAreaConstraint are added to either (exact -dE/dX of
// their penalty energies about the volume and area of mesh.nodes; docs/volume-conservation.md).
// See docs/membrane-bending.md for the derivations, the lumping rule and the two deviations from the paper
// (element-node tensions, not deformation gradients, are averaged at nodes; nodal curvature by a local fit
// instead of averaging the element-wise (40), so that the nodal bending load converges).
// Verified by: the studies membrane_rigid_motion, membrane_inflation, membrane_energy_gradient,
// membrane_force_agreement, membrane_momentum and membrane_bending, and the tests MembraneForce.*.
#include <cstddef>
#include <optional>
#include <span>
#include <vector>

#include "immerse/core/Vec3.hpp"
#include "immerse/membrane/CurvatureFit.hpp"
#include "immerse/membrane/MaterialLaw.hpp"
#include "immerse/membrane/MeanCurvatureBending.hpp"
#include "immerse/membrane/Mesh.hpp"
#include "immerse/membrane/VolumeAreaConstraint.hpp"

namespace immerse {

enum class ForceMethod { Contour, Energy };

/// The parts of a membrane's discrete energy (J).
struct MembraneEnergy {
  double elastic = 0;     ///< in-plane: sum_e sum_gp W(A1, A2) Jbar w
  double bending = 0;     ///< MeanCurvatureBending's E_B (0 without bending)
  double constraint = 0;  ///< VolumeAreaConstraint's penalty energies
  double total() const { return elastic + bending + constraint; }
};

/// Per-node strain and tension for output: invariants (19)-(20), principal stretches and principal tensions.
struct NodeStrain {
  double A1, A2;
  double lambda1, lambda2;  ///< lambda1 >= lambda2
  double tau1, tau2;        ///< principal tensions, N/m, tau1 >= tau2
};

class ElasticMembrane {
 public:
  /// `reference` holds the unstressed positions Xbar (indexed like mesh.nodes). InputError on size mismatch,
  /// bad element indices, kappa_B < 0, a negative constraint modulus or a degenerate reference element. The
  /// constraints (if any modulus > 0) hold the volume and area of mesh.nodes (in a run: the initial shape).
  ElasticMembrane(const Mesh& mesh, std::vector<Vec3> reference, MaterialLaw law, Bending bending,
                  ForceMethod method, ConstraintModuli constraint = {});

  /// Nodal forces F (N) exerted by the membrane at positions X (read in place; F resized to the node count),
  /// constraint forces included. Thread-safe for concurrent calls; OpenMP inside; independent of the thread count.
  /// SimulationError naming the element if one inverts or degenerates (Jacobian <= 0 or not finite).
  void compute_force(std::span<const Vec3> X, std::vector<Vec3>& F) const;
  /// Discrete in-plane elastic energy E (J) = sum_e sum_gp W(A1, A2) Jbar w (without bending and constraints).
  double compute_energy(std::span<const Vec3> X) const;
  /// In-plane, bending (E_B of MeanCurvatureBending, also reported for the contour method, whose forces are not
  /// its gradient) and constraint energies at X.
  MembraneEnergy energy_parts(std::span<const Vec3> X) const;

  /// Strain and tension at each node: invariants A1, A2 at the element nodes averaged over the elements sharing
  /// the node, principal stretches from them and principal tensions from (18) in principal axes.
  std::vector<NodeStrain> node_strain(std::span<const Vec3> X) const;
  /// Lumped area a_i (m^2) each node carries at X; sum_i a_i = total area. Force density at node i = F_i / a_i
  /// for the contour method.
  std::vector<double> node_area(std::span<const Vec3> X) const;
  /// Unit normal at each node: normalized average of the normals of the elements sharing it (used by eq. 42).
  std::vector<Vec3> node_normal(std::span<const Vec3> X) const;
  /// kappa_m^R of eq. (25) per node (1/m) for the contour method; zero unless kappa_B > 0 with
  /// ReferenceCurvature::RestShape and ForceMethod::Contour.
  const std::vector<double>& reference_curvature() const { return kappa_ref_; }

  std::size_t num_nodes() const { return reference_.size(); }
  std::size_t num_elements() const { return elements_.size(); }
  /// The elements' node indices (Mesh::elements).
  const std::vector<std::array<int, 6>>& elements() const { return elements_; }
  ForceMethod method() const { return method_; }
  /// Curved area of each element in the stress-free reference (element_areas of Geometry), the denominators of
  /// the local area ratio.
  std::span<const double> reference_element_areas() const { return ref_element_area_; }
  /// The global volume and area constraints, when a modulus is > 0.
  const std::optional<VolumeAreaConstraint>& constraint() const { return constraint_; }
  const MaterialLaw& law() const { return law_; }
  /// Bytes held by this object (reference data, incidence) plus the workspace compute_force keeps per calling
  /// thread.
  std::size_t memory_bytes() const;

 private:
  struct Work;
  static Work& workspace();  ///< compute_force's scratch data, one per calling thread
  void check_size(std::span<const Vec3> X) const;
  void node_pass(std::span<const Vec3> X, bool with_tension, Work& w) const;
  void moment_pass(std::span<const Vec3> X, Work& w) const;
  void bending_passes(std::span<const Vec3> X, Work& w) const;
  void contour_forces(std::span<const Vec3> X, bool with_tension, bool with_bending, Work& w) const;
  void energy_forces(std::span<const Vec3> X, Work& w) const;
  std::vector<double> reference_mean_curvature() const;

  std::vector<std::array<int, 6>> elements_;
  std::vector<Vec3> reference_;
  MaterialLaw law_;
  Bending bending_;
  ForceMethod method_;
  std::vector<int> inc_start_;  ///< node i's element-node slots are inc_[inc_start_[i] .. inc_start_[i+1])
  std::vector<int> inc_;        ///< slot 6 e + k: element e, local node k; ascending in e
  std::vector<double> ref_node_;  ///< per element node: Gbar^{xx}, Gbar^{xe}, Gbar^{ee}, Jbar (4 doubles)
  std::vector<double> ref_quad_;  ///< per quadrature point: Gbar^{xx}, Gbar^{xe}, Gbar^{ee}, Jbar w
  std::vector<double> kappa_ref_;
  std::vector<double> ref_element_area_;
  bool threaded_ = false;  ///< large enough for OpenMP threads (kMinElementsForThreads)
  std::optional<CurvatureFit> fit_;  ///< nodal normal and curvature for the bending moments (kappa_B > 0)
  std::optional<VolumeAreaConstraint> constraint_;
  std::optional<MeanCurvatureBending> bending_energy_;  ///< kappa_B > 0
};

}  // namespace immerse
