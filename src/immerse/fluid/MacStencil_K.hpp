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
#include <array>

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

/// (G^MAC p)_d at face q (an unknown face: never a wall face).
inline double gradient_face(const Array3& p, const MacGeom& g, int d, const Index& q) {
  Index r = q;
  r[d] = g.periodic[d] ? wrap(q[d] - 1, g.n[d]) : q[d] - 1;
  return (at(p, q) - at(p, r)) * g.inv_h;
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
