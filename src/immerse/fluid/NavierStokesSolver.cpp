#include "immerse/fluid/NavierStokesSolver.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstddef>
#include <stdexcept>

#include "immerse/core/Error.hpp"
#include "immerse/fluid/MacStencil_K.hpp"
#include "immerse/fluid/ViscousStress_K.hpp"

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

/// Whether the step after `in` is the first one (forward Euler in (10)).
bool first_step(const FluidState& in) { return in.step == 0 || in.dt_prev <= 0; }

/// The constants of (9)–(10) for component d of the step of size dt after `in`.
RhsCoefficients rhs_coefficients(const FluidParams& prm, const FluidState& in, double dt, int d) {
  const double r = first_step(in) ? 0.0 : dt / in.dt_prev;  // (10): AB2 for a variable step
  return {dt / prm.rho, prm.rho, 0.5 * prm.mu, 1.0 + 0.5 * r, -0.5 * r, prm.body_force[d]};
}

/// The explicit terms of (9) at one face, E = −ρ A^{n+1/2} − G p^{n−1/2} + (μ/2) lap, with the implicit half of the
/// viscous term on the left (lap: ∇_h² u^n including the wall values, which so move to the right) and A^{n+1/2} by
/// (10) (adv_old unused on the first step).
inline double explicit_face(const RhsCoefficients& c, bool first, double a_now, double adv_old, double lap,
                            double grad_p) {
  const double a = first ? a_now : c.w_now * a_now + c.w_old * adv_old;
  return -c.rho * a - grad_p + c.half_mu * lap;
}

/// Right-hand side of (9) at one face from u^n, its explicit terms e and the force f: u^n + (Δt/ρ)((e + f) + f_body),
/// the sums of u^n + (Δt/ρ)(−ρ A − G p + (μ/2) lap + f + f_body) in their order.
inline double rhs_face(const RhsCoefficients& c, double un, double e, double f) {
  return un + c.dt_rho * (e + f + c.fb);
}

/// What the kernels below write at a face besides (u·∇_h u)^n: the explicit terms e (prepare), or, WithForce, the
/// right-hand side of (9) under the force f[n] (the fused step).
template <bool WithForce>
inline double result_face(const RhsCoefficients& c, double un, double e, const double* f, std::size_t n) {
  if constexpr (WithForce)
    return rhs_face(c, un, e, f[n]);
  else
    return e;
}

/// (u·∇_h u)^n (into adv) and the explicit terms of (9), or WithForce the right-hand side under `force` (into res),
/// along row (j, k) of component D, i in [i0, i1) (no wall layer), reading through accessor R.
template <int D, bool First, bool WithForce, class R>
__attribute__((flatten)) void explicit_row(const MacStencilGrid& g, const FluidState& in, const Array3& p,
                                          const Array3* force, const RhsCoefficients& c, Array3& adv, Array3& res,
                                          int j, int k, int i0, int i1) {
  // Everything the loop reads in locals: the compiler then sees loop-invariant rows and vectorizes. Flattened: with
  // the many instances of this kernel GCC would leave the stencil functions out of line, and the loop scalar.
  const R ru(in.u[D], g, j, k), r0(in.u[0], g, j, k), r1(in.u[1], g, j, k), r2(in.u[2], g, j, k), rp(p, g, j, k);
  const std::size_t o = adv.index(0, j, k);
  const double* const fr = WithForce ? force->data() + o : nullptr;
  const double* const old = First ? nullptr : in.adv[D].data() + o;  // (not read on the first step)
  double* const ar = adv.data() + o;
  double* const rr = res.data() + o;
  const RhsCoefficients cc = c;
  const double inv_h = g.inv_h, inv_h2 = g.inv_h2;
  mac::along_row(i0, i1, g.n[0], g.periodic[0], [&](mac::XIndex x) __attribute__((always_inline)) {
    const int i = x.c;
    const mac::FaceStencil st = mac::gather_row(ru, x);
    const double a_now = mac::advection_row<D>(st, r0, r1, r2, x, inv_h);
    ar[i] = a_now;
    const double e = explicit_face(cc, First, a_now, First ? 0.0 : old[i], mac::laplacian(st, inv_h2),
                                   mac::gradient_row<D>(rp, x, inv_h));
    rr[i] = result_face<WithForce>(cc, st.centre, e, fr, i);
  });
}

/// Writes (u·∇_h u)^n into adv and the explicit terms of (9), or WithForce the right-hand side under `force`, into
/// res at every unknown of component D (p: the pressure of (9)): the row kernels wherever they apply, the generic
/// kernels in the wall layers.
template <int D, bool First, bool WithForce>
void build_t(const MacStencilGrid& g, const FluidState& in, const Array3& p, const Array3* force, const RhsCoefficients& c,
             Array3& adv, Array3& res) {
  const Array3& un = in.u[D];
  const double* const f = WithForce ? force->data() : nullptr;
  for_each_split(
      g, face_box(g, D), interior_face_box(g, D),
      [&](int i, int j, int k) {
        const mac::Index q{i, j, k};
        const mac::FaceStencil st = mac::gather(un, g, D, q);
        const double a_now = mac::advection_face(in.u, g, D, q, st);
        adv(i, j, k) = a_now;
        const double lap = mac::laplacian(st, g) + mac::wall_source_face(g, D, q);
        const double e = explicit_face(c, First, a_now, First ? 0.0 : in.adv[D](i, j, k), lap,
                                       mac::gradient_face(p, g, D, q));
        res(i, j, k) = result_face<WithForce>(c, un(i, j, k), e, f, un.index(i, j, k));
      },
      [&](int j, int k, int i0, int i1) {
        if (mac::row_wraps(g, j, k))
          explicit_row<D, First, WithForce, mac::WrappedRows>(g, in, p, force, c, adv, res, j, k, i0, i1);
        else
          explicit_row<D, First, WithForce, mac::Strided>(g, in, p, force, c, adv, res, j, k, i0, i1);
      });
}

/// build_t for component d (force: its component d, WithForce).
template <bool WithForce>
void build(const MacStencilGrid& g, int d, const FluidState& in, const Array3& p, const Array3* force,
           const RhsCoefficients& c, Array3& adv, Array3& res) {
  const bool first = first_step(in);
  const auto run = [&]<int D>() {
    if (first)
      build_t<D, true, WithForce>(g, in, p, force, c, adv, res);
    else
      build_t<D, false, WithForce>(g, in, p, force, c, adv, res);
  };
  if (d == 0)
    run.template operator()<0>();
  else if (d == 1)
    run.template operator()<1>();
  else
    run.template operator()<2>();
}

/// The right-hand side of (9) (into rhs) along row (j, k) of the unknowns of one component, i in [i0, i1), from
/// u^n, the explicit terms ex and the force f; and, CopyAdv, the next state's (u·∇_h u)^n (adv, into adv_out).
template <bool CopyAdv>
void rhs_row(const Array3& un, const Array3& ex, const Array3& f, const Array3& adv, const RhsCoefficients& c,
             Array3& rhs, Array3& adv_out, int j, int k, int i0, int i1) {
  const std::size_t o = rhs.index(0, j, k);
  const double* const ur = un.data() + o;
  const double* const er = ex.data() + o;
  const double* const fr = f.data() + o;
  const double* const ar = adv.data() + o;
  double* const rr = rhs.data() + o;
  double* const ao = adv_out.data() + o;
  const RhsCoefficients cc = c;
#pragma omp simd
  for (int i = i0; i < i1; ++i) {
    rr[i] = rhs_face(cc, ur[i], er[i], fr[i]);
    if constexpr (CopyAdv) ao[i] = ar[i];
  }
}

/// D u* (into div) and the right-hand side (ρ/Δt) D u* of (11) (into phi) along row (j, k) of the cells.
template <class R>
void divergence_row(const MacStencilGrid& g, const FaceField& us, double rho_dt, Array3& div, Array3& phi, int j, int k,
                    int i0, int i1) {
  const R r0(us[0], g, j, k), r1(us[1], g, j, k), r2(us[2], g, j, k);
  double* const dr = div.data() + div.index(0, j, k);
  double* const pr = phi.data() + phi.index(0, j, k);
  const double inv_h = g.inv_h;
  mac::along_row(i0, i1, g.n[0], g.periodic[0], [&](mac::XIndex x) __attribute__((always_inline)) {
    const double dv = mac::divergence_row(r0, r1, r2, x, inv_h);
    dr[x.c] = dv;
    pr[x.c] = rho_dt * dv;
  });
}

/// (12) along row (j, k) of the unknowns of component D: u^{n+1} = u* − (Δt/ρ) G φ.
template <int D, class R>
void project_row(const MacStencilGrid& g, const Array3& us, const Array3& phi, Array3& un1, int j, int k, int i0, int i1,
                 double dt_rho) {
  const R rphi(phi, g, j, k);
  const std::size_t o = us.index(0, j, k);
  const double* const sr = us.data() + o;
  double* const nr = un1.data() + o;
  const double inv_h = g.inv_h;
  mac::along_row(i0, i1, g.n[0], g.periodic[0], [&](mac::XIndex x) __attribute__((always_inline)) {
    nr[x.c] = sr[x.c] - dt_rho * mac::gradient_row<D>(rphi, x, inv_h);
  });
}

/// (12) and (13) along row (j, k) of the cells in one pass (φ read once for the three components): the unknowns of
/// each component in that row (face_box: a component normal to a wall has none in the wall's first row), then
/// p^{n+1/2} = p0 + φ − (μ/2) D u* at the cells (p0: the pressure (9) took), keeping p^{n−1/2} (pn) as out.p_prev.
template <class R>
void project_and_update_row(const MacStencilGrid& g, const FaceField& us, const Array3& phi, const Array3& div,
                            const Array3& p0, const Array3& pn, FluidState& out, int j, int k, double dt_rho,
                            double half_mu) {
  const int i1 = g.n[0];
  project_row<0, R>(g, us[0], phi, out.u[0], j, k, g.first(0, 0), i1, dt_rho);
  if (j >= g.first(1, 1)) project_row<1, R>(g, us[1], phi, out.u[1], j, k, g.first(1, 0), i1, dt_rho);
  if (k >= g.first(2, 2)) project_row<2, R>(g, us[2], phi, out.u[2], j, k, g.first(2, 0), i1, dt_rho);
  const std::size_t o = phi.index(0, j, k);
  const double* const pr0 = p0.data() + o;
  const double* const ph = phi.data() + o;
  const double* const dv = div.data() + o;
  const double* const prn = pn.data() + o;
  double* const pr1 = out.p.data() + o;
  double* const prp = out.p_prev.data() + o;
#pragma omp simd
  for (int i = 0; i < i1; ++i) {
    pr1[i] = pr0[i] + ph[i] - half_mu * dv[i];
    prp[i] = prn[i];
  }
}

}  // namespace

double extrapolation_weight(double dt, double dt_prev, double dt_prev2) {
  return dt_prev2 > 0 ? (dt + dt_prev) / (dt_prev + dt_prev2) : 0.0;
}

NavierStokesSolver::NavierStokesSolver(const Grid& grid, const FluidParams& params, FftPlanning planning)
    : grid_(grid),
      params_(params),
      geom_(grid, params),
      geom0_(grid),
      mu_implicit_(params.variable_viscosity ? params.implicit_ratio * params.mu : params.mu),
      ustar_(grid),
      div_(grid.n(0), grid.n(1), grid.n(2)),
      phi_(grid.n(0), grid.n(1), grid.n(2)) {
  params_.validate(grid_);
  for (int l = 0; l < 4; ++l)
    solvers_[l] = std::make_unique<FftHelmholtzSolver>(grid_, static_cast<Layout>(l), planning, l < 3 ? &ustar_[l] : &phi_);
}

FluidState NavierStokesSolver::initial_state() const {
  FluidState s;
  s.u = FaceField(grid_);
  s.adv = FaceField(grid_);
  s.p = Array3(grid_.n(0), grid_.n(1), grid_.n(2));
  s.p_prev = Array3(grid_.n(0), grid_.n(1), grid_.n(2));
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

void NavierStokesSolver::check(const FluidState& in, double dt) const {
  if (!(std::isfinite(dt) && dt > 0)) require(false, "fluid.dt", dt, "> 0");  // (no strings built when valid)
  if (!matches_grid(in.u) || in.p.shape() != grid_.cell_shape() || (in.step > 0 && !matches_grid(in.adv)))
    throw std::invalid_argument("NavierStokesSolver: state does not match the grid");
}

void NavierStokesSolver::check_force(const FaceField& force) const {
  if (!matches_grid(force)) throw std::invalid_argument("NavierStokesSolver::step: force does not match the grid");
}

const Array3& NavierStokesSolver::momentum_pressure(const FluidState& in, double dt, Array3& scratch) const {
  if (params_.pressure == PressurePredictor::Lagged) return in.p;
  const double w = extrapolation_weight(dt, in.dt_prev, in.dt_prev2);
  if (w == 0.0) return in.p;
  if (in.p_prev.shape() != grid_.cell_shape())
    throw std::invalid_argument("NavierStokesSolver: state has no previous pressure to extrapolate from");
  ensure_shape(scratch, grid_);
  const long n = static_cast<long>(in.p.size());
  const double* const p = in.p.data();
  const double* const q = in.p_prev.data();
  double* const s = scratch.data();
#pragma omp parallel for schedule(static) if (n >= MacStencilGrid::kMinCellsForThreads)
  for (long i = 0; i < n; ++i) s[i] = p[i] + w * (p[i] - q[i]);
  return scratch;
}

template <class Rhs>
void NavierStokesSolver::advance(const FluidState& in, double dt, const Array3& p, FluidState& out, Rhs&& rhs) {
  ensure_shape(out.u, grid_);
  ensure_shape(out.adv, grid_);
  ensure_shape(out.p, grid_);
  ensure_shape(out.p_prev, grid_);

  const MacStencilGrid& g = geom_;
  const double rho = params_.rho, mu = mu_implicit_;
  const double c = mu * dt / (2.0 * rho);  // (I − c ∇_h²) u* = rhs
  const double dt_rho = dt / rho;

  for (int d = 0; d < 3; ++d) {
    rhs(d);
    solvers_[d]->solve(ustar_[d], 1.0, -c);
  }
  apply_wall_values(ustar_);

  // (11): ∇_h² φ = (ρ/Δt) D u*, Neumann walls.
  const double rho_dt = rho / dt;
  for_each_row(g, IndexBox{{0, 0, 0}, g.n}, [&](int j, int k, int i0, int i1) {
    if (mac::row_wraps(g, j, k))
      divergence_row<mac::WrappedRows>(g, ustar_, rho_dt, div_, phi_, j, k, i0, i1);
    else
      divergence_row<mac::Strided>(g, ustar_, rho_dt, div_, phi_, j, k, i0, i1);
  });
  solvers_[3]->solve(phi_, 0.0, 1.0);

  // (12) and (13).
  const double half_mu = 0.5 * mu;
  for_each_row(g, IndexBox{{0, 0, 0}, g.n}, [&](int j, int k, int, int) {
    if (mac::row_wraps(g, j, k))
      project_and_update_row<mac::WrappedRows>(g, ustar_, phi_, div_, p, in.p, out, j, k, dt_rho, half_mu);
    else
      project_and_update_row<mac::Strided>(g, ustar_, phi_, div_, p, in.p, out, j, k, dt_rho, half_mu);
  });
  apply_wall_values(out.u);
  if (params_.variable_viscosity) {
    ensure_shape(out.u_prev, grid_);
    for (int d = 0; d < 3; ++d) out.u_prev[d].values() = in.u[d].values();
  }

  out.dt_prev2 = in.dt_prev;
  out.dt_prev = dt;
  out.step = in.step + 1;
  out.time = in.time + dt;
}

void NavierStokesSolver::step(const FluidState& in, const FaceField& force, double dt, FluidState& out,
                              const Array3* chi) {
  if (params_.variable_viscosity) {
    prepare(in, dt, own_);
    step(own_, force, out, chi);
    return;
  }
  check(in, dt);
  check_force(force);
  if (&in == &out) throw std::invalid_argument("NavierStokesSolver::step: `in` and `out` must be different states");
  out.adv_of = 0;
  const Array3& p = momentum_pressure(in, dt, ptilde_);
  // (9) in one pass: (u·∇_h u)^n into the new state, the right-hand side into u*.
  advance(in, dt, p, out, [&](int d) {
    build<true>(geom_, d, in, p, &force[d], rhs_coefficients(params_, in, dt, d), out.adv[d], ustar_[d]);
  });
}

void NavierStokesSolver::prepare(const FluidState& in, double dt, PreparedStep& prepared) const {
  check(in, dt);
  prepared.state_ = nullptr;  // (not prepared until the end)
  ensure_shape(prepared.adv_, grid_);
  ensure_shape(prepared.explicit_, grid_);
  const Array3& p = momentum_pressure(in, dt, prepared.pressure_);
  prepared.extrapolated_ = &p != &in.p;
  for (int d = 0; d < 3; ++d)
    build<false>(geom_, d, in, p, nullptr, rhs_coefficients(params_, in, dt, d), prepared.adv_[d],
                 prepared.explicit_[d]);
  if (params_.variable_viscosity) prepare_variable(in, dt, prepared);
  static std::atomic<std::uint64_t> prepares{0};  // (ids only: results never depend on it)
  prepared.state_ = &in;
  prepared.id_ = ++prepares;
  prepared.step_ = in.step;
  prepared.time_ = in.time;
  prepared.dt_ = dt;
}

void NavierStokesSolver::step(const PreparedStep& prepared, const FaceField& force, FluidState& out,
                              const Array3* chi) {
  const FluidState* const in = prepared.state_;
  if (!in) throw std::invalid_argument("NavierStokesSolver::step: the step was not prepared");
  if (!prepared.prepared_for(*in, prepared.dt_))
    throw std::logic_error("NavierStokesSolver::step: the state the step was prepared from has changed");
  if (in == &out)
    throw std::invalid_argument("NavierStokesSolver::step: `out` must not be the state the step was prepared from");
  check_force(force);
  const double dt = prepared.dt_;
  // (9) from the prepared explicit terms; their (u·∇_h u)^n into the new state unless it holds it already.
  const bool stress = params_.variable_viscosity && chi;
  if (stress && chi->shape() != grid_.cell_shape())
    throw std::invalid_argument("NavierStokesSolver::step: the viscosity field does not match the grid");
  const IndexBox box = stress ? variable_stress_box(*chi) : IndexBox{};
  const bool copy_adv = out.adv_of != prepared.id_ || !matches_grid(out.adv);
  out.adv_of = 0;
  const auto rhs = [&]<bool CopyAdv>(int d) {
    const RhsCoefficients c = rhs_coefficients(params_, *in, dt, d);
    for_each_row(geom_, face_box(geom_, d), [&](int j, int k, int i0, int i1) {
      rhs_row<CopyAdv>(in->u[d], prepared.explicit_[d], force[d], prepared.adv_[d], c, ustar_[d], out.adv[d], j, k, i0,
                       i1);
    });
  };
  advance(*in, dt, prepared.extrapolated_ ? prepared.pressure_ : in->p, out, [&](int d) {
    if (copy_adv)
      rhs.template operator()<true>(d);
    else
      rhs.template operator()<false>(d);
    if (stress) add_variable_stress(prepared.utilde_, *chi, dt, d, box);
  });
  out.adv_of = prepared.id_;
}

void NavierStokesSolver::prepare_variable(const FluidState& in, double dt, PreparedStep& prepared) const {
  ensure_shape(prepared.utilde_, grid_);
  const bool extrapolate = !first_step(in) && matches_grid(in.u_prev);
  const double half_r = extrapolate ? 0.5 * dt / in.dt_prev : 0.0;
  const double dmu = mu_implicit_ - params_.mu;
  for (int d = 0; d < 3; ++d) {
    const long n = static_cast<long>(in.u[d].size());
    const double* const u = in.u[d].data();
    const double* const up = extrapolate ? in.u_prev[d].data() : u;
    double* const ut = prepared.utilde_[d].data();
    if (dmu != 0) {
      // (μ_p − μ) ∇_h²(u^n/2 − ũ) with homogeneous walls, from u^n/2 − ũ held in utilde_ meanwhile.
#pragma omp parallel for schedule(static) if (geom_.threaded())
      for (long i = 0; i < n; ++i) ut[i] = 0.5 * u[i] - (u[i] + half_r * (u[i] - up[i]));
      Array3& e = prepared.explicit_[d];
      const Array3& w = prepared.utilde_[d];
      for_each_face(geom_, d, [&](int i, int j, int k) {
        e(i, j, k) += dmu * mac::laplacian_face(w, geom0_, d, mac::Index{i, j, k});
      });
    }
#pragma omp parallel for schedule(static) if (geom_.threaded())
    for (long i = 0; i < n; ++i) ut[i] = u[i] + half_r * (u[i] - up[i]);
  }
}

IndexBox NavierStokesSolver::variable_stress_box(const Array3& chi) const {
  const MacStencilGrid& g = geom_;
  std::array<int, 3> lo = g.n, hi{-1, -1, -1};
  for (int k = 0; k < g.n[2]; ++k)
    for (int j = 0; j < g.n[1]; ++j) {
      const double* const row = chi.data() + chi.index(0, j, k);
      for (int i = 0; i < g.n[0]; ++i)
        if (row[i] != 0.0) {
          const std::array<int, 3> q{i, j, k};
          for (int a = 0; a < 3; ++a) {
            lo[a] = std::min(lo[a], q[a]);
            hi[a] = std::max(hi[a], q[a]);
          }
        }
    }
  if (hi[0] < 0) return IndexBox{{0, 0, 0}, {0, 0, 0}};
  IndexBox box{};
  for (int a = 0; a < 3; ++a) {
    if (g.periodic[a] && (lo[a] < 1 || hi[a] > g.n[a] - 2)) {
      box.begin[a] = 0;
      box.end[a] = g.n[a];
    } else {
      box.begin[a] = std::max(lo[a] - 1, 0);
      box.end[a] = std::min(hi[a] + 2, g.n[a]);
    }
  }
  return box;
}

void NavierStokesSolver::add_variable_stress(const FaceField& utilde, const Array3& chi, double dt, int d,
                                             const IndexBox& box) {
  const MacStencilGrid& g = geom_;
  const double c = dt / params_.rho * params_.mu;
  Array3& rhs = ustar_[d];
  const int i0 = std::max(box.begin[0], g.first(d, 0)), j0 = std::max(box.begin[1], g.first(d, 1)),
            k0 = std::max(box.begin[2], g.first(d, 2));
#pragma omp parallel for collapse(2) schedule(static) if (g.threaded())
  for (int k = k0; k < box.end[2]; ++k)
    for (int j = j0; j < box.end[1]; ++j)
      for (int i = i0; i < box.end[0]; ++i)
        rhs(i, j, k) += c * mac::stress_divergence(utilde, chi, g, d, mac::Index{i, j, k});
}

}  // namespace immerse
