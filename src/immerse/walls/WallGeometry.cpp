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

double WallGeometry::shape_distance(const WallShape& s, const Vec3& x, Vec3& grad) const {
  if (s.kind == WallShape::Kind::Surface) return surface_distance(s, x, grad);
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
