#pragma once
// Rigid walls of any shape inside a periodic box ([[wall]] in the configuration; docs/walls.md), represented by the
// signed distance
//   φ(x) > 0 in the fluid,   φ(x) < 0 inside a wall,   |∇φ| = 1,
// exact for each analytic shape and taken to the nearest periodic image of it:
//   tube    the fluid inside a circular cylinder of radius R about the line     φ = R − |(x − c) − ((x − c)·t) t|
//           through c along the unit vector t (everything outside is wall)
//   sphere  a solid ball of radius R at c                                        φ = |x − c| − R
//   box     an axis-aligned box of edges s about c, a solid block or,            φ = b_s(x − c) (solid) or
//           fluid_inside, a channel (all outside it wall); an edge at least the   φ = −b_s(x − c) (fluid inside)
//           box's length spans that periodic axis (a rectangular duct along it)
//   constriction  a rectangular channel of widths s across the coordinate axis t through c, narrowed to the widths w
//           over the length ℓ = w·t about c (a square channel with a throat, Park & Dimitrakopoulos 2013, Soft Matter
//           9:8844):                                                          φ = min(−b_s, max(b_slab, −b_w))
//   surface a closed triangulated surface S (WallSurface, its signed distance    φ = d_S(x) (a solid obstacle) or
//           d_S > 0 outside), bounding a solid or, fluid_inside, the fluid       φ = −d_S(x) (fluid inside)
// with b_s(r) = |max(q, 0)| + min(max_a q_a, 0), q_a = |r_a| − s_a/2, the exact signed distance to a box (axes the box
// spans left out), and b_slab = |r·t| − ℓ/2. The constriction's φ is exact away from the throat's edges and corners
// and has the right sign everywhere (the no-slip condition needs only the sign: GhostCellWalls bisects on it).
// The wall is the union of the shapes' solids, so φ = min over the shapes (exact wherever one shape is nearest, and its
// sign always right): a channel with obstacles in it, or a constriction of another shape, is a union. A tube must close on itself across the box: t along a whole-number combination of the periodic
// box's edge vectors, with the tube clear of its own periodic images. Verified by the tests WallGeometry.* (distances,
// normals, images, bad input) and, through the no-slip condition, GhostCellWalls.* and TubeFlow.*. The images of a
// surface are those of the 27 lattice shifts nearest to it, united as the tube's and the sphere's are (d_S = min over
// the images): verified by the tests WallSurface.*.
#include <array>
#include <memory>
#include <string>
#include <vector>

#include "immerse/core/Vec3.hpp"
#include "immerse/grid/Grid.hpp"
#include "immerse/walls/WallSurface.hpp"

namespace immerse {

struct WallShape {
  enum class Kind { Tube, Sphere, Box, Constriction, Surface };
  Kind kind = Kind::Tube;
  Vec3 center{};
  Vec3 axis{0, 0, 1};  ///< tube: its direction (normalized by WallGeometry); constriction: a coordinate axis
  double radius = 0;
  double period = 0;   ///< tube: the length of its axis in one period of the box (set by WallGeometry)
  std::string name;    ///< "wall[i]", for messages
  std::shared_ptr<const WallSurface> surface{};  ///< surface: the closed surface (radius, center, axis unused)
  bool fluid_inside = false;  ///< box, surface: the fluid inside it, all outside wall (else a solid)
  Vec3 size{};         ///< box: its edges; constriction: the channel's widths across the axis (m)
  Vec3 throat{};       ///< constriction: the throat's widths across the axis and its length along it (m)
};

class WallGeometry {
 public:
  /// Validates the shapes against the box (InputError naming the item): radius > 0, a tube's axis a lattice direction
  /// of the box and the tube clear of its images, a sphere's centre in the box and the ball inside one period, a
  /// surface's bounding box meeting the box.
  WallGeometry(std::vector<WallShape> shapes, const Grid& grid);

  /// φ(x): the signed distance to the nearest wall, positive in the fluid.
  double distance(const Vec3& x) const;
  /// ∇φ at x: the unit normal of the nearest wall, pointing into the fluid.
  Vec3 normal(const Vec3& x) const;

  const std::vector<WallShape>& shapes() const { return shapes_; }

  /// Whether every shape is invariant along coordinate axis a: a tube along it, or a box spanning it.
  bool invariant_along(int a) const;

  /// The walls' surfaces as triangles for display, at about spacing h: a tube over one period of its axis centred at
  /// its centre, a sphere by latitude and longitude, a box or constriction as the zero level set of its φ over the
  /// box (marching tetrahedra on a lattice of spacing about h), a surface as it is. `shape_of` gets the index of each
  /// triangle's shape.
  void triangulate(double h, std::vector<Vec3>& vertices, std::vector<std::array<int, 3>>& triangles,
                   std::vector<int>& shape_of) const;

  /// The fluid's volume in the box of `grid` (m³): the points with φ > 0 of a lattice of spacing h/2.
  double fluid_volume(const Grid& grid) const;

 private:
  /// φ of one shape at x (nearest periodic image) and its gradient.
  double shape_distance(const WallShape& s, const Vec3& x, Vec3& grad) const;
  /// The same for a box or a constriction (x reduced to the nearest image of the centre).
  double block_distance(const WallShape& s, const Vec3& x, Vec3& grad) const;
  /// The same for a surface: the least signed distance to its images, negated if the fluid is inside.
  double surface_distance(const WallShape& s, const Vec3& x, Vec3& grad) const;

  /// Validates a box or constriction (InputError naming the key).
  void check_block(WallShape& s) const;

  std::vector<WallShape> shapes_;
  Vec3 origin_, length_;
  std::array<bool, 3> periodic_{};
};

}  // namespace immerse
