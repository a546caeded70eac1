#pragma once
// Pointwise MAC-grid kernels (paper §2.2, Kim & Moin staggering): divergence D^MAC, gradient G^MAC, the 7-point
// Laplacian ∇_h² on each velocity layout and on cell-centred pressure, and the central-difference advection
// (u·∇_h u) at a face. They read the arrays they are given and write nothing.
//
// Boundary values (eq. 3). Along a wall axis, velocity component d is
//   - face-normal (axis d): the wall faces carry the normal wall velocity; it is taken from MacStencilGrid, never
//     from the array, so the arrays' wall faces are only read by the divergence;
//   - cell-centred (axis ≠ d): the value beyond the wall is the ghost u_g = 2 u_w − u_0, so that the mean of
//     ghost and first interior value equals the wall velocity u_w.
// The pressure Laplacian uses the ghost p_g = p_0 (homogeneous Neumann, eq. 11): it is exactly D^MAC G^MAC
// with G^MAC φ = 0 on the wall faces, so the projection (12) leaves D^MAC u^{n+1} = 0 to round-off.
//
// Two forms of each kernel: the generic one at an index (wraps indices, branches on the boundary type at every
// access; valid everywhere), and a *_row one that reads through an accessor of the neighbouring rows (Strided,
// or WrappedRows on periodic boundary rows; no branch), valid wherever every value it reads is a stored one,
// i.e. away from the wall layers (MacStencilGrid::interior_begin/end). Both forms do the same floating-point operations
// in the same order, so they give bitwise the same result where both apply.
// Verified by: the tests MacOperators.* (D = -G*, symmetric Laplacian, row kernels bitwise the generic ones on all 8
// periodic/wall combinations) and the study fluid_divergence (D u after the projection, ≤ 1e-12).
#include <array>
#include <cstddef>

#include "immerse/core/Array3.hpp"
#include "immerse/fluid/MacStencilGrid.hpp"
#include "immerse/grid/FaceField.hpp"

namespace immerse::mac {

using Index = std::array<int, 3>;

inline int wrap(int i, int n) { return i < 0 ? i + n : (i >= n ? i - n : i); }
inline double at(const Array3& a, const Index& q) { return a(q[0], q[1], q[2]); }

/// Velocity component e at face index r of its own array, with the normal wall velocity on wall faces.
inline double face_value(const Array3& ue, const MacStencilGrid& g, int e, const Index& r) {
  if (!g.periodic[e]) {
    if (r[e] == 0) return g.wall_lower[e][e];
    if (r[e] == g.n[e]) return g.wall_upper[e][e];
  }
  return at(ue, r);
}

/// Component d at the neighbour s = ±1 along axis e of its face q (periodic wrap, wall value or ghost).
inline double neighbor(const Array3& ud, const MacStencilGrid& g, int d, Index q, int e, int s) {
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

inline FaceStencil gather(const Array3& ud, const MacStencilGrid& g, int d, const Index& q) {
  FaceStencil st{at(ud, q), {}, {}};
  for (int e = 0; e < 3; ++e) {
    st.minus[e] = neighbor(ud, g, d, q, e, -1);
    st.plus[e] = neighbor(ud, g, d, q, e, +1);
  }
  return st;
}

/// Indices i − 1, i, i + 1 along x (wrapped on a periodic axis); X<DX>() picks one.
struct XIndex {
  int m, c, p;
  template <int DX>
  int at() const {
    if constexpr (DX < 0) return m;
    else if constexpr (DX > 0) return p;
    else return c;
  }
};

/// 1 if A == axis: the components of the unit vector e_A.
constexpr int unit(int A, int axis) { return A == axis ? 1 : 0; }

/// How the row kernels read an Array3 around row (j, k): at<DX, DY, DZ>(x) is the element (x + DX, j + DY, k + DZ).
/// Two accessors: Strided for rows whose neighbour rows do not wrap (offsets ±1 row, ±1 plane: the common case,
/// few registers), WrappedRows for the boundary rows of a periodic y or z axis (the nine neighbour rows located
/// once, wrapped). Along a row the kernels index by XIndex: loop-invariant rows, unit stride, so they vectorize.
struct Strided {
  const double* row;
  std::ptrdiff_t sy, sz;
  Strided(const Array3& a, const MacStencilGrid&, int j, int k)
      : row(a.data() + a.index(0, j, k)), sy(a.nx()), sz(static_cast<std::ptrdiff_t>(a.nx()) * a.ny()) {}
  template <int DX, int DY, int DZ>
  double at(XIndex x) const {
    return row[x.at<DX>() + DY * sy + DZ * sz];
  }
};

/// Whether row (j, k) has neighbour rows that wrap (it lies on the boundary of a periodic y or z axis): then the
/// kernels must read through WrappedRows.
inline bool row_wraps(const MacStencilGrid& g, int j, int k) {
  return (g.periodic[1] && (j == 0 || j == g.n[1] - 1)) || (g.periodic[2] && (k == 0 || k == g.n[2] - 1));
}

/// row[dy + 1][dz + 1] points at element (0, j + dy, k + dz), indices wrapped on periodic axes (null if beyond
/// the array on a wall axis: such a row is never read where the row kernels apply).
struct WrappedRows {
  const double* row[3][3];
  WrappedRows(const Array3& a, const MacStencilGrid& g, int j, int k) {
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy) {
        int jj = j + dy, kk = k + dz;
        if (g.periodic[1]) jj = wrap(jj, a.ny());
        if (g.periodic[2]) kk = wrap(kk, a.nz());
        row[dy + 1][dz + 1] = (jj >= 0 && jj < a.ny() && kk >= 0 && kk < a.nz()) ? a.data() + a.index(0, jj, kk)
                                                                                 : nullptr;
      }
  }
  template <int DX, int DY, int DZ>
  double at(XIndex x) const {
    return row[DY + 1][DZ + 1][x.at<DX>()];
  }
};

/// Element (x + DX, j + DY, k + DZ) through the accessor r of row (j, k).
template <int DX, int DY, int DZ, class R>
inline double rd(const R& r, XIndex x) {
  return r.template at<DX, DY, DZ>(x);
}

/// gather() at a face of u_d whose six neighbours are stored values (rows of u_d around the face's row).
template <class R>
inline FaceStencil gather_row(const R& u, XIndex x) {
  return {rd<0, 0, 0>(u, x),
          {rd<-1, 0, 0>(u, x), rd<0, -1, 0>(u, x), rd<0, 0, -1>(u, x)},
          {rd<1, 0, 0>(u, x), rd<0, 1, 0>(u, x), rd<0, 0, 1>(u, x)}};
}

/// ∇_h² u_d from its stencil.
inline double laplacian(const FaceStencil& st, double inv_h2) {
  double s = 0;
  for (int e = 0; e < 3; ++e) s += st.minus[e] - 2.0 * st.centre + st.plus[e];
  return s * inv_h2;
}
inline double laplacian(const FaceStencil& st, const MacStencilGrid& g) { return laplacian(st, g.inv_h2); }

/// ∇_h² u_d at face q of component d, with the boundary values of g.
inline double laplacian_face(const Array3& ud, const MacStencilGrid& g, int d, const Index& q) {
  return laplacian(gather(ud, g, d, q), g);
}

/// Part of ∇_h² u_d at face q that comes from the wall velocities alone (∇_h² with walls minus ∇_h² with
/// homogeneous walls): it moves to the right-hand side of the implicit Helmholtz problem (9).
inline double wall_source_face(const MacStencilGrid& g, int d, const Index& q) {
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
inline double advection_face(const FaceField& u, const MacStencilGrid& g, int d, const Index& q, const FaceStencil& st) {
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

/// Mean ū_E of the four E-faces around a face of component D ≠ E, in the order of advection_face().
template <int D, int E, class R>
inline double mean_face_row(const R& ue, XIndex x) {
  double sum = rd<0, 0, 0>(ue, x);
  sum += rd<unit(E, 0), unit(E, 1), unit(E, 2)>(ue, x);
  sum += rd<unit(E, 0) - unit(D, 0), unit(E, 1) - unit(D, 1), unit(E, 2) - unit(D, 2)>(ue, x);
  sum += rd<-unit(D, 0), -unit(D, 1), -unit(D, 2)>(ue, x);
  return 0.25 * sum;
}

/// advection_face() at a face of component D whose reads are all stored values; st is the stencil of u_D there.
template <int D, class R>
inline double advection_row(const FaceStencil& st, const R& u0, const R& u1, const R& u2, XIndex x,
                            double inv_h) {
  const double ub0 = D == 0 ? st.centre : mean_face_row<D, 0>(u0, x);
  const double ub1 = D == 1 ? st.centre : mean_face_row<D, 1>(u1, x);
  const double ub2 = D == 2 ? st.centre : mean_face_row<D, 2>(u2, x);
  double a = 0;
  a += ub0 * (st.plus[0] - st.minus[0]);
  a += ub1 * (st.plus[1] - st.minus[1]);
  a += ub2 * (st.plus[2] - st.minus[2]);
  return 0.5 * inv_h * a;
}

/// (G^MAC p)_d at face q (an unknown face: never a wall face).
inline double gradient_face(const Array3& p, const MacStencilGrid& g, int d, const Index& q) {
  Index r = q;
  r[d] = g.periodic[d] ? wrap(q[d] - 1, g.n[d]) : q[d] - 1;
  return (at(p, q) - at(p, r)) * g.inv_h;
}

/// gradient_face() at an unknown face of component D, from the rows of p.
template <int D, class R>
inline double gradient_row(const R& p, XIndex x, double inv_h) {
  return (rd<0, 0, 0>(p, x) - rd<-unit(D, 0), -unit(D, 1), -unit(D, 2)>(p, x)) * inv_h;
}

/// (D^MAC u) at cell q, from the face values stored in u (wall faces included).
inline double divergence_cell(const FaceField& u, const MacStencilGrid& g, const Index& q) {
  double s = 0;
  for (int d = 0; d < 3; ++d) {
    Index r = q;
    r[d] = g.periodic[d] ? wrap(q[d] + 1, g.n[d]) : q[d] + 1;
    s += at(u[d], r) - at(u[d], q);
  }
  return s * g.inv_h;
}

/// divergence_cell() from the rows of the three components around the cell's row.
template <class R>
inline double divergence_row(const R& u0, const R& u1, const R& u2, XIndex x, double inv_h) {
  double s = 0;
  s += rd<1, 0, 0>(u0, x) - rd<0, 0, 0>(u0, x);
  s += rd<0, 1, 0>(u1, x) - rd<0, 0, 0>(u1, x);
  s += rd<0, 0, 1>(u2, x) - rd<0, 0, 0>(u2, x);
  return s * inv_h;
}

/// D^MAC G^MAC φ at cell q: the 7-point Laplacian with ghost φ_g = φ_0 at walls (homogeneous Neumann).
inline double laplacian_cell_neumann(const Array3& phi, const MacStencilGrid& g, const Index& q) {
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

/// Calls kernel(XIndex{i − 1, i, i + 1}) for i in [i0, i1), the neighbours wrapped modulo n on a periodic x
/// axis: the two ends one by one, the rest in a loop the compiler vectorizes (OpenMP simd). Callers mark the
/// kernel lambda __attribute__((always_inline)): called from three places, GCC would not inline it otherwise, and
/// a loop around a call does not vectorize.
template <class Kernel>
void along_row(int i0, int i1, int n, bool periodic, Kernel&& kernel) {
  if (periodic && i0 < i1) {
    if (i0 == 0) {
      kernel(XIndex{n - 1, 0, n > 1 ? 1 : 0});
      i0 = 1;
    }
    if (i1 == n && i1 > i0) {
      kernel(XIndex{n - 2, n - 1, 0});
      i1 = n - 1;
    }
  }
#pragma omp simd
  for (int i = i0; i < i1; ++i) kernel(XIndex{i - 1, i, i + 1});
}

}  // namespace immerse::mac
