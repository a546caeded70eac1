#pragma once
// The committed state of the fluid between two time steps of the projection method (paper eqs. 9–13).
#include <cstdint>

#include "immerse/core/Array3.hpp"
#include "immerse/grid/FaceField.hpp"

namespace immerse {

struct FluidState {
  FaceField u;         ///< velocity u^n on the MAC faces (wall faces hold the normal wall velocity)
  Array3 p;            ///< pressure p^{n-1/2} at the cell centres (a half step behind u)
  Array3 p_prev;       ///< the pressure before it, p^{n-3/2} (a step's pressure only when dt_prev2 > 0)
  FaceField u_prev;    ///< u^{n-1}, kept only with a variable viscosity (its explicit part is extrapolated); else empty
  FaceField adv;       ///< advection term (u·∇_h u)^{n-1} of the previous step, for Adams–Bashforth (10)
  double dt_prev = 0;  ///< time step that produced u^n (0 before the first step)
  double dt_prev2 = 0; ///< the step before it, which produced p^{n-3/2} (0 before the second step)
  long step = 0;       ///< number of steps taken
  double time = 0;     ///< t^n
  /// With fluid.flow_rate: the body force that the step which produced this state added along the flow axis to end
  /// at the flow rate (N/m^3); 0 otherwise.
  double flow_force = 0;
  /// Which prepared step's (u·∇_h u)^n `adv` holds (NavierStokesSolver::step(prepared, …) sets it and then skips
  /// copying it again into this state; 0: none). Whoever else writes `adv` in place sets it to 0.
  std::uint64_t adv_of = 0;
};

}  // namespace immerse
