#pragma once
// The stencils of the immersed boundary coupling (IBCoupler.hpp, eqs. 6 and 14): the kernel weights of one node along
// one grid line (periodic wrap; on a wall axis the points beyond the stored array dropped), the six line stencils of
// a node on the MAC layouts, and the loops that spread one nodal force component to, and interpolate one velocity
// component from, the W³ points of a node. Shared by the whole-grid IBCoupler and the slab SlabIBCoupler, so both
// evaluate the same weights and add in the same order (z, then y, then x).
// Verified by: the tests IBCoupler.* and ParallelCoupling.* (tests/test_parallel_coupling.cpp).
#include <algorithm>
#include <array>
#include <cstddef>

#include "immerse/core/Array3.hpp"
#include "immerse/core/Vec3.hpp"
#include "immerse/coupling/IndexAxis.hpp"

namespace immerse::ib_stencil {

/// The kernel weights of one node along one grid line: points idx[m] with weights w[m] for
/// m in [lo, hi). Periodic axes wrap idx; on wall axes points outside the stored array are dropped.
/// contiguous: all W points are stored and consecutive (idx[m] = first + m), the common case, which
/// the kernels below address with plain offsets (idx is then not filled).
template <int W>
struct LineStencil {
  int lo, hi;
  int first;
  bool contiguous;
  int idx[W];
  double w[W];
};

/// t: node coordinate in index units of the points (faces or centres); count: stored points; periodic, period: whether
/// and with how many points the axis wraps. shift: point i of the axis is stored at index i + shift (0 on the whole
/// grid; a slab's padded buffer along z numbers its planes from its first one, and is not wrapped).
template <class K>
LineStencil<K::width> line_stencil(double t, int count, bool periodic, int period, int shift = 0) {
  LineStencil<K::width> s;
  const int i0 = K::weights(t, s.w) + shift;
  s.first = i0;
  s.contiguous = i0 >= 0 && i0 + K::width <= count;
  if (s.contiguous) {
    s.lo = 0;
    s.hi = K::width;
  } else if (periodic) {
    s.lo = 0;
    s.hi = K::width;
    for (int m = 0; m < K::width; ++m) {
      int i = i0 + m;  // in [-2, n + 3]: wrap without a division
      while (i < 0) i += period;
      while (i >= period) i -= period;
      s.idx[m] = i;
    }
  } else {
    s.lo = std::max(0, -i0);
    s.hi = std::min(K::width, count - i0);
    for (int m = 0; m < K::width; ++m) s.idx[m] = i0 + m;
  }
  return s;
}

/// The stencil along a whole grid axis.
template <class K>
LineStencil<K::width> line_stencil(const IndexAxis& axis, double t, int count) {
  return line_stencil<K>(t, count, axis.periodic, axis.n);
}

/// The six line stencils of one node: line[a][1] for the faces normal to axis a, line[a][0]
/// for the cell centres. Component d uses the face stencil along d and centres elsewhere.
template <class K>
struct NodeStencil {
  LineStencil<K::width> line[3][2];
  NodeStencil() = default;  // lines set by the caller
  NodeStencil(const std::array<IndexAxis, 3>& axes, const Vec3& x) {
    for (int a = 0; a < 3; ++a) {
      const double t = axes[a].face_coordinate(x[a]);
      line[a][1] = line_stencil<K>(axes[a], t, axes[a].faces());
      line[a][0] = line_stencil<K>(axes[a], t - 0.5, axes[a].n);
    }
  }
  const LineStencil<K::width>& along(int axis, int d) const { return line[axis][axis == d ? 1 : 0]; }
};

/// Eq. (6) for one node and one component: f += Fd φ_x φ_y φ_z at its W³ points (Fd already divided by h³).
/// Both paths add in the same order (z, then y, then x), so they give bitwise the same sums.
template <int W>
void spread_component(const LineStencil<W>& sx, const LineStencil<W>& sy, const LineStencil<W>& sz, double Fd,
                      Array3& f) {
  const std::size_t nx = f.nx(), ny = f.ny();
  double* p = f.data();
  if (sx.contiguous && sy.contiguous && sz.contiguous) {  // plain offsets, fully unrolled
    double* const base = p + sx.first + nx * (sy.first + ny * static_cast<std::size_t>(sz.first));
    for (int kz = 0; kz < W; ++kz) {
      const double fz = Fd * sz.w[kz];
      for (int ky = 0; ky < W; ++ky) {
        const double fyz = fz * sy.w[ky];
        double* const row = base + nx * (ky + ny * kz);
        for (int kx = 0; kx < W; ++kx) row[kx] += fyz * sx.w[kx];
      }
    }
    return;
  }
  const auto index = [](const LineStencil<W>& s, int m) { return s.contiguous ? s.first + m : s.idx[m]; };
  for (int kz = sz.lo; kz < sz.hi; ++kz) {
    const double fz = Fd * sz.w[kz];
    for (int ky = sy.lo; ky < sy.hi; ++ky) {
      const double fyz = fz * sy.w[ky];
      double* row = p + nx * (index(sy, ky) + ny * index(sz, kz));
      for (int kx = sx.lo; kx < sx.hi; ++kx) row[index(sx, kx)] += fyz * sx.w[kx];
    }
  }
}

/// Eq. (14) for one node and one component: Σ u φ_x φ_y φ_z over its W³ points, summed along x, then y, then z
/// (the same order in both paths).
template <int W>
double interpolate_component(const LineStencil<W>& sx, const LineStencil<W>& sy, const LineStencil<W>& sz,
                             const Array3& u) {
  const std::size_t nx = u.nx(), ny = u.ny();
  const double* p = u.data();
  double sum = 0.0;
  if (sx.contiguous && sy.contiguous && sz.contiguous) {  // plain offsets, fully unrolled
    const double* const base = p + sx.first + nx * (sy.first + ny * static_cast<std::size_t>(sz.first));
    for (int kz = 0; kz < W; ++kz) {
      double sum_y = 0.0;
      for (int ky = 0; ky < W; ++ky) {
        const double* const row = base + nx * (ky + ny * kz);
        double sum_x = 0.0;
        for (int kx = 0; kx < W; ++kx) sum_x += sx.w[kx] * row[kx];
        sum_y += sy.w[ky] * sum_x;
      }
      sum += sz.w[kz] * sum_y;
    }
    return sum;
  }
  const auto index = [](const LineStencil<W>& s, int m) { return s.contiguous ? s.first + m : s.idx[m]; };
  for (int kz = sz.lo; kz < sz.hi; ++kz) {
    double sum_y = 0.0;
    for (int ky = sy.lo; ky < sy.hi; ++ky) {
      const double* row = p + nx * (index(sy, ky) + ny * index(sz, kz));
      double sum_x = 0.0;
      for (int kx = sx.lo; kx < sx.hi; ++kx) sum_x += sx.w[kx] * row[index(sx, kx)];
      sum_y += sy.w[ky] * sum_x;
    }
    sum += sz.w[kz] * sum_y;
  }
  return sum;
}

}  // namespace immerse::ib_stencil
