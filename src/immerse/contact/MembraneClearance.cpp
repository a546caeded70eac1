#include "immerse/contact/MembraneClearance.hpp"

#include <algorithm>
#include <array>
#include <functional>
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

void for_each_foreign_pair(const Grid& grid, const std::vector<std::vector<Vec3>>& X, double reach,
                           const std::function<void(const NodePairGap&)>& visit) {
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
              visit(NodePairGap{m, i, o.m, o.i, d});
            }
          }
    }
}

std::optional<NodePairGap> closest_foreign_nodes(const Grid& grid, const std::vector<std::vector<Vec3>>& X,
                                                 double reach) {
  std::optional<NodePairGap> best;
  for_each_foreign_pair(grid, X, reach, [&](const NodePairGap& g) {
    if (!best || std::tie(g.distance, g.membrane_b, g.node_b, g.membrane_a, g.node_a) <
                     std::tie(best->distance, best->membrane_b, best->node_b, best->membrane_a, best->node_a))
      best = g;
  });
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

namespace {

// Which side of the plane through a, b, c the point d lies on (sign of the tetrahedron's volume).
int side(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  const double v = dot(cross(b - a, c - a), d - a);
  return (v > 0) - (v < 0);
}

// Whether the segment pq passes through the interior of triangle abc (touching does not count).
bool crosses(const Vec3& p, const Vec3& q, const Vec3& a, const Vec3& b, const Vec3& c) {
  const int sp = side(a, b, c, p), sq = side(a, b, c, q);
  if (sp == 0 || sq == 0 || sp == sq) return false;
  const int s = side(p, q, a, b);
  return s != 0 && side(p, q, b, c) == s && side(p, q, c, a) == s;
}

}  // namespace

std::optional<std::pair<std::size_t, std::size_t>> self_intersection(const Mesh& mesh, const std::vector<Vec3>& X) {
  struct Triangle {
    std::array<int, 3> n;
    std::size_t element;
    Vec3 lo, hi;
  };
  std::vector<Triangle> tris;
  double largest = 0, sum = 0;
  for (std::size_t e = 0; e < mesh.elements.size(); ++e) {
    const auto& el = mesh.elements[e];
    for (const std::array<int, 3> n : {std::array<int, 3>{el[0], el[3], el[5]}, std::array<int, 3>{el[3], el[1], el[4]},
                                       std::array<int, 3>{el[5], el[4], el[2]}, std::array<int, 3>{el[3], el[4], el[5]}}) {
      Triangle t{n, e, X[n[0]], X[n[0]]};
      for (int v : n)
        for (int k = 0; k < 3; ++k) t.lo[k] = std::min(t.lo[k], X[v][k]), t.hi[k] = std::max(t.hi[k], X[v][k]);
      const double extent = std::max({t.hi[0] - t.lo[0], t.hi[1] - t.lo[1], t.hi[2] - t.lo[2]});
      largest = std::max(largest, extent);
      sum += extent;
      tris.push_back(t);
    }
  }
  if (tris.empty() || !(largest > 0)) return std::nullopt;
  // Cells twice a typical triangle's box, so that most triangles lie in 2 x 2 x 2 of them and the largest in at most
  // 17 x 17 x 17. A pair is tested in the cell holding the low corner of the intersection of their boxes only.
  const double cell = std::max(2 * sum / double(tris.size()), largest / 16);
  Vec3 origin = tris[0].lo;
  for (const auto& t : tris)
    for (int k = 0; k < 3; ++k) origin[k] = std::min(origin[k], t.lo[k]);
  const auto cell_of = [&](const Vec3& p) {
    std::array<long, 3> c{};
    for (int k = 0; k < 3; ++k) c[k] = static_cast<long>(std::floor((p[k] - origin[k]) / cell));
    return c;
  };
  const auto key = [](const std::array<long, 3>& c) { return (c[0] * 4096 + c[1]) * 4096 + c[2]; };
  std::vector<std::pair<long, std::size_t>> binned;
  for (std::size_t i = 0; i < tris.size(); ++i) {
    const auto a = cell_of(tris[i].lo), b = cell_of(tris[i].hi);
    for (long x = a[0]; x <= b[0]; ++x)
      for (long y = a[1]; y <= b[1]; ++y)
        for (long z = a[2]; z <= b[2]; ++z) binned.emplace_back(key({x, y, z}), i);
  }
  std::sort(binned.begin(), binned.end());
  std::optional<std::pair<std::size_t, std::size_t>> found;
  const auto cross_each_other = [&](const Triangle& s, const Triangle& t) {
    for (int i = 0; i < 3; ++i) {
      if (crosses(X[s.n[i]], X[s.n[(i + 1) % 3]], X[t.n[0]], X[t.n[1]], X[t.n[2]])) return true;
      if (crosses(X[t.n[i]], X[t.n[(i + 1) % 3]], X[s.n[0]], X[s.n[1]], X[s.n[2]])) return true;
    }
    return false;
  };
  for (std::size_t begin = 0; begin < binned.size();) {
    std::size_t end = begin;
    while (end < binned.size() && binned[end].first == binned[begin].first) ++end;
    for (std::size_t i = begin; i < end; ++i)
      for (std::size_t j = i + 1; j < end; ++j) {
        const Triangle &s = tris[binned[i].second], &t = tris[binned[j].second];
        if (s.element == t.element) continue;
        Vec3 lo;
        bool overlap = true;
        for (int k = 0; k < 3; ++k) {
          lo[k] = std::max(s.lo[k], t.lo[k]);
          overlap = overlap && lo[k] <= std::min(s.hi[k], t.hi[k]);
        }
        if (!overlap || key(cell_of(lo)) != binned[begin].first) continue;
        bool shared = false;
        for (int a : s.n) shared = shared || std::find(t.n.begin(), t.n.end(), a) != t.n.end();
        if (shared || !cross_each_other(s, t)) continue;
        const std::pair<std::size_t, std::size_t> pair = std::minmax(s.element, t.element);
        if (!found || pair < *found) found = pair;
      }
    begin = end;
  }
  return found;
}

}  // namespace immerse
