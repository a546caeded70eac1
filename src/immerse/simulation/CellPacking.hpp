#pragma once
// Dense initial suspensions: N copies of one membrane placed at random positions and orientations in the box with
// no two closer than a clearance, by random sequential addition with growth (as HemoCell's packCells, Závodszky
// et al. 2017, Front. Physiol. 8:563, grows cells after placing them small):
//
//   1. every copy gets a uniformly random rotation (Shoemake 1992 quaternions) and is placed at scale s0 by random
//      sequential addition, its bounding sphere clear of the others' and of the walls;
//   2. all copies grow by 1 % about their centres; every copy that has a node within `clearance` of a node of
//      another copy (minimum images on periodic axes) is pushed away from it along the line of centres, and away
//      from walls it comes within `clearance` of, until no pair is too close (translations only); then they grow
//      again, until full size.
//
// Node gaps stand for surface gaps when nodes lie closer than the clearance (checked: a surface crossing another
// between nodes would otherwise go unseen). The random numbers are xoshiro256** (Blackman & Vigna 2021) seeded by
// splitmix64, mapped to doubles by their top 53 bits, so a seed gives the same packing on every machine and compiler.
// Verified by the tests CellPacking.* (no pair within the clearance, reproducible by seed, the volume fraction).
#include <cstdint>
#include <vector>

#include "immerse/grid/Grid.hpp"
#include "immerse/membrane/Shape.hpp"

namespace immerse {

struct PackingRequest {
  std::size_t count = 0;      ///< copies to place
  std::uint64_t seed = 1;
  double clearance = 0;       ///< least distance between nodes of two copies, and from a node to a wall (m)
};

class CellPacking {
 public:
  /// `shape`: the nodes of one copy about its centroid. Throws InputError naming `key` when the copies do not fit
  /// (with the fraction reached) or when the nodes are too far apart for the node-gap test.
  CellPacking(const Grid& grid, const std::vector<Vec3>& shape, double max_node_spacing, const PackingRequest& request,
              const char* key);

  /// The rigid placement of each copy: x -> rotation·x + translation (x about the centroid).
  const std::vector<RigidTransform>& placements() const { return placements_; }

 private:
  std::vector<RigidTransform> placements_;
};

}  // namespace immerse
