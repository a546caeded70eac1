#include "immerse/coupling/IBCoupler.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "immerse/core/ThreadThresholds.hpp"
#include "immerse/coupling/IBStencil_K.hpp"
#include "immerse/coupling/NodeDiagnostics.hpp"

namespace immerse {

using ib_stencil::interpolate_component;
using ib_stencil::NodeStencil;
using ib_stencil::spread_component;

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
