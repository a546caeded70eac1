#pragma once
// The pointwise parts of one step of the projection method (NavierStokesSolver.hpp, eqs. 9–13), shared by the serial
// NavierStokesSolver and the slab-decomposed SlabNavierStokesSolver: the explicit terms and right-hand side of (9)
// with (10), the divergence of (11) and the projection (12)–(13), row by row or face by face over index boxes. Both
// solvers call the same functions, so each face sees the same floating-point operations in the same order.
// Verified by: the tests NavierStokesSolver.* and ParallelFluidStep.*.
#include <cstddef>

#include "immerse/core/Array3.hpp"
#include "immerse/fluid/FluidParams.hpp"
#include "immerse/fluid/FluidState.hpp"
#include "immerse/fluid/MacStencilGrid.hpp"
#include "immerse/fluid/MacStencil_K.hpp"
#include "immerse/grid/FaceField.hpp"

namespace immerse::step_kernels {

/// The constants of (9)–(10) at the faces of one component.
struct RhsCoefficients {
  double dt_rho, rho, half_mu;  // Δt/ρ, ρ, μ/2
  double w_now, w_old;          // Adams–Bashforth weights (10)
  double fb;                    // body force
};

/// Whether the step after `in` is the first one (forward Euler in (10)).
inline bool first_step(const FluidState& in) { return in.step == 0 || in.dt_prev <= 0; }

/// The constants of (9)–(10) for component d of the step of size dt after `in`.
inline RhsCoefficients rhs_coefficients(const FluidParams& prm, const FluidState& in, double dt, int d) {
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

/// Where build_t writes for component D: every unknown of `all`, the row kernels on `fast` (inside `all`; its faces
/// take no wall source), and the geometry `walls` and z offset (global z = local z + z_offset) that the wall sources
/// of the other faces are taken with. The serial solver: face_box, interior_face_box, its own geometry, offset 0.
struct BuildRegion {
  IndexBox all, fast;
  const MacStencilGrid* walls;
  int z_offset;
};

inline BuildRegion serial_region(const MacStencilGrid& g, int d) {
  return {face_box(g, d), interior_face_box(g, d), &g, 0};
}

/// Writes (u·∇_h u)^n into adv and the explicit terms of (9), or WithForce the right-hand side under `force`, into
/// res at every unknown of component D in region.all (p: the pressure of (9)): the row kernels on region.fast, the
/// generic kernels elsewhere (the wall layers).
template <int D, bool First, bool WithForce>
void build_t(const MacStencilGrid& g, const BuildRegion& region, const FluidState& in, const Array3& p,
             const Array3* force, const RhsCoefficients& c, Array3& adv, Array3& res) {
  const Array3& un = in.u[D];
  const double* const f = WithForce ? force->data() : nullptr;
  const MacStencilGrid& walls = *region.walls;
  const int dz = region.z_offset;
  for_each_split(
      g, region.all, region.fast,
      [&](int i, int j, int k) {
        const mac::Index q{i, j, k};
        const mac::FaceStencil st = mac::gather(un, g, D, q);
        const double a_now = mac::advection_face(in.u, g, D, q, st);
        adv(i, j, k) = a_now;
        const double lap = mac::laplacian(st, g) + mac::wall_source_face(walls, D, mac::Index{i, j, k + dz});
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

/// build_t for component d (force: its component d, WithForce) over `region`.
template <bool WithForce>
void build(const MacStencilGrid& g, const BuildRegion& region, int d, const FluidState& in, const Array3& p,
           const Array3* force, const RhsCoefficients& c, Array3& adv, Array3& res) {
  const bool first = first_step(in);
  const auto run = [&]<int D>() {
    if (first)
      build_t<D, true, WithForce>(g, region, in, p, force, c, adv, res);
    else
      build_t<D, false, WithForce>(g, region, in, p, force, c, adv, res);
  };
  if (d == 0)
    run.template operator()<0>();
  else if (d == 1)
    run.template operator()<1>();
  else
    run.template operator()<2>();
}

/// build() over every unknown of component d of the serial grid g.
template <bool WithForce>
void build(const MacStencilGrid& g, int d, const FluidState& in, const Array3& p, const Array3* force,
           const RhsCoefficients& c, Array3& adv, Array3& res) {
  build<WithForce>(g, serial_region(g, d), d, in, p, force, c, adv, res);
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


}  // namespace immerse::step_kernels
