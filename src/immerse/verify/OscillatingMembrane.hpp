#pragma once
// The oscillating membrane of the paper's §4.1, assembled for the integrator studies:
//   unit box with no-slip walls on all six faces, n^3 cells, fluid at rest, rho = 1, viscosity mu;
//   neo-Hookean membrane (E_s = 0.1) whose stress-free state is the sphere of radius 0.2 at the box centre, started
//   as the ellipsoid (0.25, 0.22, 0.2) of eq. (43); it relaxes to the sphere of radius (abc)^(1/3) = 0.2224.
// The membrane mesh is the octahedral family (level 5 = the paper's 16,386 nodes / 8,192 elements).
#include <memory>
#include <string>

#include "immerse/coupling/IBCoupler.hpp"
#include "immerse/fluid/NavierStokesSolver.hpp"
#include "immerse/membrane/ElasticMembrane.hpp"
#include "immerse/membrane/Mesh.hpp"
#include "immerse/simulation/ImmersedBoundaryOperator.hpp"
#include "immerse/timestep/MembraneIntegrator.hpp"

namespace immerse::verify {

class OscillatingMembrane {
 public:
  static constexpr double a = 0.25, b = 0.22, c = 0.2, r0 = 0.2, Es = 0.1;
  /// Radius of the equilibrium sphere, (abc)^(1/3).
  static double equilibrium_radius();

  OscillatingMembrane(int n, int mesh_level, double mu);

  const Grid& grid() const { return grid_; }
  const Mesh& mesh() const { return mesh_; }
  ImmersedBoundaryOperator& op() { return *op_; }
  /// Node weights Delta q Delta r Delta s of the Lagrangian L2 norm of §4.1 (reference-surface areas).
  const std::vector<double>& node_weights() const { return weights_; }

  /// Advances to time T with fixed steps dt (the last one shortened to land on T). Throws SimulationError if
  /// a step fails to converge.
  void run_to(MembraneIntegrator& integrator, double T, double dt);

 private:
  Grid grid_;
  NavierStokesSolver fluid_;
  IBCoupler coupler_;
  Mesh mesh_;
  ElasticMembrane membrane_;
  std::vector<double> weights_;
  std::unique_ptr<ImmersedBoundaryOperator> op_;
};

}  // namespace immerse::verify
