#include "immerse/parallel/SlabDecomposition.hpp"

#include <algorithm>
#include <cstddef>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

namespace immerse {

namespace {

std::array<int, 3> global_shape(const Grid& g, Layout layout) {
  return layout == Layout::Pressure ? g.cell_shape() : g.face_shape(static_cast<int>(layout));
}

/// Whether `layout` is u_z between walls along z (its unknowns are the faces 1 … N_z − 1).
bool normal_to_z_walls(const Grid& g, Layout layout) { return layout == Layout::VelocityZ && !g.periodic(2); }

}  // namespace

SlabDecomposition::SlabDecomposition(const Grid& grid, Communicator comm)
    : grid_(grid), comm_(comm), rank_(comm.rank()), size_(comm.size()) {
  const int nz = grid_.n(2);
  block_ = (nz + size_ - 1) / size_;
  z0_ = std::min(rank_ * block_, nz);
  z1_ = std::min(z0_ + block_, nz);
  const int last_cells = nz - (size_ - 1) * block_;
  const int needed = grid_.periodic(2) ? 1 : 2;
  if (last_cells < needed)
    throw std::invalid_argument("SlabDecomposition: " + std::to_string(size_) + " processes for " + std::to_string(nz) +
                                " cell planes along z leave the last process " +
                                std::to_string(std::max(last_cells, 0)) +
                                " (blocks of " + std::to_string(block_) + "); every process needs at least " +
                                std::to_string(needed) + (grid_.periodic(2) ? "" : " between walls along z"));
}

PlaneRange SlabDecomposition::owned(Layout layout) const {
  if (normal_to_z_walls(grid_, layout)) return {z0_ + 1, std::min(z1_, grid_.n(2) - 1) + 1};
  return {z0_, z1_};
}

PlaneRange SlabDecomposition::held(Layout layout) const {
  PlaneRange r = owned(layout);
  if (normal_to_z_walls(grid_, layout)) {
    if (first()) r.begin = 0;
    if (last()) r.end = grid_.n(2) + 1;
  }
  return r;
}

int SlabDecomposition::holder(Layout layout, int plane) const {
  const int planes = global_shape(grid_, layout)[2];
  if (plane < 0 || plane >= planes)
    throw std::out_of_range("SlabDecomposition::holder: plane " + std::to_string(plane) + " of " +
                            std::to_string(planes));
  if (normal_to_z_walls(grid_, layout)) return plane == 0 ? 0 : (plane - 1) / block_;  // faces z0 + 1 … z1
  return plane / block_;
}

std::array<int, 3> SlabDecomposition::local_shape(Layout layout) const {
  const std::array<int, 3> s = global_shape(grid_, layout);
  return {s[0], s[1], z1_ - z0_ + 3};
}

Array3 SlabDecomposition::make(Layout layout) const {
  const std::array<int, 3> s = local_shape(layout);
  return Array3(s[0], s[1], s[2]);
}

int SlabDecomposition::lower_neighbor() const {
  if (!first()) return rank_ - 1;
  return grid_.periodic(2) ? size_ - 1 : MPI_PROC_NULL;
}

int SlabDecomposition::upper_neighbor() const {
  if (!last()) return rank_ + 1;
  return grid_.periodic(2) ? 0 : MPI_PROC_NULL;
}

void SlabDecomposition::scatter(const Array3& global, Layout layout, Array3& local) const {
  if (global.shape() != global_shape(grid_, layout))
    throw std::invalid_argument("SlabDecomposition::scatter: the array does not match the layout on the grid");
  if (local.shape() != local_shape(layout)) local = make(layout);
  const PlaneRange r = held(layout);
  const std::size_t plane = static_cast<std::size_t>(global.nx()) * global.ny();
  std::copy_n(global.data() + global.index(0, 0, r.begin), plane * r.count(),
              local.data() + local.index(0, 0, r.begin - offset()));
}

Array3 SlabDecomposition::gather(const Array3& local, Layout layout) const {
  if (local.shape() != local_shape(layout))
    throw std::invalid_argument("SlabDecomposition::gather: the array is not a slab array of the layout");
  const PlaneRange r = held(layout);
  const std::size_t plane = static_cast<std::size_t>(local.nx()) * local.ny();
  const double* const first_plane = local.data() + local.index(0, 0, r.begin - offset());
  const std::vector<double> all = comm_.all_gather(std::span<const double>(first_plane, plane * r.count()));
  const std::array<int, 3> s = global_shape(grid_, layout);
  Array3 global(s[0], s[1], s[2]);
  if (all.size() != global.size()) throw std::logic_error("SlabDecomposition::gather: the slabs do not tile the array");
  std::copy(all.begin(), all.end(), global.data());
  return global;
}

}  // namespace immerse
