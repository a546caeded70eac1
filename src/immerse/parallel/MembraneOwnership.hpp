#pragma once
// Which MPI process owns each membrane when the fluid grid is cut into slabs of z planes (SlabDecomposition.hpp), and
// the migration of a membrane to its new owner when it moves.
//
// Ownership rule. Membrane m is owned by exactly one process: the one whose cell planes [z0, z1) contain the z
// coordinate of its centroid c_m = (1/n_m) Σ_i X_i (the mean of its node positions, added in node order), taken in
// face index units as the coupler takes node coordinates (IndexAxis::face_coordinate: wrapped into [0, N_z) on a
// periodic z; on a wall axis clamped to the cell planes). So process floor(c_z / h) / B owns it, B = ⌈N_z / P⌉. The
// positions of one membrane are kept continuous (a membrane across a periodic boundary has nodes beyond it, not
// wrapped node by node), as in the serial run, so its centroid is its geometric centre.
//
// State per owned membrane: its global index, its node positions and its reference (unstressed) positions. Each
// process keeps its membranes in ascending global index; their nodes concatenated in that order are the nodes it
// spreads and interpolates (SlabIBCoupler). The node count of every membrane is known on every process.
//
// Migration (migrate()) recomputes every owned membrane's owner from its current positions and sends those that
// changed, index, positions and reference positions, to their new owners in one MPI_Alltoallv; each process then
// sorts its membranes by index again. The result depends only on the positions, not on message timing. follow() sends
// other per-node values (say an integrator's history) the way the last migrate() sent the membranes. gather()
// assembles per-node values (positions, velocities) of all membranes in global membrane order on every process.
// Collective: the constructor (only in that every process passes the same membranes), migrate(), gather() and
// gather_positions() are called by every process of the decomposition's communicator.
// Verified by: the tests ParallelCoupling.* (tests/test_parallel_coupling.cpp, run with 1, 2 and 3 processes:
// initial ownership, a membrane moved across a slab boundary and across the periodic wrap migrates and its gathered
// positions are unchanged bitwise).
#include <cstddef>
#include <span>
#include <vector>

#include "immerse/core/Vec3.hpp"
#include "immerse/parallel/SlabDecomposition.hpp"

namespace immerse {

/// One membrane held by its owning process.
struct OwnedMembrane {
  int id = 0;                   ///< global membrane index
  std::vector<Vec3> positions;  ///< current node positions
  std::vector<Vec3> reference;  ///< reference (unstressed) node positions
};

class MembraneOwnership {
 public:
  /// Every process passes the positions and reference positions of all membranes (global order) and keeps the
  /// ones it owns. `slabs` is kept by reference (it must outlive this object). std::invalid_argument if a membrane
  /// has no nodes or its two arrays differ in length.
  MembraneOwnership(const SlabDecomposition& slabs, std::span<const std::vector<Vec3>> positions,
                    std::span<const std::vector<Vec3>> reference);

  /// The mean of the node positions, added in node order.
  static Vec3 centroid(std::span<const Vec3> X);
  /// The rank owning a membrane with node positions X (the ownership rule above).
  int owner(std::span<const Vec3> X) const;

  int num_membranes() const { return static_cast<int>(node_counts_.size()); }
  /// Node count of global membrane m.
  int num_nodes(int m) const { return node_counts_[m]; }
  /// This process's membranes, ascending in global index. Positions may be changed in place (then migrate()).
  const std::vector<OwnedMembrane>& owned() const { return owned_; }
  std::vector<OwnedMembrane>& owned() { return owned_; }
  /// Number of nodes of this process's membranes.
  std::size_t num_owned_nodes() const;
  /// The positions of this process's membranes, concatenated in owned() order.
  std::vector<Vec3> owned_positions() const;
  /// Sets them from such a concatenation.
  void set_owned_positions(std::span<const Vec3> X);

  /// Moves every membrane whose owner changed to its new owner; returns how many moved (the same on every rank).
  /// Collective.
  int migrate();
  /// Per-node values that travel with the membranes: `before` holds `arrays` arrays of 3 values per node over the
  /// membranes owned before the last migrate() (in their order then), concatenated; returns the same arrays over the
  /// membranes owned now (an integrator's history, for instance). Collective.
  std::vector<double> follow(std::span<const double> before, std::size_t arrays) const;
  /// Per-node values of this process's membranes (concatenated in owned() order) assembled for all membranes in
  /// global order, on every process. Collective.
  std::vector<Vec3> gather(std::span<const Vec3> owned_values) const;
  /// The positions of all membranes in global order, on every process. Collective.
  std::vector<std::vector<Vec3>> gather_positions() const;

 private:
  const SlabDecomposition& slabs_;
  std::vector<int> node_counts_;
  std::vector<std::size_t> node_offsets_;  ///< of membrane m in the global concatenation
  std::vector<OwnedMembrane> owned_;
  struct Move {
    int id, to;
  };
  std::vector<Move> moves_;  ///< the membranes owned before the last migrate(), in their order then, and their owners
};

}  // namespace immerse
