#pragma once
// Short-range repulsion between the nodes of different membranes and between every node and the no-slip walls:
// a part of the nodal force f(X) that ImmersedBoundaryOperator spreads with the elastic forces (N, eq. 6), so the
// residual g(X) of every time scheme contains it. From one energy E = sum over pairs U(r) + sum over node-wall
// pairs U(s), with, for r < d (zero beyond),
//
//   U(r)   = eps K d^2 (1 - r/d)^3 / 3          (J)
//   F(r)   = -dU/dr = eps K d (1 - r/d)^2        (N, along the separation, repulsive)
//   dF/dr  = -2 eps K (1 - r/d)                  (N/m)
//
// F and dF/dr vanish at r = d, so the force and its Jacobian are continuous there (Newton's iterations see no kink).
//   r    distance of node i of membrane a to node j of another membrane b, by the minimum image along periodic axes
//   s    distance of a node of membrane a to a wall; the wall pushes along its inward normal (for a [[wall]] shape,
//        s = φ(X) and the normal ∇φ of WallGeometry)
//   d    contact.range (m; default the grid spacing h, at which the delta function of eq. (8) starts to merge
//        the two membranes' forces)
//   eps  contact.strength (dimensionless; default 1)
//   K    the small-strain area modulus K_s (N/m) of the membrane, (K_a + K_b) / 2 for a pair: neo-Hookean E_s,
//        Yeoh 6 C10, Skalak C11/2 + C21 (small_strain_area_modulus, of the in-plane law without the area dilation
//        energy, whose large K_D would stiffen every contact); the largest force of one pair, eps K d, is that of a
//        membrane strip of width d stretched to twice its area
// F_i = -dE/dX_i exactly, and the forces of a pair are equal and opposite to the last bit (total force zero).
// The law is the soft repulsion of dissipative particle dynamics, F = a (1 - r/d) (Groot & Warren, J. Chem. Phys.
// 107, 4423 (1997)), squared for a continuous derivative at r = d.
//
// Neighbour search: first the membranes' bounding boxes (a pair can touch only if its boxes, grown by d, overlap by
// minimum image), then a cell list of bins no smaller than d holding the nodes of the membranes that can touch (at
// most a few per node, so memory and cost are linear in the nodes), rebuilt at every evaluation. Each node sums the forces of its own neighbours in a fixed order (bins,
// then node index): the sums do not depend on the thread count. With no node within d of another membrane or a
// wall every force is exactly zero, and the run is bitwise that without contact.
// Verified by tests/test_simulation_contact.cpp (ContactForce.*: gradient, support, third law, walls, curved walls, neighbour
// search against brute force; ContactRun.*: two capsules kept apart in shear, an isolated capsule unchanged) and
// ParallelRun.* (bounds(), boxes_within_range() and set_search_nodes() on part of the membranes, in
// DistributedOperator: the forces of a distributed run equal the one-process run's).
#include <array>
#include <cstddef>
#include <memory>
#include <span>
#include <vector>

#include "immerse/core/Vec3.hpp"
#include "immerse/grid/Grid.hpp"
#include "immerse/membrane/MaterialLaw.hpp"

namespace immerse {

class WallGeometry;

struct ContactSettings {
  double range = 0;     ///< d (m); 0 switches contact off
  double strength = 1;  ///< eps (dimensionless)
  bool walls = true;    ///< node-wall repulsion on the wall axes and from the [[wall]] shapes
  /// The [[wall]] shapes (null: none): with `walls`, a node at distance s = φ(X) < d from them is pushed along ∇φ.
  std::shared_ptr<const WallGeometry> shapes;
};

/// K_s = (1/2) d tau / d lambda at lambda = 1 of the isotropic tension (MaterialLaw.hpp) of the law without its
/// area dilation energy, N/m.
double small_strain_area_modulus(const MaterialLaw& law);

class ContactForce {
 public:
  /// `offsets`: the first node of each membrane in the concatenated node arrays, and the node count at the end;
  /// `moduli`: K of each membrane (N/m). InputError naming contact.range if d is not below half of every periodic
  /// length (the minimum image must be the only image within d).
  ContactForce(const Grid& grid, const ContactSettings& settings, const std::vector<std::size_t>& offsets,
               std::vector<double> moduli);

  bool active() const { return settings_.range > 0; }
  /// Sizes the bins of the neighbour search as for `nodes` nodes instead of the nodes passed to compute() (0: those).
  /// A process that computes the forces of some membranes from them and their neighbours alone (DistributedOperator)
  /// passes the node count of all membranes: its bins, and so each node's order of additions, are then those of the
  /// whole run, and its forces equal the whole run's bitwise.
  void set_search_nodes(std::size_t nodes) { search_nodes_ = nodes; }

  /// The bounding box of a membrane's nodes X, as the broad phase sees it: centre c, half-widths s and the largest
  /// distance R of a node from c.
  struct Bounds {
    Vec3 centre, half;
    double radius = 0;
  };
  static Bounds bounds(std::span<const Vec3> X);
  /// The broad phase's test (see bin()): whether two membranes with these bounds may have nodes within d.
  static bool boxes_within_range(const Grid& grid, double d, const Bounds& a, const Bounds& b);
  /// F = -dE/dX at the concatenated nodes X (F sized like X; overwritten).
  void compute(std::span<const Vec3> X, std::span<Vec3> F);
  /// E (J).
  double energy(std::span<const Vec3> X);
  /// The nodes of other membranes within d of each node, ascending (the search compute() uses).
  std::vector<std::vector<std::size_t>> neighbours(std::span<const Vec3> X);

  /// |F(r)| / (eps K d) = (1 - r/d)^2 for r < d, else 0.
  static double pair_force_shape(double r, double d) {
    if (r >= d) return 0;
    const double t = 1 - r / d;
    return t * t;
  }

 private:
  /// Marks the membranes whose bounding box, grown by d, overlaps another's, and sorts their nodes into bins
  /// (counting sort: ascending node index within a bin); the other nodes have no neighbours.
  void bin(std::span<const Vec3> X);
  /// Whether membrane `m` has a bounding box within d of another's (set by bin()).
  bool may_touch(std::size_t m) const { return touching_[m] != 0; }
  std::array<long, 3> bin_coords(const Vec3& p) const;
  /// f(j, X_i - X_j by minimum image, r) for each node j of another membrane within d of node i, in a fixed order.
  template <class F>
  void for_each_neighbour(std::span<const Vec3> X, std::size_t i, F&& f) const;
  /// eps K d of a pair of membranes (or of a membrane and a wall: a == b).
  double scale(std::size_t a, std::size_t b) const { return eps_d_ * 0.5 * (moduli_[a] + moduli_[b]); }

  Grid grid_;
  ContactSettings settings_;
  double eps_d_;
  std::vector<double> moduli_;
  std::vector<std::size_t> offsets_;      ///< first node of each membrane, and the node count
  std::vector<std::size_t> membrane_of_;  ///< membrane of each node
  std::array<long, 3> nb_{};              ///< bins along each axis
  std::array<double, 3> size_{};          ///< bin size along each axis (>= d)
  std::vector<std::size_t> node_bin_, start_, sorted_;  ///< bin of each node; bin b holds sorted_[start_[b] .. start_[b+1])
  std::vector<std::size_t> next_;                       ///< bin() work: next free slot of each bin
  std::vector<char> touching_;                          ///< per membrane: may touch another (bin())
  std::size_t search_nodes_ = 0;                        ///< set_search_nodes()
};

}  // namespace immerse
