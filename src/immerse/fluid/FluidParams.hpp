#pragma once
// Physical parameters of the incompressible Navier–Stokes equations (1)–(3), paper §2.1:
//   rho (u_t + u·∇u) = −∇p + mu Δu + F + f_body,   ∇·u = 0,   u = u_b on the walls.
// f_body is a uniform body force (a mean pressure gradient) that drives periodic channel/duct flow.
// On a wall axis a, the wall at the lower end moves with wall_lower[a] and the one at the upper end
// with wall_upper[a] (constant in time); entries for periodic axes are ignored.
// Also the one numerical choice of the step (NavierStokesSolver.hpp): the pressure that (9) takes.
#include <array>
#include <memory>

#include "immerse/core/Vec3.hpp"
#include "immerse/grid/Grid.hpp"

namespace immerse {

class WallGeometry;

/// The pressure in the momentum step (9): p^{n−1/2} as printed (Lagged), or extrapolated to t^{n+1/2} from p^{n−1/2}
/// and p^{n−3/2} (Extrapolated; second order in time also where the fluid is a Stokes flow at the step's scale).
enum class PressurePredictor { Lagged, Extrapolated };

struct FluidParams {
  double rho = 1.0;
  double mu = 1.0;
  Vec3 body_force{};
  std::array<Vec3, 3> wall_lower{};
  std::array<Vec3, 3> wall_upper{};
  PressurePredictor pressure = PressurePredictor::Lagged;
  /// Viscosity contrast (NavierStokesSolver.hpp, docs/viscosity-contrast.md): μ(x) = mu (1 + χ(x)) with χ given to
  /// each step, and the implicit part of (9) taken with mu_implicit = implicit_ratio · mu ≥ max μ(x). Off: the
  /// constant-viscosity step of the paper.
  bool variable_viscosity = false;
  double implicit_ratio = 1.0;
  /// fluid.flow_rate: every step ends at the mean velocity flow_mean_velocity along the periodic axis flow_axis (−1:
  /// off), by the uniform body force it adds along that axis (NavierStokesSolver.hpp, "Flow rate").
  int flow_axis = -1;
  double flow_mean_velocity = 0;
  /// Rigid walls of any shape inside a periodic box ([[wall]]; GhostCellWalls): null for none.
  std::shared_ptr<const WallGeometry> walls;

  /// Throws a one-line InputError unless rho, mu > 0 and finite, the body force and wall velocities are finite,
  /// and on every wall axis the normal wall velocity is the same at both walls (zero net flux through the
  /// boundary: the pressure Neumann problem (11) is then solvable), implicit_ratio ≥ 1 and finite, and the flow axis
  /// (if any) periodic.
  void validate(const Grid& grid) const;
};

struct FluidState;
/// `params` with the body force of the step that reached `state`: fluid.flow_rate's added force included.
FluidParams step_params(const FluidParams& params, const FluidState& state);

}  // namespace immerse
