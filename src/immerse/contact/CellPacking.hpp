#pragma once
// Dense initial suspensions: N copies of one membrane placed at random positions and orientations in the box with
// no two closer than a clearance c, by random sequential addition followed by growth and an overdamped rigid-body
// relaxation (the force-biased packing of HemoCell's packCells, Závodszky et al. 2017, Front. Physiol. 8:563; the
// compress-and-relax route to jammed packings of soft repulsive particles, O'Hern et al. 2003, Phys. Rev. E
// 68:011306):
//
//   1. every copy i gets a uniformly random orientation q_i (Shoemake 1992 quaternions) and is placed at scale s0 by
//      random sequential addition, its bounding sphere clear of the others' and of the walls (a [[wall]] shape's too:
//      φ(c_i) at least the bounding radius plus c; the start scale from the fluid's volume);
//   2. at scale s copy i has the nodes x_ik = c_i + s R(q_i) p_k. Every pair of nodes of two copies closer than
//      c* = 1.05 c (minimum images on periodic axes), and every node closer than c* to a wall, repels with
//      f = (c* - d) n (n the unit vector between the nodes, or the wall's normal; ∇φ for a [[wall]] shape, d = φ):
//      the force of the energy
//      U = 1/2 sum (c* - d)^2. The forces sum into F_i = sum f and torques T_i = sum (x_ik - c_i) x f about the
//      centres, and the copies move as rigid bodies of unit mass and moment of inertia I = s^2 <|p_k|^2> down U
//      by FIRE (Bitzek et al. 2006, Phys. Rev. Lett. 97:170201): velocities dv_i = F_i dt and d(omega_i) = T_i/I dt,
//      mixed towards the forces and stopped when the power sum F·v + T·omega turns negative; the centres move by
//      v_i dt and the orientations turn by the rotation vector omega_i dt. No node moves more than 0.2 c in a step,
//      so no copy passes through another. The relaxation stops when no gap is below c;
//   3. the copies grow by up to 2 % (no node moving more than 0.2 c) and relax again, until full size. A size that
//      does not relax within 2,000 steps is stepped back towards the last clear one and the growth step halved;
//      when it falls below 1e-4, or a size fails after 20,000 steps in all, the copies are jammed and the request
//      is refused.
//
// Close node pairs come from a list of the pairs within (1.05 + 0.6) c, built by MembraneClearance's cell list and
// rebuilt when the two copies that moved most since have moved 0.6 c together (a Verlet list). Everything is summed
// in a fixed order on one thread, so a seed gives bitwise the same packing on every run. Node gaps stand for surface
// gaps when nodes lie closer than the clearance (checked: a surface crossing another between nodes would otherwise
// go unseen). The random numbers are xoshiro256** (Blackman & Vigna 2021) seeded by splitmix64, mapped to doubles by
// their top 53 bits.
// Verified by the tests CellPacking.* (red cells at a volume fraction of 0.4 in a periodic box and between walls: no
// pair within the clearance, no node inside another copy, no elements crossing, bitwise reproducible by seed; a
// fraction that cannot be reached is refused) and CellPacking.SpheresInATube (every node clear of a tube's wall).
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "immerse/grid/Grid.hpp"
#include "immerse/membrane/Shape.hpp"

namespace immerse {

class WallGeometry;

struct PackingRequest {
  std::size_t count = 0;      ///< copies to place
  std::uint64_t seed = 1;
  double clearance = 0;       ///< least distance between nodes of two copies, and from a node to a wall (m)
  /// The [[wall]] shapes (null: none): the copies are placed in their fluid, no node closer than the clearance to them.
  std::shared_ptr<const WallGeometry> walls;
  /// Asked between relaxation steps (when set): true ends the packing with StopRequested, nothing placed.
  std::function<bool()> stop_requested;
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
