#pragma once
// A wall given as a closed triangulated surface (shape = "surface" in [[wall]]; WallGeometry): read from an STL file
// (ASCII or binary; vertices merged by exact coordinate equality) or a Gmsh .msh file (3- or 6-node triangles, the
// corners kept), scaled to metres, checked (closed: every edge in exactly two triangles; consistently oriented; no
// zero-area triangle; not self-intersecting: no edge through another triangle sharing no vertex with it, clear of
// round-off) and oriented with its normals outward (all flipped if the enclosed volume is negative). Its signed
// distance d(x) is the exact point-triangle distance to the nearest triangle, found in a bounding-volume hierarchy
// (median splits, branch and bound on box distances), with the sign of the angle-weighted pseudonormal of the nearest
// feature (face, edge or vertex; Bærentzen & Aanæs 2005): positive outside, negative inside, exact for every point off
// the surface of a closed, manifold, non-self-intersecting surface. The gradient is ±(x − c)/|x − c|, c the nearest
// point, pointing outward. Verified by the tests WallSurface.* (distances against the exact sphere and cube, signs,
// normals, every defect, STL ASCII, binary and Gmsh, periodic images through WallGeometry, the surface sphere against
// the analytic one).
#include <array>
#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "immerse/core/Vec3.hpp"

namespace immerse {

class WallSurface {
 public:
  /// Checks and orients the surface; InputError "<label>: <defect>" (one line) if it is not a usable closed surface.
  WallSurface(std::vector<Vec3> vertices, std::vector<std::array<int, 3>> triangles, const std::string& label);

  /// Signed distance to the surface: positive outside, negative inside.
  double distance(const Vec3& x) const;
  /// Unit outward gradient of distance() at x (the pseudonormal of the nearest feature on the surface itself).
  Vec3 normal(const Vec3& x) const;
  /// Both at once: returns distance(x), sets grad = normal(x).
  double signed_distance(const Vec3& x, Vec3& grad) const;

  const std::vector<Vec3>& vertices() const { return vertices_; }
  const std::vector<std::array<int, 3>>& triangles() const { return triangles_; }
  Vec3 lower() const { return lower_; }  ///< bounding box
  Vec3 upper() const { return upper_; }
  double volume() const { return volume_; }  ///< enclosed volume (> 0)

 private:
  struct Node {
    Vec3 lo, hi;
    int first = 0, count = 0;  ///< leaf: triangles order_[first, first + count); else count = 0, children first, +1
  };
  void build(int node, int begin, int end, const std::vector<Vec3>& centroid);
  /// The lowest pair of triangles sharing no vertex of which one has an edge through the other, if any.
  std::optional<std::pair<std::size_t, std::size_t>> crossing_triangles() const;

  std::vector<Vec3> vertices_;
  std::vector<std::array<int, 3>> triangles_;
  std::vector<Vec3> face_normal_;                    ///< unit normals
  std::vector<std::array<Vec3, 3>> edge_normal_;     ///< edge k = (v_k, v_k+1): sum of its two faces' normals
  std::vector<Vec3> vertex_normal_;                  ///< angle-weighted sums of the face normals
  std::vector<int> order_;                           ///< triangles in BVH leaf order
  std::vector<Node> nodes_;                          ///< BVH, root at 0
  Vec3 lower_, upper_;
  double volume_ = 0;
};

/// Reads `file` (STL ASCII, STL binary or Gmsh .msh, told apart by content), multiplies its coordinates by `scale`
/// (metres per file unit) and builds the checked surface; InputError "<name> <file>: <defect>" otherwise.
WallSurface read_wall_surface(const std::filesystem::path& file, double scale, const std::string& name);

/// "[x, y, z]" with %g, for the walls' messages.
std::string point_text(const Vec3& v);

}  // namespace immerse
