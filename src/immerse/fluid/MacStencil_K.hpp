#pragma once
// Pointwise MAC-grid kernels (paper §2.2, Kim & Moin staggering): divergence D^MAC, gradient G^MAC, the 7-point
// Laplacian ∇_h² on each velocity layout and on cell-centred pressure, and the central-difference advection
// (u·∇_h u) at a face. They read the arrays they are given and write nothing.
//
// Boundary values (eq. 3). Along a wall axis, velocity component d is
//   - face-normal (axis d): the wall faces carry the normal wall velocity; it is taken from MacGeom, never
//     from the array, so the arrays' wall faces are only read by the divergence;
//   - cell-centred (axis ≠ d): the value beyond the wall is the ghost u_g = 2 u_w − u_0, so that the mean of
//     ghost and first interior value equals the wall velocity u_w.
// The pressure Laplacian uses the ghost p_g = p_0 (homogeneous Neumann, eq. 11): it is exactly D^MAC G^MAC
// with G^MAC φ = 0 on the wall faces, so the projection (12) leaves D^MAC u^{n+1} = 0 to round-off.
//
// Two forms of each kernel: the generic one at an index (wraps indices, branches on the boundary type at every
// access; valid everywhere), and an *_interior one on Views (no wrap, no branch), valid only where every value
// it reads is a plain stored one (MacGeom::interior_begin/end). The interior forms do the
// same floating-point operations in the same order, so both give bitwise the same result where both apply.
#include <array>
#include <cstddef>

#include "immerse/core/Array3.hpp"
#include "immerse/fluid/MacGeom.hpp"
#include "immerse/grid/FaceField.hpp"

namespace immerse::mac {

using Index = std::array<int, 3>;

inline int wrap(int i, int n) { return i < 0 ? i + n : (i >= n ? i - n : i); }
inline double at(const Array3& a, const Index& q) { return a(q[0], q[1], q[2]); }

/// Velocity component e at face index r of its own array, with the normal wall velocity on wall faces.
inline double face_value(const Array3& ue, const MacGeom& g, int e, const Index& r) {
  if (!g.periodic[e]) {
    if (r[e] == 0) return g.wall_lower[e][e];
    if (r[e] == g.n[e]) return g.wall_upper[e][e];
  }
  return at(ue, r);
}

/// Component d at the neighbour s = ±1 along axis e of its face q (periodic wrap, wall value or ghost).
inline double neighbor(const Array3& ud, const MacGeom& g, int d, Index q, int e, int s) {
  const int m = q[e] + s;
  if (m > 0 && m < g.n[e]) {  // interior (the common case)
    q[e] = m;
    return at(ud, q);
  }
  if (g.periodic[e]) {
    q[e] = wrap(m, g.n[e]);
    return at(ud, q);
  }
  q[e] = m;
  if (e == d) return face_value(ud, g, d, q);
  if (m >= 0 && m < g.n[e]) return at(ud, q);
  q[e] -= s;
  const double uw = s < 0 ? g.wall_lower[e][d] : g.wall_upper[e][d];
  return 2.0 * uw - at(ud, q);
}

/// Face q of component d with its six neighbours: minus[e] at −e, plus[e] at +e.
struct FaceStencil {
  double centre;
  double minus[3], plus[3];
};

inline FaceStencil gather(const Array3& ud, const MacGeom& g, int d, const Index& q) {
  FaceStencil st{at(ud, q), {}, {}};
  for (int e = 0; e < 3; ++e) {
    st.minus[e] = neighbor(ud, g, d, q, e, -1);
    st.plus[e] = neighbor(ud, g, d, q, e, +1);
  }
  return st;
}

/// An Array3 as the interior kernels read or write it: x has unit stride, so along a row of constant (j, k) the
/// offsets of the neighbours are loop invariants and the kernels vectorize.
template <class T>
struct View {
  T* p;
  std::ptrdiff_t sy, sz;
  template <class A>
  explicit View(A& a) : p(a.data()), sy(a.nx()), sz(static_cast<std::ptrdiff_t>(a.nx()) * a.ny()) {}
  /// Offset of a unit step along axis A.
  template <int A>
  std::ptrdiff_t stride() const {
    if constexpr (A == 0) return 1;
    else if constexpr (A == 1) return sy;
    else return sz;
  }
  std::ptrdiff_t index(int i, int j, int k) const { return i + sy * j + sz * k; }
  T& operator()(int i, int j, int k) const { return p[index(i, j, k)]; }
};
using ConstView = View<const double>;
using MutView = View<double>;

/// gather() at an interior face (i, j, k) of u_d.
inline FaceStencil gather_interior(const ConstView& u, int i, int j, int k) {
  return {u(i, j, k), {u(i - 1, j, k), u(i, j - 1, k), u(i, j, k - 1)}, {u(i + 1, j, k), u(i, j + 1, k), u(i, j, k + 1)}};
}

/// ∇_h² u_d from its stencil.
inline double laplacian(const FaceStencil& st, const MacGeom& g) {
  double s = 0;
  for (int e = 0; e < 3; ++e) s += st.minus[e] - 2.0 * st.centre + st.plus[e];
  return s * g.inv_h2;
}

/// ∇_h² u_d at face q of component d, with the boundary values of g.
inline double laplacian_face(const Array3& ud, const MacGeom& g, int d, const Index& q) {
  return laplacian(gather(ud, g, d, q), g);
}

/// Part of ∇_h² u_d at face q that comes from the wall velocities alone (∇_h² with walls minus ∇_h² with
/// homogeneous walls): it moves to the right-hand side of the implicit Helmholtz problem (9).
inline double wall_source_face(const MacGeom& g, int d, const Index& q) {
  double s = 0;
  for (int e = 0; e < 3; ++e) {
    if (g.periodic[e]) continue;
    const double f = e == d ? 1.0 : 2.0;  // face value itself, or ghost 2u_w − u_0
    const int lo = e == d ? 1 : 0, hi = g.n[e] - 1;
    if (q[e] == lo) s += f * g.wall_lower[e][d];
    if (q[e] == hi) s += f * g.wall_upper[e][d];
  }
  return s * g.inv_h2;
}

/// Central-difference advection (u·∇_h u)_d at face q: Σ_e ū_e (u_d(q+e) − u_d(q−e)) / 2h, where ū_e is the
/// mean of the four e-faces around face q (ū_d = u_d); st is the stencil of u_d at q.
inline double advection_face(const FaceField& u, const MacGeom& g, int d, const Index& q, const FaceStencil& st) {
  double a = 0;
  for (int e = 0; e < 3; ++e) {
    double ue = st.centre;
    if (e != d) {
      Index r = q;
      const int dm = g.periodic[d] ? wrap(q[d] - 1, g.n[d]) : q[d] - 1;
      const int ep = g.periodic[e] ? wrap(q[e] + 1, g.n[e]) : q[e] + 1;
      double sum = face_value(u[e], g, e, r);
      r[e] = ep;
      sum += face_value(u[e], g, e, r);
      r[d] = dm;
      sum += face_value(u[e], g, e, r);
      r[e] = q[e];
      sum += face_value(u[e], g, e, r);
      ue = 0.25 * sum;
    }
    a += ue * (st.plus[e] - st.minus[e]);
  }
  return 0.5 * g.inv_h * a;
}

/// Mean ū_E of the four E-faces around face (i, j, k) of component D ≠ E, in the order of advection_face().
template <int D, int E>
inline double mean_face_interior(const ConstView& ue, int i, int j, int k) {
  const std::ptrdiff_t q = ue.index(i, j, k), pe = ue.stride<E>(), md = ue.stride<D>();
  double sum = ue.p[q];
  sum += ue.p[q + pe];
  sum += ue.p[q + pe - md];
  sum += ue.p[q - md];
  return 0.25 * sum;
}

/// advection_face() at an interior face (i, j, k) of component D; st is the stencil of u_D there.
template <int D>
inline double advection_interior(const FaceStencil& st, const ConstView& u0, const ConstView& u1, const ConstView& u2,
                                 int i, int j, int k, double inv_h) {
  const double ub0 = D == 0 ? st.centre : mean_face_interior<D, 0>(u0, i, j, k);
  const double ub1 = D == 1 ? st.centre : mean_face_interior<D, 1>(u1, i, j, k);
  const double ub2 = D == 2 ? st.centre : mean_face_interior<D, 2>(u2, i, j, k);
  double a = 0;
  a += ub0 * (st.plus[0] - st.minus[0]);
  a += ub1 * (st.plus[1] - st.minus[1]);
  a += ub2 * (st.plus[2] - st.minus[2]);
  return 0.5 * inv_h * a;
}

/// (G^MAC p)_d at face q (an unknown face: never a wall face).
inline double gradient_face(const Array3& p, const MacGeom& g, int d, const Index& q) {
  Index r = q;
  r[d] = g.periodic[d] ? wrap(q[d] - 1, g.n[d]) : q[d] - 1;
  return (at(p, q) - at(p, r)) * g.inv_h;
}

/// gradient_face() at face (i, j, k) of component D where the cell behind it does not wrap.
template <int D>
inline double gradient_interior(const ConstView& p, int i, int j, int k, double inv_h) {
  const std::ptrdiff_t q = p.index(i, j, k);
  return (p.p[q] - p.p[q - p.stride<D>()]) * inv_h;
}

/// (D^MAC u) at cell q, from the face values stored in u (wall faces included).
inline double divergence_cell(const FaceField& u, const MacGeom& g, const Index& q) {
  double s = 0;
  for (int d = 0; d < 3; ++d) {
    Index r = q;
    r[d] = g.periodic[d] ? wrap(q[d] + 1, g.n[d]) : q[d] + 1;
    s += at(u[d], r) - at(u[d], q);
  }
  return s * g.inv_h;
}

/// divergence_cell() at cell (i, j, k) where no face beyond it wraps.
inline double divergence_interior(const ConstView& u0, const ConstView& u1, const ConstView& u2, int i, int j, int k,
                                  double inv_h) {
  double s = 0;
  s += u0(i + 1, j, k) - u0(i, j, k);
  s += u1(i, j + 1, k) - u1(i, j, k);
  s += u2(i, j, k + 1) - u2(i, j, k);
  return s * inv_h;
}

/// D^MAC G^MAC φ at cell q: the 7-point Laplacian with ghost φ_g = φ_0 at walls (homogeneous Neumann).
inline double laplacian_cell_neumann(const Array3& phi, const MacGeom& g, const Index& q) {
  const double c = at(phi, q);
  double s = 0;
  for (int e = 0; e < 3; ++e)
    for (int sgn = -1; sgn <= 1; sgn += 2) {
      Index r = q;
      const int m = q[e] + sgn;
      if (g.periodic[e])
        r[e] = wrap(m, g.n[e]);
      else if (m >= 0 && m < g.n[e])
        r[e] = m;
      s += at(phi, r) - c;
    }
  return s * g.inv_h2;
}

}  // namespace immerse::mac
