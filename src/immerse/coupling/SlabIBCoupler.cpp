#include "immerse/coupling/SlabIBCoupler.hpp"

#include <mpi.h>

#include <algorithm>
#include <climits>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <variant>

#include "immerse/core/ThreadThresholds.hpp"
#include "immerse/coupling/IBStencil_K.hpp"
#include "immerse/coupling/NodeDiagnostics.hpp"

namespace immerse {

namespace {

/// The line stencils of a node: along x and y those of the whole grid (IBCoupler's), along z those of the padded
/// buffers, whose plane 0 is the global plane begin_c (centres, components 0 and 1) or begin_f (faces, component 2)
/// and into which the node's z image is shifted by `shift` planes.
template <class K>
ib_stencil::NodeStencil<K> node_stencil(const std::array<IndexAxis, 3>& axes, const Vec3& x, int shift, int begin_c,
                                        int count_c, int begin_f, int count_f) {
  ib_stencil::NodeStencil<K> s;
  for (int a = 0; a < 2; ++a) {
    const double t = axes[a].face_coordinate(x[a]);
    s.line[a][1] = ib_stencil::line_stencil<K>(axes[a], t, axes[a].faces());
    s.line[a][0] = ib_stencil::line_stencil<K>(axes[a], t - 0.5, axes[a].n);
  }
  const double t = axes[2].face_coordinate(x[2]);
  s.line[2][1] = ib_stencil::line_stencil<K>(t, count_f, false, 0, shift - begin_f);
  s.line[2][0] = ib_stencil::line_stencil<K>(t - 0.5, count_c, false, 0, shift - begin_c);
  return s;
}

std::size_t plane_size(const Array3& a) { return static_cast<std::size_t>(a.nx()) * a.ny(); }

}  // namespace

SlabIBCoupler::SlabIBCoupler(const SlabDecomposition& slabs, DeltaKernel kernel)
    : slabs_(slabs), grid_(slabs.grid()), kernel_(kernel),
      axes_{IndexAxis(grid_, 0), IndexAxis(grid_, 1), IndexAxis(grid_, 2)}, rank_(slabs.communicator().rank()),
      size_(slabs.communicator().size()) {
  for (int d = 0; d < 3; ++d) {
    planes_[d] = grid_.face_shape(d)[2];
    const std::array<int, 3> s = grid_.face_shape(d);
    buffer_[d] = Array3(s[0], s[1], 0);
  }
  all_ranges_.resize(static_cast<std::size_t>(3) * size_);
}

int SlabIBCoupler::wrap(int d, int plane) const {
  if (!grid_.periodic(2)) return plane;
  const int n = planes_[d];
  return (plane % n + n) % n;
}

template <class K>
void SlabIBCoupler::prepare(std::span<const Vec3> X) {
  const int n = static_cast<int>(X.size()), nz = grid_.n(2);
  const bool periodic = grid_.periodic(2);
  const double centre = 0.5 * (slabs_.cells().begin + slabs_.cells().end);  // of the owned planes, face index units
  shift_.resize(X.size());
  int lo_c = INT_MAX, hi_c = INT_MIN, lo_f = INT_MAX, hi_f = INT_MIN;
  for (int l = 0; l < n; ++l) {
    const double t = axes_[2].face_coordinate(X[l][2]);
    int shift = 0;
    if (periodic) {  // the image nearest the owned planes
      if (std::abs(t - nz - centre) < std::abs(t - centre)) shift = -nz;
      if (std::abs(t + nz - centre) < std::abs(t + shift - centre)) shift = nz;
    }
    shift_[l] = shift;
    const int first_c = K::first(t - 0.5) + shift, first_f = K::first(t) + shift;
    lo_c = std::min(lo_c, first_c);
    hi_c = std::max(hi_c, first_c + K::width);
    lo_f = std::min(lo_f, first_f);
    hi_f = std::max(hi_f, first_f + K::width);
  }
  if (n == 0) lo_c = hi_c = lo_f = hi_f = 0;
  range_[0] = range_[1] = {lo_c, hi_c};
  range_[2] = {lo_f, hi_f};
  for (int d = 0; d < 3; ++d) {
    Range& r = range_[d];
    if (!periodic) {  // the stored planes only: kernel points beyond a wall are dropped, as in IBCoupler
      r.begin = std::max(r.begin, 0);
      r.end = std::min(r.end, planes_[d]);
      if (r.end <= r.begin) r = {};
    }
    const int count = r.end - r.begin;
    if (buffer_[d].nz() != count) buffer_[d] = Array3(buffer_[d].nx(), buffer_[d].ny(), count);
  }
  gather_ranges();
}

void SlabIBCoupler::gather_ranges() {
  int mine[6];
  for (int d = 0; d < 3; ++d) {
    mine[2 * d] = range_[d].begin;
    mine[2 * d + 1] = range_[d].end;
  }
  std::vector<int> all(static_cast<std::size_t>(6) * size_);
  check_mpi(MPI_Allgather(mine, 6, MPI_INT, all.data(), 6, MPI_INT, slabs_.communicator().comm()), "MPI_Allgather");
  for (std::size_t q = 0; q < all_ranges_.size(); ++q) all_ranges_[q] = {all[2 * q], all[2 * q + 1]};
}

void SlabIBCoupler::count_planes(std::vector<int>& mine, std::vector<int>& theirs) const {
  mine.assign(size_, 0);
  theirs.assign(size_, 0);
  for (int d = 0; d < 3; ++d) {
    const Layout layout = velocity_layout(d);
    const int per_plane = static_cast<int>(plane_size(buffer_[d]));
    for (int q = range_[d].begin; q < range_[d].end; ++q) mine[slabs_.holder(layout, wrap(d, q))] += per_plane;
    for (int r = 0; r < size_; ++r) {
      const Range& range = all_ranges_[static_cast<std::size_t>(3) * r + d];
      for (int q = range.begin; q < range.end; ++q)
        if (slabs_.holder(layout, wrap(d, q)) == rank_) theirs[r] += per_plane;
    }
  }
}

SlabIBCoupler::Exchange SlabIBCoupler::plan_exchange(bool spreading) {
  Exchange e;
  if (spreading)
    count_planes(e.send_counts, e.recv_counts);
  else
    count_planes(e.recv_counts, e.send_counts);
  e.send_offsets.assign(size_, 0);
  e.recv_offsets.assign(size_, 0);
  for (int r = 1; r < size_; ++r) {
    e.send_offsets[r] = e.send_offsets[r - 1] + e.send_counts[r - 1];
    e.recv_offsets[r] = e.recv_offsets[r - 1] + e.recv_counts[r - 1];
  }
  send_.resize(static_cast<std::size_t>(e.send_offsets[size_ - 1]) + e.send_counts[size_ - 1]);
  recv_.resize(static_cast<std::size_t>(e.recv_offsets[size_ - 1]) + e.recv_counts[size_ - 1]);
  return e;
}

void SlabIBCoupler::exchange(const Exchange& e) {
  check_mpi(MPI_Alltoallv(send_.data(), e.send_counts.data(), e.send_offsets.data(), MPI_DOUBLE, recv_.data(),
                      e.recv_counts.data(), e.recv_offsets.data(), MPI_DOUBLE, slabs_.communicator().comm()),
        "MPI_Alltoallv");
}

void SlabIBCoupler::check_slab(const FaceField& field, const char* what) const {
  for (int d = 0; d < 3; ++d)
    if (field[d].shape() != slabs_.local_shape(velocity_layout(d)))
      throw std::invalid_argument(std::string("SlabIBCoupler: ") + what + " is not a slab field of the decomposition");
}

template <class K>
void SlabIBCoupler::spread(std::span<const Vec3> X, std::span<const Vec3> F) {
  for (Array3& b : buffer_) b.fill(0.0);
  const double inv_h3 = 1.0 / grid_.cell_volume();
  const int count_c = range_[0].end - range_[0].begin, count_f = range_[2].end - range_[2].begin;
  for (std::size_t l = 0; l < X.size(); ++l) {
    const auto s = node_stencil<K>(axes_, X[l], shift_[l], range_[0].begin, count_c, range_[2].begin, count_f);
    for (int d = 0; d < 3; ++d)
      ib_stencil::spread_component(s.along(0, d), s.along(1, d), s.along(2, d), F[l][d] * inv_h3, buffer_[d]);
  }
}

template <class K>
void SlabIBCoupler::interpolate(std::span<const Vec3> X, std::span<Vec3> U) const {
  const int count_c = range_[0].end - range_[0].begin, count_f = range_[2].end - range_[2].begin;
  const long n = static_cast<long>(X.size());
#pragma omp parallel for if (n >= kMinNodesForThreads)
  for (long l = 0; l < n; ++l) {
    const auto s = node_stencil<K>(axes_, X[l], shift_[l], range_[0].begin, count_c, range_[2].begin, count_f);
    for (int d = 0; d < 3; ++d)
      U[l][d] = ib_stencil::interpolate_component(s.along(0, d), s.along(1, d), s.along(2, d), buffer_[d]);
  }
}

void SlabIBCoupler::spread_force(std::span<const Vec3> X, std::span<const Vec3> F, FaceField& f) {
  if (F.size() != X.size()) throw std::invalid_argument("SlabIBCoupler::spread_force: X and F differ in length");
  check_nodes_in_domain(grid_, X);
  std::visit(
      [&](const auto& k) {
        using K = std::decay_t<decltype(k)>;
        prepare<K>(X);
        spread<K>(X, F);
      },
      kernel_);
  // Each plane of the buffers to its holder, in the order (holder, component, plane).
  const Exchange planned = plan_exchange(true);
  std::size_t at = 0;
  for (int r = 0; r < size_; ++r)
    for (int d = 0; d < 3; ++d) {
      const std::size_t n = plane_size(buffer_[d]);
      for (int q = range_[d].begin; q < range_[d].end; ++q)
        if (slabs_.holder(velocity_layout(d), wrap(d, q)) == r) {
          const double* const plane = buffer_[d].data() + n * static_cast<std::size_t>(q - range_[d].begin);
          std::copy_n(plane, n, send_.data() + at);
          at += n;
        }
    }
  exchange(planned);
  // The held planes: the sum of the received planes, added in the order of the senders' ranks.
  bool shaped = true;
  for (int d = 0; d < 3; ++d) shaped = shaped && f[d].shape() == slabs_.local_shape(velocity_layout(d));
  if (!shaped)
    for (int d = 0; d < 3; ++d) f[d] = slabs_.make(velocity_layout(d));
  f.fill(0.0);
  const int offset = slabs_.offset();
  at = 0;
  for (int r = 0; r < size_; ++r)
    for (int d = 0; d < 3; ++d) {
      const Range& range = all_ranges_[static_cast<std::size_t>(3) * r + d];
      const std::size_t n = plane_size(buffer_[d]);
      for (int q = range.begin; q < range.end; ++q) {
        const int g = wrap(d, q);
        if (slabs_.holder(velocity_layout(d), g) != rank_) continue;
        double* const plane = f[d].data() + f[d].index(0, 0, g - offset);
        const double* const in = recv_.data() + at;
        for (std::size_t p = 0; p < n; ++p) plane[p] += in[p];
        at += n;
      }
    }
}

void SlabIBCoupler::interpolate_velocity(const FaceField& u, std::span<const Vec3> X, std::span<Vec3> U) {
  if (U.size() != X.size())
    throw std::invalid_argument("SlabIBCoupler::interpolate_velocity: X and U differ in length");
  check_slab(u, "the velocity field");
  check_nodes_in_domain(grid_, X);
  std::visit([&](const auto& k) { prepare<std::decay_t<decltype(k)>>(X); }, kernel_);
  // The held planes each process's buffers need, to it, in the order (component, plane) of its buffers.
  const Exchange planned = plan_exchange(false);
  const int offset = slabs_.offset();
  std::size_t at = 0;
  for (int r = 0; r < size_; ++r)
    for (int d = 0; d < 3; ++d) {
      const Range& range = all_ranges_[static_cast<std::size_t>(3) * r + d];
      const std::size_t n = plane_size(buffer_[d]);
      for (int q = range.begin; q < range.end; ++q) {
        const int g = wrap(d, q);
        if (slabs_.holder(velocity_layout(d), g) != rank_) continue;
        std::copy_n(u[d].data() + u[d].index(0, 0, g - offset), n, send_.data() + at);
        at += n;
      }
    }
  exchange(planned);
  for (int r = 0; r < size_; ++r) {  // the planes from holder r sit at recv_offsets[r], in (component, plane) order
    at = static_cast<std::size_t>(planned.recv_offsets[r]);
    for (int d = 0; d < 3; ++d) {
      const std::size_t n = plane_size(buffer_[d]);
      for (int q = range_[d].begin; q < range_[d].end; ++q) {
        if (slabs_.holder(velocity_layout(d), wrap(d, q)) != r) continue;
        std::copy_n(recv_.data() + at, n, buffer_[d].data() + n * static_cast<std::size_t>(q - range_[d].begin));
        at += n;
      }
    }
  }
  std::visit([&](const auto& k) { interpolate<std::decay_t<decltype(k)>>(X, U); }, kernel_);
}

}  // namespace immerse
