#include "immerse/scenario/ShearPlaneProfile.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include "immerse/membrane/MeshElement.hpp"

namespace immerse {

ShearPlaneProfile shear_plane_profile(const Mesh& mesh, const std::vector<Vec3>& X, const Vec3& c) {
  constexpr int n = ShearPlaneProfile::kDivisions;
  // Points (i/n, j/n), i + j <= n, of the parent triangle, row by row.
  const auto at = [](int i, int j) { return j * (n + 1) - j * (j - 1) / 2 + i; };
  std::array<Vec3, (n + 1) * (n + 2) / 2> P;
  double L = 0, B = std::numeric_limits<double>::infinity();
  const auto cut = [&](const Vec3& a, const Vec3& b) {
    const double sa = a.y - c.y, sb = b.y - c.y;
    if ((sa < 0) == (sb < 0)) return;  // the chord does not cross the plane y = c.y
    const Vec3 p = a + (b - a) * (sa / (sa - sb));
    const double r = std::hypot(p.x - c.x, p.z - c.z);
    L = std::max(L, r);
    B = std::min(B, r);
  };
  for (const auto& e : mesh.elements) {
    MeshElement::Nodes x;
    double lo = std::numeric_limits<double>::infinity(), hi = -lo;
    for (int k = 0; k < 6; ++k) {
      x[k] = X[e[k]];
      lo = std::min(lo, x[k].y);
      hi = std::max(hi, x[k].y);
    }
    // The curved element stays within a quarter of its nodes' spread beyond them.
    const double margin = 0.25 * (hi - lo);
    if (c.y < lo - margin || c.y > hi + margin) continue;
    for (int j = 0; j <= n; ++j)
      for (int i = 0; i + j <= n; ++i) P[at(i, j)] = MeshElement::position(x, double(i) / n, double(j) / n);
    for (int j = 0; j < n; ++j)
      for (int i = 0; i + j < n; ++i) {
        // The edges of the triangles (i, j), (i + 1, j), (i, j + 1) are every edge of the division, each once.
        const Vec3 &p = P[at(i, j)], &q = P[at(i + 1, j)], &r = P[at(i, j + 1)];
        cut(p, q);
        cut(q, r);
        cut(r, p);
      }
  }
  ShearPlaneProfile p;
  if (L > 0 && std::isfinite(B)) p = {L, B, (L - B) / (L + B)};
  return p;
}

}  // namespace immerse
