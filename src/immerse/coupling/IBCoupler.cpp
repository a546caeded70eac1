#include "immerse/coupling/IBCoupler.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "immerse/coupling/NodeDiagnostics.hpp"
#include "immerse/core/Parallel.hpp"

namespace immerse {

namespace {

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

/// t: node coordinate in index units of the points (faces or centres); count: stored points.
template <class K>
LineStencil<K::width> line_stencil(const IndexAxis& axis, double t, int count) {
  LineStencil<K::width> s;
  const int i0 = K::weights(t, s.w);
  s.first = i0;
  s.contiguous = i0 >= 0 && i0 + K::width <= count;
  if (s.contiguous) {
    s.lo = 0;
    s.hi = K::width;
  } else if (axis.periodic) {
    s.lo = 0;
    s.hi = K::width;
    for (int m = 0; m < K::width; ++m) {
      int i = i0 + m;  // in [-2, n + 3]: wrap without a division
      while (i < 0) i += axis.n;
      while (i >= axis.n) i -= axis.n;
      s.idx[m] = i;
    }
  } else {
    s.lo = std::max(0, -i0);
    s.hi = std::min(K::width, count - i0);
    for (int m = 0; m < K::width; ++m) s.idx[m] = i0 + m;
  }
  return s;
}

/// The six line stencils of one node: line[a][1] for the faces normal to axis a, line[a][0]
/// for the cell centres. Component d uses the face stencil along d and centres elsewhere.
template <class K>
struct NodeStencil {
  LineStencil<K::width> line[3][2];
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

}  // namespace

IBCoupler::IBCoupler(const Grid& grid, DeltaKernel kernel)
    : grid_(grid), kernel_(kernel), axes_{IndexAxis(grid, 0), IndexAxis(grid, 1), IndexAxis(grid, 2)} {
  // Blocks one kernel width (or more) wide: a node's writes span at most width + 1 points
  // from its first centre index, so two blocks of the same colour never touch the same point.
  const int width = kernel_width(kernel_);
  for (int b = 0; b < 2; ++b) {
    const int n = grid_.n(b + 1);
    const int count = (n / width) & ~1;
    blocks_[b] = count >= 2 ? count : 1;
    block_size_[b] = count >= 2 ? width : n + 1;
  }
  block_start_.assign(static_cast<std::size_t>(blocks_[0] * blocks_[1]) + 1, 0);
}

void IBCoupler::check_shape(const FaceField& field, const char* what) const {
  for (int d = 0; d < 3; ++d)
    if (field[d].shape() != grid_.face_shape(d))
      throw std::invalid_argument(std::string("IBCoupler: ") + what + " is not shaped like the grid's faces");
}

template <class K>
void IBCoupler::sort_into_blocks(std::span<const Vec3> X) {
  const int n = static_cast<int>(X.size());
  block_of_node_.resize(X.size());
  block_nodes_.resize(X.size());
  std::fill(block_start_.begin(), block_start_.end(), 0);
#pragma omp parallel for if (n >= kMinNodesForThreads)
  for (int l = 0; l < n; ++l) {
    int block[2];
    for (int b = 0; b < 2; ++b) {
      const int axis = b + 1, na = grid_.n(axis);
      const double t = axes_[axis].face_coordinate(X[l][axis]);
      int lo = std::min(K::first(t - 0.5), K::first(t));
      lo = grid_.periodic(axis) ? (lo % na + na) % na : std::clamp(lo, 0, na - 1);
      block[b] = std::min(lo / block_size_[b], blocks_[b] - 1);
    }
    block_of_node_[l] = block[0] + blocks_[0] * block[1];
  }
  // Counting sort, stable: each block keeps its nodes in index order.
  for (int l = 0; l < n; ++l) ++block_start_[block_of_node_[l] + 1];
  for (std::size_t b = 1; b < block_start_.size(); ++b) block_start_[b] += block_start_[b - 1];
  for (int l = 0; l < n; ++l) block_nodes_[block_start_[block_of_node_[l]]++] = l;
  for (std::size_t b = block_start_.size() - 1; b > 0; --b) block_start_[b] = block_start_[b - 1];
  block_start_[0] = 0;
}

template <class K>
void IBCoupler::spread(std::span<const Vec3> X, std::span<const Vec3> F, FaceField& f) {
  sort_into_blocks<K>(X);
  for (int d = 0; d < 3; ++d) {
    double* p = f[d].data();
    const long size = static_cast<long>(f[d].size());
#pragma omp parallel for if (size >= kMinCellsForThreads)
    for (long i = 0; i < size; ++i) p[i] = 0.0;
  }
  // Colours (y block parity, z block parity) one after another; blocks of one colour in
  // parallel, each adding its nodes in index order: the sums do not depend on the thread count.
  const double inv_h3 = 1.0 / grid_.cell_volume();
  for (int colour = 0; colour < 4; ++colour) {
    const int cy = colour % 2, cz = colour / 2;
    const int my = (blocks_[0] - cy + 1) / 2, mz = (blocks_[1] - cz + 1) / 2;
#pragma omp parallel for schedule(dynamic, 1) if (static_cast<long>(X.size()) >= kMinNodesForThreads)
    for (int m = 0; m < my * mz; ++m) {
      const int b = (cy + 2 * (m % my)) + blocks_[0] * (cz + 2 * (m / my));
      for (int p = block_start_[b]; p < block_start_[b + 1]; ++p) {
        const int l = block_nodes_[p];
        const NodeStencil<K> s(axes_, X[l]);
        for (int d = 0; d < 3; ++d)
          spread_component(s.along(0, d), s.along(1, d), s.along(2, d), F[l][d] * inv_h3, f[d]);
      }
    }
  }
}

template <class K>
void IBCoupler::interpolate(const FaceField& u, std::span<const Vec3> X, std::span<Vec3> U) const {
  const long n = static_cast<long>(X.size());
#pragma omp parallel for if (n >= kMinNodesForThreads)
  for (long l = 0; l < n; ++l) {
    const NodeStencil<K> s(axes_, X[l]);
    for (int d = 0; d < 3; ++d) U[l][d] = interpolate_component(s.along(0, d), s.along(1, d), s.along(2, d), u[d]);
  }
}

void IBCoupler::spread_force(std::span<const Vec3> X, std::span<const Vec3> F, FaceField& f) {
  if (F.size() != X.size()) throw std::invalid_argument("IBCoupler::spread_force: X and F differ in length");
  check_shape(f, "the force field");
  check_nodes_in_domain(grid_, X);
  std::visit([&](const auto& k) { spread<std::decay_t<decltype(k)>>(X, F, f); }, kernel_);
}

void IBCoupler::interpolate_velocity(const FaceField& u, std::span<const Vec3> X, std::span<Vec3> U) const {
  if (U.size() != X.size()) throw std::invalid_argument("IBCoupler::interpolate_velocity: X and U differ in length");
  check_shape(u, "the velocity field");
  check_nodes_in_domain(grid_, X);
  std::visit([&](const auto& k) { interpolate<std::decay_t<decltype(k)>>(u, X, U); }, kernel_);
}

}  // namespace immerse
