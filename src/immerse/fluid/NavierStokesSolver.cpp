#include "immerse/fluid/NavierStokesSolver.hpp"

#include <cmath>
#include <stdexcept>

#include "immerse/core/Error.hpp"
#include "immerse/fluid/MacStencil_K.hpp"

namespace immerse {

namespace {

void ensure_shape(FaceField& f, const Grid& g) {
  for (int d = 0; d < 3; ++d)
    if (f[d].shape() != g.face_shape(d)) {
      f = FaceField(g);
      return;
    }
}

void ensure_shape(Array3& a, const Grid& g) {
  if (a.shape() != g.cell_shape()) a = Array3(g.n(0), g.n(1), g.n(2));
}

}  // namespace

NavierStokesSolver::NavierStokesSolver(const Grid& grid, const FluidParams& params, FftPlanning planning)
    : grid_(grid),
      params_(params),
      geom_(grid, params),
      ustar_(grid),
      div_(grid.n(0), grid.n(1), grid.n(2)),
      phi_(grid.n(0), grid.n(1), grid.n(2)) {
  params_.validate(grid_);
  for (int l = 0; l < 4; ++l) solvers_[l] = std::make_unique<FastSolver>(grid_, static_cast<Layout>(l), planning);
}

FluidState NavierStokesSolver::initial_state() const {
  FluidState s;
  s.u = FaceField(grid_);
  s.adv = FaceField(grid_);
  s.p = Array3(grid_.n(0), grid_.n(1), grid_.n(2));
  apply_wall_values(s.u);
  return s;
}

void NavierStokesSolver::apply_wall_values(FaceField& u) const {
  for (int d = 0; d < 3; ++d) {
    if (grid_.periodic(d)) continue;
    Array3& ud = u[d];
    const int e1 = (d + 1) % 3, e2 = (d + 2) % 3;
    for (int side = 0; side < 2; ++side) {
      const double v = side == 0 ? params_.wall_lower[d][d] : params_.wall_upper[d][d];
      mac::Index q{};
      q[d] = side == 0 ? 0 : grid_.n(d);
      for (q[e2] = 0; q[e2] < ud.n(e2); ++q[e2])
        for (q[e1] = 0; q[e1] < ud.n(e1); ++q[e1]) ud(q[0], q[1], q[2]) = v;
    }
  }
}

bool NavierStokesSolver::matches_grid(const FaceField& f) const {
  for (int d = 0; d < 3; ++d)
    if (f[d].shape() != grid_.face_shape(d)) return false;
  return true;
}

void NavierStokesSolver::step(const FluidState& in, const FaceField& force, double dt, FluidState& out) {
  if (!(std::isfinite(dt) && dt > 0)) require(false, "fluid.dt", dt, "> 0");  // (no strings built when valid)
  if (&in == &out) throw std::invalid_argument("NavierStokesSolver::step: `in` and `out` must be different states");
  if (!matches_grid(in.u) || !matches_grid(force) || in.p.shape() != grid_.cell_shape() ||
      (in.step > 0 && !matches_grid(in.adv)))
    throw std::invalid_argument("NavierStokesSolver::step: state or force does not match the grid");
  ensure_shape(out.u, grid_);
  ensure_shape(out.adv, grid_);
  ensure_shape(out.p, grid_);

  const MacGeom& g = geom_;
  const double rho = params_.rho, mu = params_.mu;
  const double c = mu * dt / (2.0 * rho);  // (I − c ∇_h²) u* = rhs
  // (10): Adams–Bashforth weights for a variable step; forward Euler on the first step.
  const bool first = in.step == 0 || in.dt_prev <= 0;
  const double r = first ? 0.0 : dt / in.dt_prev;
  const double w_now = 1.0 + 0.5 * r, w_old = -0.5 * r;
  const double dt_rho = dt / rho;

  for (int d = 0; d < 3; ++d) {
    const Array3 &un = in.u[d], &adv_old = in.adv[d], &f = force[d];
    Array3 &adv = out.adv[d], &rhs = ustar_[d];
    const double fb = params_.body_force[d];
    for_each_face(g, d, [&](int i, int j, int k) {
      const mac::Index q{i, j, k};
      const mac::FaceStencil st = mac::gather(un, g, d, q);
      const double a_now = mac::advection_face(in.u, g, d, q, st);
      adv(i, j, k) = a_now;
      const double a = first ? a_now : w_now * a_now + w_old * adv_old(i, j, k);
      // (9) with the implicit half of the viscous term on the left; its wall values move to the right.
      const double visc = 0.5 * mu * (mac::laplacian(st, g) + mac::wall_source_face(g, d, q));
      rhs(i, j, k) = un(i, j, k) + dt_rho * (-rho * a - mac::gradient_face(in.p, g, d, q) + visc + f(i, j, k) + fb);
    });
    solvers_[d]->solve(rhs, 1.0, -c);
  }
  apply_wall_values(ustar_);

  // (11): ∇_h² φ = (ρ/Δt) D u*, Neumann walls.
  for_each_cell(g, [&](int i, int j, int k) {
    const double dv = mac::divergence_cell(ustar_, g, {i, j, k});
    div_(i, j, k) = dv;
    phi_(i, j, k) = rho / dt * dv;
  });
  solvers_[3]->solve(phi_, 0.0, 1.0);

  // (12) and (13).
  for (int d = 0; d < 3; ++d) {
    const Array3& us = ustar_[d];
    Array3& un1 = out.u[d];
    for_each_face(g, d, [&](int i, int j, int k) {
      un1(i, j, k) = us(i, j, k) - dt_rho * mac::gradient_face(phi_, g, d, {i, j, k});
    });
  }
  apply_wall_values(out.u);
  for_each_cell(
      g, [&](int i, int j, int k) { out.p(i, j, k) = in.p(i, j, k) + phi_(i, j, k) - 0.5 * mu * div_(i, j, k); });

  out.dt_prev = dt;
  out.step = in.step + 1;
  out.time = in.time + dt;
}

}  // namespace immerse
