#include "immerse/membrane/VolumeCorrection.hpp"

#include <cmath>
#include <sstream>

#include "immerse/core/Error.hpp"
#include "immerse/membrane/MeshElement.hpp"
#include "immerse/membrane/VolumeAreaConstraint.hpp"

namespace immerse {

std::vector<Vec3> area_weighted_normals(const Mesh& mesh, const std::vector<Vec3>& X) {
  std::vector<Vec3> n(X.size());
  for (const auto& el : mesh.elements) {
    MeshElement::Nodes x;
    for (int i = 0; i < 6; ++i) x[i] = X[el[i]];
    for (int k = 0; k < 6; ++k) {
      const auto& p = MeshElement::node_coordinates[k];
      n[el[k]] += MeshElement::jacobian(x, p[0], p[1]);
    }
  }
  for (auto& v : n) v = normalized(v);
  return n;
}

double normal_shift(const Mesh& mesh, std::vector<Vec3>& X, double V0) {
  const std::vector<Vec3> n = area_weighted_normals(mesh, X), X0 = X;
  constexpr int kMaxIterations = 10;
  constexpr double kTolerance = 1e-13;  // relative volume error: above the round-off of the quadrature's sum
  double s = 0, error = 0;
  for (int it = 0; it < kMaxIterations; ++it) {
    const SurfaceGradients g = surface_gradients(mesh.elements, X, false);
    error = g.volume - V0;
    if (std::abs(error) <= kTolerance * V0) return s;
    double slope = 0;
    for (std::size_t i = 0; i < X.size(); ++i) slope += dot(g.d_volume[i], n[i]);
    s -= error / slope;
    for (std::size_t i = 0; i < X.size(); ++i) X[i] = X0[i] + s * n[i];
  }
  std::ostringstream msg;
  msg << "volume correction (normal_shift) did not converge: relative volume error " << error / V0 << " after "
      << kMaxIterations << " Newton iterations";
  throw SimulationError(msg.str());
}

}  // namespace immerse
