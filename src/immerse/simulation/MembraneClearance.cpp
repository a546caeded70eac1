#include "immerse/simulation/MembraneClearance.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <tuple>

namespace immerse {

Vec3 minimum_image(const Grid& grid, const Vec3& a, const Vec3& b) {
  Vec3 d = a - b;
  for (int k = 0; k < 3; ++k)
    if (grid.periodic(k)) d[k] -= grid.length(k) * std::round(d[k] / grid.length(k));
  return d;
}

std::optional<NodePairGap> closest_foreign_nodes(const Grid& grid, const std::vector<std::vector<Vec3>>& X,
                                                 double reach) {
  // Bins of size >= reach covering the box (nodes beyond a periodic end are wrapped in).
  std::array<long, 3> nb{};
  std::array<double, 3> size{};
  for (int k = 0; k < 3; ++k) {
    nb[k] = std::max(1L, static_cast<long>(std::floor(grid.length(k) / reach)));
    size[k] = grid.length(k) / double(nb[k]);
  }
  struct Item {
    long bin;
    std::size_t m, i;
  };
  auto bin_coords = [&](const Vec3& p) {
    std::array<long, 3> c{};
    for (int k = 0; k < 3; ++k) {
      double s = (p[k] - grid.origin()[k]) / size[k];
      if (grid.periodic(k)) s -= double(nb[k]) * std::floor(s / double(nb[k]));
      c[k] = std::clamp(static_cast<long>(std::floor(s)), 0L, nb[k] - 1);
    }
    return c;
  };
  auto bin_index = [&](const std::array<long, 3>& c) { return (c[2] * nb[1] + c[1]) * nb[0] + c[0]; };
  std::vector<Item> items;
  for (std::size_t m = 0; m < X.size(); ++m)
    for (std::size_t i = 0; i < X[m].size(); ++i) items.push_back({bin_index(bin_coords(X[m][i])), m, i});
  std::sort(items.begin(), items.end(), [](const Item& a, const Item& b) {
    return std::tie(a.bin, a.m, a.i) < std::tie(b.bin, b.m, b.i);
  });
  std::vector<std::size_t> start(static_cast<std::size_t>(nb[0] * nb[1] * nb[2]) + 1, items.size());
  for (std::size_t k = items.size(); k-- > 0;) start[static_cast<std::size_t>(items[k].bin)] = k;
  for (std::size_t b = start.size() - 1; b-- > 0;) start[b] = std::min(start[b], start[b + 1]);

  std::optional<NodePairGap> best;
  auto better = [&](const NodePairGap& g) {
    if (!best) return true;
    return std::tie(g.distance, g.membrane_b, g.node_b, g.membrane_a, g.node_a) <
           std::tie(best->distance, best->membrane_b, best->node_b, best->membrane_a, best->node_a);
  };
  for (std::size_t m = 0; m < X.size(); ++m)
    for (std::size_t i = 0; i < X[m].size(); ++i) {
      const auto c = bin_coords(X[m][i]);
      for (long dz = -1; dz <= 1; ++dz)
        for (long dy = -1; dy <= 1; ++dy)
          for (long dx = -1; dx <= 1; ++dx) {
            std::array<long, 3> n{c[0] + dx, c[1] + dy, c[2] + dz};
            bool inside = true;
            for (int k = 0; k < 3; ++k) {
              if (grid.periodic(k)) n[k] = (n[k] % nb[k] + nb[k]) % nb[k];
              inside = inside && n[k] >= 0 && n[k] < nb[k];
            }
            if (!inside) continue;
            const auto b = static_cast<std::size_t>(bin_index(n));
            for (std::size_t k = start[b]; k < start[b + 1]; ++k) {
              const Item& o = items[k];
              if (o.m >= m) continue;  // each pair once, from the higher membrane index
              const double d = norm(minimum_image(grid, X[m][i], X[o.m][o.i]));
              if (d >= reach) continue;
              const NodePairGap g{m, i, o.m, o.i, d};
              if (better(g)) best = g;
            }
          }
    }
  return best;
}

bool encloses(const Mesh& mesh, const std::vector<Vec3>& X, const Vec3& p) {
  // Solid angle of triangle (a, b, c) seen from the origin: tan(Ω/2) = a·(b×c) / (|a||b||c| + (a·b)|c| + ...).
  auto solid_angle = [&](int ia, int ib, int ic) {
    const Vec3 a = X[ia] - p, b = X[ib] - p, c = X[ic] - p;
    const double la = norm(a), lb = norm(b), lc = norm(c);
    return 2 * std::atan2(dot(a, cross(b, c)), la * lb * lc + dot(a, b) * lc + dot(b, c) * la + dot(c, a) * lb);
  };
  double omega = 0;
  for (const auto& e : mesh.elements)
    omega += solid_angle(e[0], e[3], e[5]) + solid_angle(e[3], e[1], e[4]) + solid_angle(e[5], e[4], e[2]) +
             solid_angle(e[3], e[4], e[5]);
  return omega > 2 * std::numbers::pi;  // 4π inside, 0 outside
}

}  // namespace immerse
