#include "immerse/contact/ContactForce.hpp"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "immerse/contact/MembraneClearance.hpp"
#include "immerse/core/Error.hpp"
#include "immerse/core/ThreadThresholds.hpp"
#include "immerse/walls/WallGeometry.hpp"

namespace immerse {

double small_strain_area_modulus(const MaterialLaw& law) {
  // tau ~ 2 K_s (lambda - 1) for small isotropic stretches; the central difference is within 1e-8 of it.
  const double dl = 1e-5;
  const MaterialLaw in_plane = without_area_dilation(law);
  return (isotropic_tension(in_plane, 1 + dl) - isotropic_tension(in_plane, 1 - dl)) / (4 * dl);
}

ContactForce::ContactForce(const Grid& grid, const ContactSettings& settings, const std::vector<std::size_t>& offsets,
                           std::vector<double> moduli)
    : grid_(grid),
      settings_(settings),
      eps_d_(settings.strength * settings.range),
      moduli_(std::move(moduli)),
      offsets_(offsets) {
  for (int k = 0; k < 3; ++k)
    if (grid_.periodic(k)) {
      std::ostringstream half;
      half << "below half the periodic box length (" << 0.5 * grid_.length(k) << " m)";
      require(settings_.range < 0.5 * grid_.length(k), "contact.range", settings_.range, half.str());
    }
  for (std::size_t m = 0; m + 1 < offsets.size(); ++m) membrane_of_.insert(membrane_of_.end(), offsets[m + 1] - offsets[m], m);
}

ContactForce::Bounds ContactForce::bounds(std::span<const Vec3> X) {
  Vec3 lo = X[0], hi = lo;
  for (const Vec3& x : X)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], x[k]), hi[k] = std::max(hi[k], x[k]);
  Bounds b;
  b.centre = 0.5 * (lo + hi);
  b.half = 0.5 * (hi - lo);
  for (const Vec3& x : X) b.radius = std::max(b.radius, norm(x - b.centre));
  return b;
}

bool ContactForce::boxes_within_range(const Grid& grid, double d, const Bounds& a, const Bounds& b) {
  bool overlap = norm(minimum_image(grid, a.centre, b.centre)) < a.radius + b.radius + d;
  for (int k = 0; k < 3 && overlap; ++k) {
    const double reach = a.half[k] + b.half[k] + d;
    double gap = a.centre[k] - b.centre[k];
    if (grid.periodic(k)) {
      const double L = grid.length(k);
      if (reach >= 0.5 * L) continue;  // the boxes may meet through either image
      gap -= L * std::round(gap / L);
    }
    overlap = std::abs(gap) < reach;
  }
  return overlap;
}

std::array<long, 3> ContactForce::bin_coords(const Vec3& p) const {
  std::array<long, 3> c{};
  for (int k = 0; k < 3; ++k) {
    double s = (p[k] - grid_.origin()[k]) / size_[k];
    if (grid_.periodic(k)) s -= double(nb_[k]) * std::floor(s / double(nb_[k]));
    c[k] = std::clamp(static_cast<long>(std::floor(s)), 0L, nb_[k] - 1);
  }
  return c;
}

void ContactForce::bin(std::span<const Vec3> X) {
  // Broad phase: nodes i of a and j of b within d by minimum image need |c_a - c_b| < s_a + s_b + d on every axis
  // (c the box centre, s its half-width, the difference wrapped into half a period when s_a + s_b + d is below it),
  // and |c_a - c_b| < R_a + R_b + d by minimum image (R the largest distance of a node from c).
  const std::size_t membranes = offsets_.size() - 1;
  std::vector<Bounds> box(membranes);
  for (std::size_t m = 0; m < membranes; ++m) box[m] = bounds(X.subspan(offsets_[m], offsets_[m + 1] - offsets_[m]));
  touching_.assign(membranes, 0);
  for (std::size_t a = 0; a < membranes; ++a)
    for (std::size_t b = a + 1; b < membranes; ++b)
      if (boxes_within_range(grid_, settings_.range, box[a], box[b])) touching_[a] = touching_[b] = 1;
  if (std::ranges::find(touching_, char{1}) == touching_.end()) return;  // no node has a neighbour: no bins needed
  // Bins of at least d; fewer (larger) ones where the box holds many more bins than nodes.
  const long limit = 27 + 8 * static_cast<long>(search_nodes_ > 0 ? search_nodes_ : X.size());
  for (int k = 0; k < 3; ++k) nb_[k] = std::max(1L, static_cast<long>(std::floor(grid_.length(k) / settings_.range)));
  while (nb_[0] * nb_[1] * nb_[2] > limit) {
    long& largest = *std::max_element(nb_.begin(), nb_.end());
    largest = std::max(1L, largest / 2);
  }
  for (int k = 0; k < 3; ++k) size_[k] = grid_.length(k) / double(nb_[k]);
  const auto bins = static_cast<std::size_t>(nb_[0] * nb_[1] * nb_[2]);
  node_bin_.resize(X.size());
  start_.assign(bins + 1, 0);
  for (std::size_t i = 0; i < X.size(); ++i) {
    if (!touching_[membrane_of_[i]]) continue;
    const auto c = bin_coords(X[i]);
    node_bin_[i] = static_cast<std::size_t>((c[2] * nb_[1] + c[1]) * nb_[0] + c[0]);
    ++start_[node_bin_[i] + 1];
  }
  for (std::size_t b = 0; b < bins; ++b) start_[b + 1] += start_[b];
  sorted_.resize(start_[bins]);
  next_.assign(start_.begin(), start_.end() - 1);
  for (std::size_t i = 0; i < X.size(); ++i)
    if (touching_[membrane_of_[i]]) sorted_[next_[node_bin_[i]]++] = i;
}

template <class F>
void ContactForce::for_each_neighbour(std::span<const Vec3> X, std::size_t i, F&& f) const {
  if (!touching_[membrane_of_[i]]) return;  // no other membrane within reach of its box
  const double d = settings_.range;
  const std::size_t b = node_bin_[i];
  const std::array<long, 3> c{static_cast<long>(b) % nb_[0], static_cast<long>(b) / nb_[0] % nb_[1],
                              static_cast<long>(b) / (nb_[0] * nb_[1])};
  // The bins next to c along each axis, each once (a periodic axis of one or two bins wraps onto itself).
  std::array<std::array<long, 3>, 3> near{};
  std::array<int, 3> count{};
  for (int k = 0; k < 3; ++k) {
    if (grid_.periodic(k) && nb_[k] < 3) {
      for (long n = 0; n < nb_[k]; ++n) near[k][count[k]++] = n;
      continue;
    }
    for (long n = c[k] - 1; n <= c[k] + 1; ++n) {
      const long w = grid_.periodic(k) ? (n + nb_[k]) % nb_[k] : n;
      if (w >= 0 && w < nb_[k]) near[k][count[k]++] = w;
    }
  }
  for (int z = 0; z < count[2]; ++z)
    for (int y = 0; y < count[1]; ++y)
      for (int x = 0; x < count[0]; ++x) {
        const auto nb = static_cast<std::size_t>((near[2][z] * nb_[1] + near[1][y]) * nb_[0] + near[0][x]);
        const auto first = sorted_.begin() + static_cast<std::ptrdiff_t>(start_[nb]),
                   last = sorted_.begin() + static_cast<std::ptrdiff_t>(start_[nb + 1]);
        // A bin lists its nodes in ascending order, so node i's own membrane is one run in it: skipped at once.
        const std::size_t a = membrane_of_[i];
        const auto own = std::lower_bound(first, last, offsets_[a]), after = std::lower_bound(own, last, offsets_[a + 1]);
        for (auto s = first; s != last; ++s) {
          if (s == own) s = after;
          if (s == last) break;
          const std::size_t j = *s;
          const Vec3 dx = minimum_image(grid_, X[i], X[j]);
          const double r = norm(dx);
          if (r < d) f(j, dx, r);
        }
      }
}

void ContactForce::compute(std::span<const Vec3> X, std::span<Vec3> F) {
  const bool pairs = offsets_.size() > 2;  // with one membrane only the walls act
  if (pairs) bin(X);
  const double d = settings_.range;
  const long n = static_cast<long>(X.size());
#pragma omp parallel for schedule(static) if (n >= kMinNodesForThreads)
  for (long l = 0; l < n; ++l) {
    const auto i = static_cast<std::size_t>(l);
    const std::size_t a = membrane_of_[i];
    Vec3 f{};
    if (pairs)
      for_each_neighbour(X, i, [&](std::size_t j, const Vec3& dx, double r) {
        // r > 0: two coincident nodes have no direction to push along.
        if (r > 0) f += (scale(a, membrane_of_[j]) * pair_force_shape(r, d) / r) * dx;
      });
    if (settings_.walls)
      for (int k = 0; k < 3; ++k) {
        if (grid_.periodic(k)) continue;
        const double lower = X[i][k] - grid_.origin()[k], upper = grid_.origin()[k] + grid_.length(k) - X[i][k];
        f[k] += scale(a, a) * (pair_force_shape(lower, d) - pair_force_shape(upper, d));
      }
    if (settings_.walls && settings_.shapes)
      if (const double s = settings_.shapes->distance(X[i]); s < d)
        f += (scale(a, a) * pair_force_shape(s, d)) * settings_.shapes->normal(X[i]);
    F[i] = f;
  }
}

double ContactForce::energy(std::span<const Vec3> X) {
  bin(X);
  const double d = settings_.range;
  const auto U = [&](double r) {
    const double t = std::max(0.0, 1 - r / d);
    return d * t * t * t / 3;  // U / (eps K d)
  };
  double E = 0;
  for (std::size_t i = 0; i < X.size(); ++i) {
    const std::size_t a = membrane_of_[i];
    // Each pair is seen from both nodes: half of it from each.
    for_each_neighbour(X, i, [&](std::size_t j, const Vec3&, double r) { E += 0.5 * scale(a, membrane_of_[j]) * U(r); });
    if (settings_.walls)
      for (int k = 0; k < 3; ++k)
        if (!grid_.periodic(k))
          E += scale(a, a) * (U(X[i][k] - grid_.origin()[k]) + U(grid_.origin()[k] + grid_.length(k) - X[i][k]));
    if (settings_.walls && settings_.shapes) E += scale(a, a) * U(settings_.shapes->distance(X[i]));
  }
  return E;
}

std::vector<std::vector<std::size_t>> ContactForce::neighbours(std::span<const Vec3> X) {
  bin(X);
  std::vector<std::vector<std::size_t>> out(X.size());
  for (std::size_t i = 0; i < X.size(); ++i) {
    for_each_neighbour(X, i, [&](std::size_t j, const Vec3&, double) { out[i].push_back(j); });
    std::ranges::sort(out[i]);
  }
  return out;
}

}  // namespace immerse
