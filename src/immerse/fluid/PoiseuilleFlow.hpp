#pragma once
// Steady pressure-driven flow of the discrete equations (9)-(12): a uniform body force f (a mean pressure
// gradient) along periodic axes, between resting no-slip walls. Each driven component solves
//   mu lap_h u_d = -f_d,   u_d = 0 on the walls,
// and is independent of the periodic coordinates, so u.grad_h u = 0, the pressure is uniform and u is an exact
// steady state of the discrete Navier-Stokes step (one fast-transform solve per component). In a rectangular duct
// it converges at second order to the series solution (the study duct_poiseuille shows the same of the discrete
// duct problem solved directly).
// With [[wall]] tubes along the body force's axis (FluidParams::walls), the same in the cut-cell discretization
// (GhostCellWalls::steady_flow on a section two cells long): a steady state of the step with walls.
// Verified by the tests PoiseuilleFlow.* (a steady state of the discrete step, second order to the series, input
// checks) and RbcChannel.ThirtyTwoCellsInAPoiseuilleDuctWithTheirDiagnostics (the channel starts from it).
#include "immerse/fluid/FluidParams.hpp"
#include "immerse/grid/FaceField.hpp"
#include "immerse/grid/Grid.hpp"

namespace immerse {

/// Overwrites u with the discrete Poiseuille flow of params.body_force. InputError (naming fluid.body_force,
/// boundary.*_velocity or fluid.initial) unless there is a wall axis, all walls rest and f is zero along wall axes; or,
/// with [[wall]] shapes, unless they are tubes along the one axis of the body force (naming wall[i].axis).
void set_poiseuille_flow(const Grid& grid, const FluidParams& params, FaceField& u);

/// The mean of u along `axis` over the box in that flow (the faces as FaceField holds them, as the runs' mean_velocity
/// takes it), computed on a box two cells long along every periodic axis: the flow does not depend on those
/// coordinates. The same InputErrors as set_poiseuille_flow.
double poiseuille_mean_velocity(const Grid& grid, const FluidParams& params, int axis);

}  // namespace immerse
