#include "immerse/walls/WallGeometry.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numbers>

#include "immerse/core/Error.hpp"
#include "immerse/walls/WallSurface.hpp"

namespace immerse {

namespace {

std::string num_text(double x) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", x);
  return buf;
}

// The periodic lattice vectors Σ m_a L_a e_a with |m_a| ≤ reach over the periodic axes (m = 0 included).
template <class F>
void for_each_image(const std::array<bool, 3>& periodic, const Vec3& length, int reach, F&& f) {
  const int rx = periodic[0] ? reach : 0, ry = periodic[1] ? reach : 0, rz = periodic[2] ? reach : 0;
  for (int mz = -rz; mz <= rz; ++mz)
    for (int my = -ry; my <= ry; ++my)
      for (int mx = -rx; mx <= rx; ++mx) f(Vec3{mx * length.x, my * length.y, mz * length.z});
}

// b_s(r): the signed distance to the box |r_a| ≤ half_a over the axes it does not span, and its gradient.
double box_distance(const Vec3& r, const Vec3& half, const std::array<bool, 3>& span, Vec3& grad) {
  double out2 = 0, inner = -std::numeric_limits<double>::infinity();
  int lead = -1;
  Vec3 g{};
  for (int a = 0; a < 3; ++a) {
    if (span[a]) continue;
    const double q = std::abs(r[a]) - half[a];
    if (q > 0) {
      out2 += q * q;
      g[a] = r[a] >= 0 ? q : -q;
    }
    if (q > inner) {
      inner = q;
      lead = a;
    }
  }
  if (out2 > 0) {
    const double d = std::sqrt(out2);
    grad = g / d;
    return d;
  }
  grad = Vec3{};
  if (lead >= 0) grad[lead] = r[lead] >= 0 ? 1.0 : -1.0;
  return inner;
}

// The zero level set of f over the box [o, o + L] as triangles: marching tetrahedra on a lattice of about spacing h
// (six tetrahedra about each cube's main diagonal), the crossings linearly interpolated, each triangle facing f's
// positive side.
template <class F>
void level_set_triangles(F&& f, const Vec3& o, const Vec3& L, double h, std::vector<Vec3>& vertices,
                         std::vector<std::array<int, 3>>& triangles) {
  std::array<int, 3> n{};
  for (int a = 0; a < 3; ++a) n[a] = std::max(1, static_cast<int>(std::ceil(L[a] / h)));
  const auto node = [&](int i, int j, int k) {
    return o + Vec3{L.x * i / n[0], L.y * j / n[1], L.z * k / n[2]};
  };
  const auto at = [&](int i, int j, int k) {
    return (static_cast<std::size_t>(k) * (n[1] + 1) + j) * (n[0] + 1) + i;
  };
  std::vector<double> value(static_cast<std::size_t>(n[0] + 1) * (n[1] + 1) * (n[2] + 1));
  for (int k = 0; k <= n[2]; ++k)
    for (int j = 0; j <= n[1]; ++j)
      for (int i = 0; i <= n[0]; ++i) value[at(i, j, k)] = f(node(i, j, k));
  constexpr std::array<std::array<int, 3>, 6> orders{{{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}}};
  const auto emit = [&](const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& up) {
    const int base = static_cast<int>(vertices.size());
    vertices.push_back(a);
    const bool flip = dot(cross(b - a, c - a), up) < 0;
    vertices.push_back(flip ? c : b);
    vertices.push_back(flip ? b : c);
    triangles.push_back({base, base + 1, base + 2});
  };
  for (int k = 0; k < n[2]; ++k)
    for (int j = 0; j < n[1]; ++j)
      for (int i = 0; i < n[0]; ++i)
        for (const auto& ord : orders) {
          std::array<std::array<int, 3>, 4> c{};
          c[0] = {i, j, k};
          for (int v = 1; v < 4; ++v) {
            c[v] = c[v - 1];
            ++c[v][ord[v - 1]];
          }
          std::array<Vec3, 4> x;
          std::array<double, 4> phi;
          Vec3 pos{}, neg{};
          int below = 0;
          for (int v = 0; v < 4; ++v) {
            x[v] = node(c[v][0], c[v][1], c[v][2]);
            phi[v] = value[at(c[v][0], c[v][1], c[v][2])];
            if (phi[v] <= 0) {
              ++below;
              neg += x[v];
            } else {
              pos += x[v];
            }
          }
          if (below == 0 || below == 4) continue;
          const Vec3 up = pos / (4 - below) - neg / below;
          const auto cut = [&](int a, int b) { return x[a] + (phi[a] / (phi[a] - phi[b])) * (x[b] - x[a]); };
          std::array<int, 4> in{}, out{};
          int ni = 0, no = 0;
          for (int v = 0; v < 4; ++v) (phi[v] <= 0 ? in[ni++] : out[no++]) = v;
          if (ni == 1) {
            emit(cut(in[0], out[0]), cut(in[0], out[1]), cut(in[0], out[2]), up);
          } else if (ni == 3) {
            emit(cut(out[0], in[0]), cut(out[0], in[1]), cut(out[0], in[2]), up);
          } else {
            const Vec3 p0 = cut(in[0], out[0]), p1 = cut(in[0], out[1]), p2 = cut(in[1], out[1]),
                       p3 = cut(in[1], out[0]);
            emit(p0, p1, p2, up);
            emit(p0, p2, p3, up);
          }
        }
}

}  // namespace

WallGeometry::WallGeometry(std::vector<WallShape> shapes, const Grid& grid)
    : shapes_(std::move(shapes)), origin_(grid.origin()) {
  for (int a = 0; a < 3; ++a) {
    length_[a] = grid.length(a);
    periodic_[a] = grid.periodic(a);
  }
  for (int a = 0; a < 3; ++a)
    if (!periodic_[a])
      throw InputError(std::string("boundary.") + axis_name(a) +
                       " = \"wall\": [[wall]] needs a box periodic along every "
                       "axis (the [[wall]] shapes are the walls)");
  for (WallShape& s : shapes_) {
    if (s.kind == WallShape::Kind::Surface) {
      if (!s.surface) throw InputError(s.name + ".file: no surface given");
      const Vec3 lo = s.surface->lower(), hi = s.surface->upper();
      for (int a = 0; a < 3; ++a)
        if (hi[a] < origin_[a] || lo[a] > origin_[a] + length_[a])
          throw InputError(s.name + ": the surface (bounding box " + point_text(lo) + " to " + point_text(hi) +
                           ") lies outside the box " + point_text(origin_) + " to " + point_text(origin_ + length_) +
                           " (is the file in another unit? scale converts it to metres)");
      continue;
    }
    if (s.kind == WallShape::Kind::Box || s.kind == WallShape::Kind::Constriction) {
      check_block(s);
      continue;
    }
    if (!(s.radius > 0) || !std::isfinite(s.radius))
      throw InputError(s.name + ".radius = " + num_text(s.radius) + ": must be positive");
    if (!isfinite(s.center)) throw InputError(s.name + ".center = " + point_text(s.center) + ": must be finite");
    if (s.kind == WallShape::Kind::Sphere) {
      for (int a = 0; a < 3; ++a) {
        if (s.center[a] < origin_[a] || s.center[a] > origin_[a] + length_[a])
          throw InputError(s.name + ".center = " + point_text(s.center) + ": must lie in the box");
        if (periodic_[a] && 2 * s.radius >= length_[a])
          throw InputError(s.name + ".radius = " + num_text(s.radius) +
                           ": the sphere meets its periodic image (the "
                           "diameter must be below the box length " +
                           num_text(length_[a]) + " along " + axis_name(a) + ")");
      }
      continue;
    }
    if (!isfinite(s.axis) || norm(s.axis) == 0)
      throw InputError(s.name + ".axis = " + point_text(s.axis) + ": must be a non-zero direction");
    const Vec3 given = s.axis;
    s.axis = normalized(s.axis);
    for (int a = 0; a < 3; ++a)
      if (s.center[a] < origin_[a] || s.center[a] > origin_[a] + length_[a])
        throw InputError(s.name + ".center = " + point_text(s.center) + ": must lie in the box");
    // The axis returns onto itself after the lattice vector m_a L_a e_a (whole m_a, zero on a wall axis).
    bool closes = false;
    int lead = 0;
    for (int a = 1; a < 3; ++a)
      if (std::abs(s.axis[a]) / length_[a] > std::abs(s.axis[lead]) / length_[lead]) lead = a;
    for (int m = 1; m <= 16 && !closes; ++m) {
      const Vec3 v = s.axis * (m * length_[lead] / std::abs(s.axis[lead]));
      closes = true;
      for (int a = 0; a < 3; ++a) {
        const double ma = v[a] / length_[a];
        if (std::abs(ma - std::round(ma)) > 1e-6 * m || (!periodic_[a] && std::round(ma) != 0)) closes = false;
      }
      if (closes) s.period = norm(v);
    }
    if (!closes)
      throw InputError(s.name + ".axis = " + point_text(given) +
                       ": a tube must close on itself across the box (its axis "
                       "along (mx Lx, my Ly, mz Lz) with whole "
                       "numbers m up to 16)");
    double clearance = std::numeric_limits<double>::infinity();
    for_each_image(periodic_, length_, 2, [&](const Vec3& v) {
      const Vec3 perp = v - dot(v, s.axis) * s.axis;
      if (norm(perp) > 1e-9 * norm(length_)) clearance = std::min(clearance, norm(perp));
    });
    if (2 * s.radius >= clearance)
      throw InputError(s.name + ".radius = " + num_text(s.radius) +
                       ": the tube meets its periodic image (the diameter must be below " + num_text(clearance) +
                       ", the distance between the tube's axis and its nearest image)");
  }
}

void WallGeometry::check_block(WallShape& s) const {
  if (!isfinite(s.center)) throw InputError(s.name + ".center = " + point_text(s.center) + ": must be finite");
  for (int a = 0; a < 3; ++a)
    if (s.center[a] < origin_[a] || s.center[a] > origin_[a] + length_[a])
      throw InputError(s.name + ".center = " + point_text(s.center) + ": must lie in the box");
  const auto positive = [&](const Vec3& v, const std::string& key) {
    for (int a = 0; a < 3; ++a)
      if (!(v[a] > 0) || !std::isfinite(v[a]))
        throw InputError(s.name + "." + key + " = " + point_text(v) + ": every edge must be positive");
  };
  positive(s.size, "size");
  if (s.kind == WallShape::Kind::Box) {
    if (s.size.x >= length_.x && s.size.y >= length_.y && s.size.z >= length_.z)
      throw InputError(s.name + ".size = " + point_text(s.size) + ": the box spans the whole periodic box " +
                       point_text(length_) + (s.fluid_inside ? " (no wall is left)" : " (no fluid is left)") +
                       "; an edge must be below the box's length along at least one axis");
    return;
  }
  int t = -1;
  for (int a = 0; a < 3; ++a)
    if (std::abs(s.axis[a]) == 1.0 && s.axis[(a + 1) % 3] == 0 && s.axis[(a + 2) % 3] == 0) t = a;
  if (t < 0)
    throw InputError(s.name + ".axis = " + point_text(s.axis) +
                     ": a constriction's channel runs along a coordinate axis ([1, 0, 0], [0, 1, 0] or [0, 0, 1])");
  s.axis = Vec3{};
  s.axis[t] = 1.0;
  positive(s.throat, "throat");
  if (s.throat[t] >= length_[t])
    throw InputError(s.name + ".throat = " + point_text(s.throat) + ": the throat's length along " + axis_name(t) +
                     " must be below the box's " + num_text(length_[t]));
  bool narrower = false;
  for (int a = 0; a < 3; ++a)
    if (a != t) {
      if (s.throat[a] > s.size[a])
        throw InputError(s.name + ".throat = " + point_text(s.throat) + ": wider than the channel (size = " +
                         point_text(s.size) + ") along " + axis_name(a));
      narrower = narrower || (s.throat[a] < s.size[a] && s.throat[a] < length_[a]);
    }
  if (!narrower)
    throw InputError(s.name + ".throat = " + point_text(s.throat) +
                     ": must be narrower than the channel (size = " + point_text(s.size) + ") across at least one axis");
}

bool WallGeometry::invariant_along(int a) const {
  if (shapes_.empty()) return false;
  for (const WallShape& s : shapes_) {
    const bool tube = s.kind == WallShape::Kind::Tube && std::abs(s.axis[a]) == 1.0;
    const bool duct = s.kind == WallShape::Kind::Box && s.size[a] >= length_[a];
    if (!tube && !duct) return false;
  }
  return true;
}

double WallGeometry::block_distance(const WallShape& s, const Vec3& x, Vec3& grad) const {
  Vec3 r = x - s.center;
  for (int a = 0; a < 3; ++a) r[a] -= length_[a] * std::floor(r[a] / length_[a] + 0.5);
  std::array<bool, 3> span{};
  for (int a = 0; a < 3; ++a) span[a] = s.size[a] >= length_[a];
  if (s.kind == WallShape::Kind::Box) {
    const double b = box_distance(r, 0.5 * s.size, span, grad);
    if (!s.fluid_inside) return b;
    grad = -grad;
    return -b;
  }
  const int t = s.axis.x != 0 ? 0 : s.axis.y != 0 ? 1 : 2;
  span[t] = true;
  Vec3 g_channel, g_throat;
  const double channel = -box_distance(r, 0.5 * s.size, span, g_channel);
  std::array<bool, 3> throat_span{};
  throat_span[t] = true;
  for (int a = 0; a < 3; ++a)
    if (a != t) throat_span[a] = s.throat[a] >= length_[a];
  const double throat = -box_distance(r, 0.5 * s.throat, throat_span, g_throat);
  const double slab = std::abs(r[t]) - 0.5 * s.throat[t];
  // The throat's frame (the slab less the throat) is solid: φ_frame = max(slab, fluid-side distance of the throat).
  double frame;
  Vec3 g_frame{};
  if (slab >= throat) {
    frame = slab;
    g_frame[t] = r[t] >= 0 ? 1.0 : -1.0;
  } else {
    frame = throat;
    g_frame = -g_throat;
  }
  if (channel <= frame) {
    grad = -g_channel;
    return channel;
  }
  grad = g_frame;
  return frame;
}

double WallGeometry::shape_distance(const WallShape& s, const Vec3& x, Vec3& grad) const {
  if (s.kind == WallShape::Kind::Surface) return surface_distance(s, x, grad);
  if (s.kind == WallShape::Kind::Box || s.kind == WallShape::Kind::Constriction) return block_distance(s, x, grad);
  Vec3 r = x - s.center;
  for (int a = 0; a < 3; ++a)
    if (periodic_[a]) r[a] -= length_[a] * std::floor(r[a] / length_[a] + 0.5);
  const bool tube = s.kind == WallShape::Kind::Tube;
  double best = tube ? -std::numeric_limits<double>::infinity() : std::numeric_limits<double>::infinity();
  for_each_image(periodic_, length_, 1, [&](const Vec3& v) {
    const Vec3 q = r + v;
    if (tube) {
      const Vec3 perp = q - dot(q, s.axis) * s.axis;
      const double d = norm(perp),
                   phi = s.radius - d;  // fluid inside any image of the tube
      if (phi > best) {
        best = phi;
        grad = d > 0 ? perp * (-1.0 / d) : Vec3{};
      }
    } else {
      const double d = norm(q),
                   phi = d - s.radius;  // solid inside every image of the ball
      if (phi < best) {
        best = phi;
        grad = d > 0 ? q / d : Vec3{};
      }
    }
  });
  return best;
}

double WallGeometry::surface_distance(const WallShape& s, const Vec3& x, Vec3& grad) const {
  // The point shifted into the period about the surface's box centre, then by the 27 nearest lattice vectors; an image
  // whose bounding box is farther than the least signed distance so far cannot lower it.
  const WallSurface& S = *s.surface;
  const Vec3 lo = S.lower(), hi = S.upper(), mid = 0.5 * (lo + hi);
  Vec3 r = x - mid;
  for (int a = 0; a < 3; ++a)
    if (periodic_[a]) r[a] -= length_[a] * std::floor(r[a] / length_[a] + 0.5);
  std::array<std::pair<double, Vec3>, 27> images;
  int count = 0;
  for_each_image(periodic_, length_, 1, [&](const Vec3& v) {
    const Vec3 q = mid + r + v;
    double b2 = 0;
    for (int a = 0; a < 3; ++a) {
      const double e = std::max({lo[a] - q[a], 0.0, q[a] - hi[a]});
      b2 += e * e;
    }
    images[count++] = {std::sqrt(b2), q};
  });
  std::sort(images.begin(), images.begin() + count, [](const auto& a, const auto& b) { return a.first < b.first; });
  double best = std::numeric_limits<double>::infinity();
  Vec3 g;
  for (int i = 0; i < count; ++i) {
    if (images[i].first > 0 && images[i].first >= best) break;
    const double d = S.signed_distance(images[i].second, g);
    if (d < best) {
      best = d;
      grad = g;
    }
  }
  if (s.fluid_inside) {
    grad = -grad;
    return -best;
  }
  return best;
}

double WallGeometry::distance(const Vec3& x) const {
  double phi = std::numeric_limits<double>::infinity();
  Vec3 g;
  for (const WallShape& s : shapes_) phi = std::min(phi, shape_distance(s, x, g));
  return phi;
}

Vec3 WallGeometry::normal(const Vec3& x) const {
  double phi = std::numeric_limits<double>::infinity();
  Vec3 n{}, g;
  for (const WallShape& s : shapes_) {
    const double d = shape_distance(s, x, g);
    if (d < phi) {
      phi = d;
      n = g;
    }
  }
  return n;
}

void WallGeometry::triangulate(double h, std::vector<Vec3>& vertices, std::vector<std::array<int, 3>>& triangles,
                               std::vector<int>& shape_of) const {
  for (std::size_t k = 0; k < shapes_.size(); ++k) {
    const WallShape& s = shapes_[k];
    const int base = static_cast<int>(vertices.size());
    if (s.kind == WallShape::Kind::Surface) {
      for (const Vec3& v : s.surface->vertices()) vertices.push_back(v);
      for (const auto& t : s.surface->triangles()) triangles.push_back({base + t[0], base + t[1], base + t[2]});
      shape_of.resize(triangles.size(), static_cast<int>(k));
      continue;
    }
    if (s.kind == WallShape::Kind::Box || s.kind == WallShape::Kind::Constriction) {
      Vec3 g;
      level_set_triangles([&](const Vec3& x) { return block_distance(s, x, g); }, origin_, length_, h, vertices,
                          triangles);
      shape_of.resize(triangles.size(), static_cast<int>(k));
      continue;
    }
    // A grid of rings: (rows + 1) rings of `around` points.
    const int around = std::max(12, static_cast<int>(std::ceil(2 * std::numbers::pi * s.radius / h)));
    const bool tube = s.kind == WallShape::Kind::Tube;
    const int rows = tube ? std::max(1, static_cast<int>(std::ceil(s.period / h))) : std::max(6, around / 2);
    const Vec3 t = tube ? s.axis : Vec3{0, 0, 1};
    const Vec3 e1 = normalized(std::abs(t.x) < 0.9 ? cross(t, Vec3{1, 0, 0}) : cross(t, Vec3{0, 1, 0}));
    const Vec3 e2 = cross(t, e1);
    for (int r = 0; r <= rows; ++r)
      for (int j = 0; j < around; ++j) {
        const double phi = 2 * std::numbers::pi * j / around;
        if (tube) {
          vertices.push_back(s.center + (s.period * (static_cast<double>(r) / rows - 0.5)) * t +
                             s.radius * (std::cos(phi) * e1 + std::sin(phi) * e2));
        } else {
          const double theta = std::numbers::pi * r / rows;
          vertices.push_back(s.center + s.radius * (std::sin(theta) * (std::cos(phi) * e1 + std::sin(phi) * e2) +
                                                    std::cos(theta) * t));
        }
      }
    for (int r = 0; r < rows; ++r)
      for (int j = 0; j < around; ++j) {
        const int a = base + r * around + j, b = base + r * around + (j + 1) % around;
        triangles.push_back({a, b, a + around});
        triangles.push_back({b, b + around, a + around});
      }
    shape_of.resize(triangles.size(), static_cast<int>(k));
  }
}

double WallGeometry::fluid_volume(const Grid& grid) const {
  const double q = 0.5 * grid.h();
  std::size_t inside = 0;
  for (int k = 0; k < 2 * grid.n(2); ++k)
    for (int j = 0; j < 2 * grid.n(1); ++j)
      for (int i = 0; i < 2 * grid.n(0); ++i)
        inside += distance(grid.origin() + Vec3{(i + 0.5) * q, (j + 0.5) * q, (k + 0.5) * q}) > 0;
  return static_cast<double>(inside) * q * q * q;
}

}  // namespace immerse
