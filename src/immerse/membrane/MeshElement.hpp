#pragma once
// The six-node curved triangle of eq. (38): u(ξ, η) = Σ_i u_i N_i(ξ, η) on the parent triangle
// ξ, η >= 0, ξ + η <= 1, with L0 = 1 - ξ - η, L1 = ξ, L2 = η and node order {v0, v1, v2, m01, m12, m20}:
//   N_k = L_k (2 L_k - 1) (vertices),  N_3 = 4 L0 L1,  N_4 = 4 L1 L2,  N_5 = 4 L2 L0 (mid-side nodes).
// The surface Jacobian vector J = ∂X/∂ξ × ∂X/∂η gives n dA = J dξ dη (outward for counter-clockwise vertices).
// Quadrature: Dunavant's 7-point rule, exact for polynomials of degree 5 on the parent triangle.
#include <array>

#include "immerse/core/Vec3.hpp"

namespace immerse {

struct MeshElement {
  using Nodes = std::array<Vec3, 6>;

  /// N_i(ξ, η), i = 0..5.
  static constexpr std::array<double, 6> shape(double xi, double eta) {
    const double l0 = 1.0 - xi - eta, l1 = xi, l2 = eta;
    return {l0 * (2 * l0 - 1), l1 * (2 * l1 - 1), l2 * (2 * l2 - 1), 4 * l0 * l1, 4 * l1 * l2, 4 * l2 * l0};
  }
  /// ∂N_i/∂ξ.
  static constexpr std::array<double, 6> shape_dxi(double xi, double eta) {
    const double l0 = 1.0 - xi - eta, l1 = xi, l2 = eta;
    return {-(4 * l0 - 1), 4 * l1 - 1, 0.0, 4 * (l0 - l1), 4 * l2, -4 * l2};
  }
  /// ∂N_i/∂η.
  static constexpr std::array<double, 6> shape_deta(double xi, double eta) {
    const double l0 = 1.0 - xi - eta, l1 = xi, l2 = eta;
    return {-(4 * l0 - 1), 0.0, 4 * l2 - 1, -4 * l1, 4 * l1, 4 * (l0 - l2)};
  }

  static constexpr Vec3 interpolate(const Nodes& x, const std::array<double, 6>& n) {
    Vec3 s;
    for (int i = 0; i < 6; ++i) s += n[i] * x[i];
    return s;
  }
  static constexpr Vec3 position(const Nodes& x, double xi, double eta) { return interpolate(x, shape(xi, eta)); }
  /// J = ∂X/∂ξ × ∂X/∂η; |J| is the area element of the curved surface per unit parent area.
  static constexpr Vec3 jacobian(const Nodes& x, double xi, double eta) {
    return cross(interpolate(x, shape_dxi(xi, eta)), interpolate(x, shape_deta(xi, eta)));
  }

  /// Parent coordinates (ξ, η) of the six nodes.
  static constexpr std::array<std::array<double, 2>, 6> node_coordinates{
      {{0, 0}, {1, 0}, {0, 1}, {0.5, 0}, {0.5, 0.5}, {0, 0.5}}};

  struct QuadraturePoint {
    double xi, eta, weight;  ///< weights sum to 1/2, the parent triangle's area
  };
  static constexpr std::array<QuadraturePoint, 7> quadrature{{
      {1.0 / 3.0, 1.0 / 3.0, 0.1125},
      {0.059715871789769820, 0.47014206410511509, 0.066197076394253090},
      {0.47014206410511509, 0.059715871789769820, 0.066197076394253090},
      {0.47014206410511509, 0.47014206410511509, 0.066197076394253090},
      {0.79742698535308732, 0.10128650732345634, 0.062969590272413576},
      {0.10128650732345634, 0.79742698535308732, 0.062969590272413576},
      {0.10128650732345634, 0.10128650732345634, 0.062969590272413576},
  }};
};

}  // namespace immerse
