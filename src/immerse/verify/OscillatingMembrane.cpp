#include "immerse/verify/OscillatingMembrane.hpp"

#include <cmath>

#include "immerse/core/Error.hpp"
#include "immerse/membrane/Geometry.hpp"
#include "immerse/membrane/MeshGenerator.hpp"
#include "immerse/membrane/NeoHookean.hpp"
#include "immerse/membrane/Shape.hpp"

namespace immerse::verify {

namespace {
Shape centred(decltype(Shape::form) form) {
  Shape s{form, {}};
  s.placement.translation = {0.5, 0.5, 0.5};
  return s;
}
FluidParams fluid_params(double mu) {
  FluidParams p;
  p.rho = 1.0;
  p.mu = mu;
  return p;
}
}  // namespace

double OscillatingMembrane::equilibrium_radius() { return std::cbrt(a * b * c); }

OscillatingMembrane::OscillatingMembrane(int n, int mesh_level, double mu)
    : grid_({n, n, n}, {1.0, 1.0, 1.0}, {Boundary::Wall, Boundary::Wall, Boundary::Wall}),
      fluid_(grid_, fluid_params(mu)),
      coupler_(grid_),
      mesh_(octahedral_sphere(mesh_level)),
      membrane_(mesh_, map_sphere(centred(Sphere{r0}), mesh_.nodes), NeoHookean(Es), Bending{},
                ForceMethod::Contour) {
  const auto reference = map_sphere(centred(Sphere{r0}), mesh_.nodes);
  weights_ = node_area_weights(mesh_, reference);
  op_ = std::make_unique<ImmersedBoundaryOperator>(
      fluid_, coupler_, std::vector<const ElasticMembrane*>{&membrane_},
      std::vector<std::vector<Vec3>>{map_sphere(centred(Ellipsoid{a, b, c}), mesh_.nodes)}, fluid_.initial_state());
}

void OscillatingMembrane::run_to(MembraneIntegrator& integrator, double T, double dt) {
  double t = op_->fluid_state().time;
  while (t < T - 1e-12 * T) {
    const double step = std::min(dt, T - t);
    const auto st = integrator.step(*op_, step);
    if (!st.converged) throw SimulationError("§4.1 run: step at t = " + std::to_string(t) + " failed: " + st.failure);
    t = op_->fluid_state().time;
  }
}

}  // namespace immerse::verify
