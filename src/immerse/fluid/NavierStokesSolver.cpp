#include "immerse/fluid/NavierStokesSolver.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
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

/// The constants of (9)–(10) at the faces of one component.
struct RhsCoefficients {
  double dt_rho, rho, half_mu;  // Δt/ρ, ρ, μ/2
  double w_now, w_old;          // Adams–Bashforth weights (10)
  double fb;                    // body force
};

/// Right-hand side of (9) at one face, with the implicit half of the viscous term on the left (lap: ∇_h² u^n
/// including the wall values, which so move to the right) and A^{n+1/2} by (10) (adv_old unused on the first step).
inline double rhs_face(const RhsCoefficients& c, bool first, double un, double a_now, double adv_old, double lap,
                       double grad_p, double f) {
  const double a = first ? a_now : c.w_now * a_now + c.w_old * adv_old;
  return un + c.dt_rho * (-c.rho * a - grad_p + c.half_mu * lap + f + c.fb);
}

/// Writes (u·∇_h u)^n into adv and the right-hand side of (9) into rhs at every unknown of component D: interior
/// faces by the pointer kernels along unit-stride rows, the boundary layers by the generic kernels.
template <int D, bool First>
void build_rhs_t(const MacGeom& g, const FluidState& in, const FaceField& force, const RhsCoefficients& c,
                 Array3& adv, Array3& rhs) {
  const Array3 &un = in.u[D], &f = force[D], &p = in.p;
  for_each_split(
      g, face_box(g, D), interior_face_box(g, D),
      [&](int i, int j, int k) {
        const mac::Index q{i, j, k};
        const mac::FaceStencil st = mac::gather(un, g, D, q);
        const double a_now = mac::advection_face(in.u, g, D, q, st);
        adv(i, j, k) = a_now;
        const double lap = mac::laplacian(st, g) + mac::wall_source_face(g, D, q);
        rhs(i, j, k) = rhs_face(c, First, un(i, j, k), a_now, First ? 0.0 : in.adv[D](i, j, k), lap,
                                mac::gradient_face(p, g, D, q), f(i, j, k));
      },
      [&](int j, int k, int i0, int i1) {
        // Everything the loop reads in locals: the compiler then sees loop-invariant strides and vectorizes.
        const mac::ConstView vu(un), u0(in.u[0]), u1(in.u[1]), u2(in.u[2]), vp(p), vf(f);
        const mac::ConstView vold = First ? vu : mac::ConstView(in.adv[D]);  // (not read on the first step)
        const mac::MutView va(adv), vr(rhs);
        const RhsCoefficients cc = c;
        const MacGeom& gg = g;
        const double inv_h = gg.inv_h;
#pragma omp simd
        for (int i = i0; i < i1; ++i) {
          const mac::FaceStencil st = mac::gather_interior(vu, i, j, k);
          const double a_now = mac::advection_interior<D>(st, u0, u1, u2, i, j, k, inv_h);
          va(i, j, k) = a_now;
          vr(i, j, k) = rhs_face(cc, First, vu(i, j, k), a_now, First ? 0.0 : vold(i, j, k), mac::laplacian(st, gg),
                                 mac::gradient_interior<D>(vp, i, j, k, inv_h), vf(i, j, k));
        }
      });
}

/// (12) along one row of interior faces of component D: u^{n+1} = u* − (Δt/ρ) G φ.
template <int D>
void project_row(const mac::ConstView& us, const mac::ConstView& phi, const mac::MutView& un1, int j, int k, int i0,
                 int i1, double dt_rho, double inv_h) {
#pragma omp simd
  for (int i = i0; i < i1; ++i) un1(i, j, k) = us(i, j, k) - dt_rho * mac::gradient_interior<D>(phi, i, j, k, inv_h);
}

template <int D>
void build_rhs(const MacGeom& g, const FluidState& in, const FaceField& force, const RhsCoefficients& c, bool first,
               Array3& adv, Array3& rhs) {
  if (first)
    build_rhs_t<D, true>(g, in, force, c, adv, rhs);
  else
    build_rhs_t<D, false>(g, in, force, c, adv, rhs);
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
  const RhsCoefficients coef{dt / rho, rho, 0.5 * mu, 1.0 + 0.5 * r, -0.5 * r, 0.0};

  for (int d = 0; d < 3; ++d) {
    RhsCoefficients cd = coef;
    cd.fb = params_.body_force[d];
    switch (d) {
      case 0: build_rhs<0>(g, in, force, cd, first, out.adv[0], ustar_[0]); break;
      case 1: build_rhs<1>(g, in, force, cd, first, out.adv[1], ustar_[1]); break;
      default: build_rhs<2>(g, in, force, cd, first, out.adv[2], ustar_[2]); break;
    }
    solvers_[d]->solve(ustar_[d], 1.0, -c);
  }
  apply_wall_values(ustar_);

  // (11): ∇_h² φ = (ρ/Δt) D u*, Neumann walls.
  const double rho_dt = rho / dt;
  {
    IndexBox all{{0, 0, 0}, g.n}, fast = all;
    for (int a = 0; a < 3; ++a)
      if (g.periodic[a]) fast.end[a] = std::max(0, g.n[a] - 1);  // q + e_a wraps at the last cell
    for_each_split(
        g, all, fast,
        [&](int i, int j, int k) {
          const double dv = mac::divergence_cell(ustar_, g, {i, j, k});
          div_(i, j, k) = dv;
          phi_(i, j, k) = rho_dt * dv;
        },
        [&](int j, int k, int i0, int i1) {
          const mac::ConstView u0(ustar_[0]), u1(ustar_[1]), u2(ustar_[2]);
          const mac::MutView vd(div_), vphi(phi_);
          const double inv_h = g.inv_h, s = rho_dt;
#pragma omp simd
          for (int i = i0; i < i1; ++i) {
            const double dv = mac::divergence_interior(u0, u1, u2, i, j, k, inv_h);
            vd(i, j, k) = dv;
            vphi(i, j, k) = s * dv;
          }
        });
  }
  solvers_[3]->solve(phi_, 0.0, 1.0);

  // (12) and (13).
  const double dt_rho = coef.dt_rho;
  for (int d = 0; d < 3; ++d) {
    const Array3& us = ustar_[d];
    Array3& un1 = out.u[d];
    const IndexBox all = face_box(g, d);
    IndexBox fast = all;
    fast.begin[d] = std::min(std::max(fast.begin[d], 1), fast.end[d]);  // q − e_d wraps at face 0
    for_each_split(
        g, all, fast,
        [&](int i, int j, int k) { un1(i, j, k) = us(i, j, k) - dt_rho * mac::gradient_face(phi_, g, d, {i, j, k}); },
        [&](int j, int k, int i0, int i1) {
          const mac::ConstView vs(us), vphi(phi_);
          const mac::MutView vn(un1);
          const double inv_h = g.inv_h, s = dt_rho;
          switch (d) {
            case 0: project_row<0>(vs, vphi, vn, j, k, i0, i1, s, inv_h); break;
            case 1: project_row<1>(vs, vphi, vn, j, k, i0, i1, s, inv_h); break;
            default: project_row<2>(vs, vphi, vn, j, k, i0, i1, s, inv_h); break;
          }
        });
  }
  apply_wall_values(out.u);
  {
    const double half_mu = coef.half_mu;
    const double* p0 = in.p.data();
    const double* ph = phi_.data();
    const double* dv = div_.data();
    double* p1 = out.p.data();
    const long cells = static_cast<long>(out.p.size());
#pragma omp parallel for simd schedule(static) if (g.threaded())
    for (long n = 0; n < cells; ++n) p1[n] = p0[n] + ph[n] - half_mu * dv[n];
  }

  out.dt_prev = dt;
  out.step = in.step + 1;
  out.time = in.time + dt;
}

}  // namespace immerse
