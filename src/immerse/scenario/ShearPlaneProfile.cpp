#include "immerse/scenario/ShearPlaneProfile.hpp"

#include <array>
#include <cmath>
#include <limits>

namespace immerse {

ShearPlaneProfile shear_plane_profile(const Mesh& mesh, const std::vector<Vec3>& X, const Vec3& c) {
  // Sub-triangles of a 6-node element (v0 v1 v2 m01 m12 m20).
  static constexpr std::array<std::array<int, 3>, 4> sub{{{0, 3, 5}, {3, 1, 4}, {5, 4, 2}, {3, 4, 5}}};
  double L = 0, B = std::numeric_limits<double>::infinity();
  auto visit = [&](const Vec3& p) {
    const double r = std::hypot(p.x - c.x, p.z - c.z);
    L = std::max(L, r);
    B = std::min(B, r);
  };
  for (const auto& e : mesh.elements)
    for (const auto& t : sub)
      for (int k = 0; k < 3; ++k) {
        const Vec3& a = X[e[t[k]]];
        const Vec3& b = X[e[t[(k + 1) % 3]]];
        const double sa = a.y - c.y, sb = b.y - c.y;
        if ((sa < 0) == (sb < 0)) continue;  // the edge does not cross the plane y = c.y
        visit(a + (b - a) * (sa / (sa - sb)));
      }
  ShearPlaneProfile p;
  if (L > 0 && std::isfinite(B)) p = {L, B, (L - B) / (L + B)};
  return p;
}

}  // namespace immerse
