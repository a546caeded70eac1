#pragma once
// One time step of the pressure-increment projection method on the MAC grid, paper §2.2, eqs. (9)–(13)
// (Brown, Cortez & Minion 2001). Given u^n, p^{n−1/2}, (u·∇_h u)^{n−1} and the force F^{n+1/2}:
//
//   (9)   ρ (u* − u^n)/Δt = −ρ A^{n+1/2} − G p^{n−1/2} + (μ/2) ∇_h²(u* + u^n) + F^{n+1/2} + f_body,  u*|∂Ω = u_b
//   (10)  A^{n+1/2} = (1 + r/2) (u·∇_h u)^n − (r/2) (u·∇_h u)^{n−1},  r = Δt/Δt_prev
//         (Adams–Bashforth 2 for a variable step; r = 1 gives the paper's 3/2, −1/2; the first step is
//         forward Euler, A = (u·∇_h u)^0)
//   (11)  D G φ = (ρ/Δt) D u*,  n·∇φ = 0 on walls
//   (12)  u^{n+1} = u* − (Δt/ρ) G φ
//   (13)  p^{n+1/2} = p^{n−1/2} + φ − (μ/2) D u*
//
// Eq. (13) as printed, p^{n−1/2} + φ − (μ/2ρ) D u*, is dimensionally inconsistent (μ D u / ρ is not a pressure);
// with φ scaled as in (11) the pressure update of Brown–Cortez–Minion (2001) is the one used here.
// (9) is three Helmholtz problems (I − (μΔt/2ρ) ∇_h²) u*_d = rhs_d and (11) one Poisson problem; all four are
// solved directly by FftHelmholtzSolver. Since G is applied only at interior faces and ∇_h² for φ is D G with G φ = 0 on
// walls, D u^{n+1} = 0 to round-off.
//
// The pressure of (9) (FluidParams::pressure). As printed, p^{n−1/2}, half a step behind t^{n+1/2}: where the fluid
// is a Stokes flow at the step's scale (ν Δt/h² ≫ 1, as in §4.4) the lag errs by O(Δt) wherever the pressure changes
// at O(1) rates (across a moving membrane, at the walls), and the membrane positions converge at first order only
// (docs/time-integration.md). Extrapolated, (9) and (13) take instead
//   p̃ = p^{n−1/2} + w (p^{n−1/2} − p^{n−3/2}),   w = (Δt + Δt_prev) / (Δt_prev + Δt_prev2),
// the line through p^{n−1/2} at t^n − Δt_prev/2 and p^{n−3/2} at t^{n−1} − Δt_prev2/2, taken to t^{n+1/2} (w = 1 for
// a constant step; w = 0 until two steps are taken), and the positions converge at second order there too.
//
// step(in, F, Δt) builds the right-hand side of (9) in one pass over the faces. A step may also be split in two:
// prepare() does the part that depends on the state and Δt alone, the explicit terms
// E = −ρ A^{n+1/2} − G p^{n−1/2} + (μ/2) ∇_h² u^n of (9) and (10); step(prepared, F) adds the force,
// rhs = u^n + (Δt/ρ)((E + F) + f_body), and does the solves (9), (11) and (12)–(13). The trials of an implicit
// step are fluid steps from the same state with the same Δt under different forces: they share one prepare().
// Both paths evaluate the same pointwise functions, the sums of u^n + (Δt/ρ)(−ρ A − G p + (μ/2) ∇_h² u^n + F +
// f_body) taken left to right, so the split step is bitwise the one-pass one.
//
// Flow rate (FluidParams::flow_axis, fluid.flow_rate). The step is linear in the body force, the advection term and
// the pressure being those of the state before it: a uniform ΔG added along the flow axis a adds ΔG w to u_a^{n+1},
//   w = (I − (μΔt/2ρ) ∇_h²)⁻¹ Δt/ρ
// (one fast solve per step size; D w = 0 since w does not vary along a periodic a, so the projection leaves it). After
// (12) each step adds ΔG w with ΔG = (U* − ⟨u_a^{n+1}⟩)/⟨w⟩, ⟨·⟩ the mean over the box: the step that ends at the mean
// velocity U* under the body force f_body + ΔG, exactly, whatever the membranes do (the constant flow rate of channel-
// flow codes). ΔG goes into the new state (FluidState::flow_force) for the diagnostics and the energy budget. With
// [[wall]] shapes, w is the walls' solve of the same problem and ⟨·⟩ sums the fluid's points only (for a divergence-
// free field the mean of u_a over the box is the flow rate through any cross-section over the box's); walls that vary
// along a (a constriction) give w a divergence, and the response is then w projected by (11)–(13), velocity (all
// three components) and pressure, so that ΔG times it is exactly what the body force ΔG adds to the step.
// Verified by the tests RbcChannel.FlowRateIsHeldWhileThePressureDropRises, RestartFlowRate.* and
// ParallelRun.RedCellChannelAtAFlowRateEqualsTheOneProcessRun.
//
// Walls of any shape (FluidParams::walls, a periodic box): the Helmholtz problems of (9) take the no-slip condition
// on them by GhostCellWalls (two fast solves each); the projection stays periodic.
//
// Variable viscosity (FluidParams::variable_viscosity; docs/viscosity-contrast.md). With μ(x) = μ (1 + χ(x)) the
// viscous term of (9) is ½[∇_h·(μ(∇_h u* + ∇_h u*ᵀ)) + ∇_h·(μ(∇_h u^n + ∇_h u^nᵀ))]. The fast solvers invert only
// the constant part: with μ_p = implicit_ratio · μ ≥ max μ(x) and L_μ the stress operator, (9) takes
//   ½ L_μ(u* + u^n) ≈ (μ_p/2) ∇_h²(u* + u^n) + (L_μ − μ_p ∇_h²) ũ,  ũ = u^n + (r/2)(u^n − u^{n−1}),  r = Δt/Δt_prev
// (ũ = u^n on the first step), the remainder at the extrapolated midpoint velocity: a Douglas–Dupont-type
// stabilization, as in Fai, Griffith, Mori & Peskin (2013, SIAM J. Sci. Comput. 35). With D_h ũ = 0,
// L_μ ũ = μ ∇_h² ũ + μ ∇_h·(χ(∇_h ũ + ∇_h ũᵀ)) (ViscousStress_K.hpp): the first part carries the wall values, the
// second vanishes where χ does and takes the wall values of the first where χ reaches a wall.
// prepare() adds (μ_p − μ) ∇_h²(u^n/2 − ũ) (homogeneous walls) to E; step(prepared, F, out, χ) adds μ ∇_h·(χ S(ũ)).
// (I − (μ_p Δt/2ρ) ∇_h²) is what is inverted, so (13) takes μ_p: p^{n+1/2} = p̃ + φ − (μ_p/2) D u* makes the step's
// u^{n+1} satisfy (9) with G p^{n+1/2} exactly, as (13) does for a constant μ. Without variable viscosity
// μ_p = μ and the step is bitwise the constant-viscosity one. Second order in Δt (the remainder's error is
// (μ_p − μ)∇²(u^{n+1} − 2u^n + u^{n−1})/2 = O(Δt²)); stable in the Stokes limit for μ_p ≥ max μ(x).
// Verified by: the studies fluid_divergence, taylor_green, abc_flow, couette, duct_poiseuille, closed_box_mms and the
// tests NavierStokesSolver.*, CompareRuns.TimeStepErrorInTheStokesRegimeIsSecondOrderWithTheExtrapolatedPressure,
// ViscosityContrast.ManufacturedFlowIsSecondOrderInSpaceAndTime, ViscosityContrast.ManufacturedFlowInAClosedBox*,
// ViscosityContrast.ManufacturedFlowWithTheViscosityVaryingAtTheWalls*,
// ViscosityContrast.UnforcedFlowDecaysInTheStokesLimitWhenTheImplicitViscosityIsTheLargest.
#include <array>
#include <cstdint>
#include <memory>

#include "immerse/fluid/FftHelmholtzSolver.hpp"
#include "immerse/fluid/FluidParams.hpp"
#include "immerse/fluid/FluidState.hpp"
#include "immerse/fluid/GhostCellWalls.hpp"
#include "immerse/fluid/MacStencilGrid.hpp"

namespace immerse {

/// The force-independent part of one step from a state (u^n, p^{n−1/2}, (u·∇_h u)^{n−1}) with a Δt, made by
/// NavierStokesSolver::prepare: step() finishes it under any number of forces. It refers to the state it was
/// prepared from (reading u^n and p^{n−1/2} there) and is valid while that state is unchanged and alive; step()
/// checks that the state still has the step counter and time it was prepared at (std::logic_error otherwise), which
/// catches a state advanced in place but not other changes to its fields.
class PreparedStep {
 public:
  /// Whether this was prepared from the object `s`, at its step and time, with this dt (never, before the first
  /// prepare()). Compares the address, step counter and time, not the fields.
  bool prepared_for(const FluidState& s, double dt) const {
    return state_ == &s && dt == dt_ && s.step == step_ && s.time == time_;
  }

 private:
  friend class NavierStokesSolver;
  const FluidState* state_ = nullptr;  ///< the state prepared from (null: not prepared)
  FaceField adv_;                      ///< (u·∇_h u)^n at the unknowns: the adv of the next state
  FaceField explicit_;  ///< E = −ρ A^{n+1/2} − G p^{n−1/2} + (μ/2) ∇_h² u^n (wall sources included) at the unknowns
  Array3 pressure_;     ///< p̃ of (9) and (13), when extrapolated_
  FaceField utilde_;    ///< ũ, with a variable viscosity
  bool extrapolated_ = false;  ///< whether (9) takes pressure_ (FluidParams::pressure), else p^{n−1/2}
  double dt_ = 0;       ///< Δt
  long step_ = 0;       ///< step and time of the state when prepared
  double time_ = 0;
  std::uint64_t id_ = 0;  ///< unique in the process for each prepare() (FluidState::adv_of)
};

/// The weight w of the extrapolated pressure p̃ = p^{n−1/2} + w (p^{n−1/2} − p^{n−3/2}) for a step dt after steps
/// dt_prev (which produced p^{n−1/2}) and dt_prev2 (which produced p^{n−3/2}); 0 when dt_prev2 = 0 (no p^{n−3/2}).
double extrapolation_weight(double dt, double dt_prev, double dt_prev2);

class NavierStokesSolver {
 public:
  /// Validates the parameters against the grid (InputError) and plans the four fast solvers.
  NavierStokesSolver(const Grid& grid, const FluidParams& params, FftPlanning planning = FftPlanning::Measure);
  NavierStokesSolver(const NavierStokesSolver&) = delete;  // its fast solvers transform its own arrays in place
  NavierStokesSolver& operator=(const NavierStokesSolver&) = delete;

  const Grid& grid() const { return grid_; }
  const FluidParams& params() const { return params_; }

  /// A state at rest (u = 0 apart from the normal wall velocity on the wall faces, p = 0), t = 0.
  FluidState initial_state() const;

  /// Writes into `out` the state one step of size dt after `in` under the force `force` (F^{n+1/2} on the
  /// velocity faces; its wall faces are ignored). Pure: `in` is only read; `out` must be a different object
  /// (it is sized on first use, then reused without allocation). Not reentrant: uses internal work arrays.
  /// Bitwise the same as prepare(in, dt, p) then step(p, force, out), in one pass over the faces for (9).
  /// With a variable viscosity, chi is χ at the cells (null: χ = 0), the viscosity μ (1 + χ) of this step.
  void step(const FluidState& in, const FaceField& force, double dt, FluidState& out, const Array3* chi = nullptr);

  /// Computes into `prepared` the part of the step of size dt after `in` that does not depend on the force: A^{n+1/2}
  /// by (10) and the explicit terms of (9) (`prepared` is sized on first use, then reused without allocation).
  /// `prepared` refers to `in` afterwards: valid while `in` is unchanged and alive.
  void prepare(const FluidState& in, double dt, PreparedStep& prepared) const;

  /// Writes into `out` the state one step after the state `prepared` was made from, under the force `force` (as
  /// step(in, force, dt, out)); `prepared` and its state are only read, so any number of forces may follow one
  /// prepare(). `out` must not be the state prepared from (std::invalid_argument); that state must still have its
  /// step counter and time of prepare() (std::logic_error otherwise). (u·∇_h u)^n is copied into out.adv only when
  /// `out` does not hold it already from an earlier call after the same prepare() (FluidState::adv_of): the trials
  /// of an implicit step, written into one output state, copy it once. Not reentrant: uses internal work arrays.
  /// With a variable viscosity, chi is χ at the cells (null: χ = 0); it may differ from one force to the next.
  void step(const PreparedStep& prepared, const FaceField& force, FluidState& out, const Array3* chi = nullptr);

  /// Writes the normal wall velocity into the wall faces of u (the boundary condition (3)).
  void apply_wall_values(FaceField& u) const;

  /// The no-slip condition of the [[wall]] shapes, if any (null: none).
  const GhostCellWalls* walls() const { return walls_.get(); }

  /// The fast solver of a layout (three velocity components and the pressure).
  FftHelmholtzSolver& fast_solver(Layout layout) { return *solvers_[static_cast<int>(layout)]; }

 private:
  Grid grid_;
  FluidParams params_;
  MacStencilGrid geom_;
  bool matches_grid(const FaceField& f) const;
  void check(const FluidState& in, double dt) const;  // dt > 0 (InputError), `in` on the grid
  void check_force(const FaceField& force) const;
  /// The pressure (9) takes after `in` for a step dt: in.p, or p̃ written into `scratch` (FluidParams::pressure).
  const Array3& momentum_pressure(const FluidState& in, double dt, Array3& scratch) const;
  /// The step of size dt after `in` into `out`, rhs(d) writing the right-hand side of (9) for component d into u*
  /// and (u·∇_h u)^n into out.adv[d]: the solves (9), (11) and (12)–(13), the last from the pressure p that (9) took.
  template <class Rhs>
  void advance(const FluidState& in, double dt, const Array3& p, FluidState& out, Rhs&& rhs);

  /// (11)–(13) on u* (ustar_): the pressure increment, u^{n+1} into out.u and p^{n+1/2} = p0 + φ − (μ/2) D u* into
  /// out.p, pn into out.p_prev.
  void project(double dt, const Array3& p0, const Array3& pn, FluidState& out);
  /// fluid.flow_rate ("Flow rate" above): adds ΔG w to the flow axis's velocity of `out`, w the step's response to a
  /// unit body force along it (cached for the step size), so that its mean is FluidParams::flow_mean_velocity;
  /// out.flow_force = ΔG.
  void hold_flow_rate(double dt, FluidState& out);
  /// Adds (Δt/ρ) μ ∇_h·(χ S(ũ)) to the right-hand side u* of (9) where χ is not zero.
  /// Component d of it, over the box of faces where it may not vanish (variable_stress_box).
  void add_variable_stress(const FaceField& utilde, const Array3& chi, double dt, int d, const IndexBox& box);
  /// The faces whose stress term reads a non-zero χ (an empty box when χ = 0 everywhere).
  IndexBox variable_stress_box(const Array3& chi) const;
  /// ũ and (μ_p − μ) ∇_h²(u^n/2 − ũ) added to the explicit terms of `prepared`.
  void prepare_variable(const FluidState& in, double dt, PreparedStep& prepared) const;

  MacStencilGrid geom0_;        // homogeneous walls: the part of ∇_h² that the remainder of a variable viscosity takes
  double mu_implicit_;   // μ_p (μ without a variable viscosity)
  FluidState flow_response_;       // w (u) and its pressure (p) of hold_flow_rate, for steps of flow_response_dt_
  double flow_response_dt_ = 0;
  double flow_response_mean_ = 0;  // its mean over the box
  PreparedStep own_;     // the one-pass step's preparation, with a variable viscosity
  std::array<std::unique_ptr<FftHelmholtzSolver>, 4> solvers_;
  std::unique_ptr<GhostCellWalls> walls_;  // the no-slip condition of [[wall]] in (9), if any
  FaceField ustar_;  // u*, then u^{n+1}
  Array3 div_;       // D u*
  Array3 phi_;       // pressure increment φ^{n+1}
  Array3 ptilde_;    // p̃ of the one-pass step, when extrapolated
};

}  // namespace immerse
