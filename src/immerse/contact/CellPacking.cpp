#include "immerse/contact/CellPacking.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

#include "immerse/contact/MembraneClearance.hpp"
#include "immerse/core/Error.hpp"
#include "immerse/walls/WallGeometry.hpp"

namespace immerse {
namespace {

constexpr double kSpacingShare = 1 / 1.2;  // nodes must lie closer than this times the clearance
constexpr double kStartFill = 0.2;         // bounding spheres at s0 fill at most this fraction of the box
constexpr double kTarget = 1.05;           // the relaxation pushes node pairs apart to this times the clearance
constexpr double kSkin = 0.6;              // the pair list holds pairs within (kTarget + kSkin) clearances
constexpr double kMaxStep = 0.2;           // largest node displacement per relaxation step, in clearances
constexpr double kGrowthMax = 0.02;        // largest size factor step (1 + g)
constexpr double kGrowthMin = 1e-4;        // the copies jam when a growth step this small cannot be relaxed
constexpr int kMaxIterations = 2000;       // relaxation steps at one size before the size steps back
constexpr long kMaxTotal = 20000;          // relaxation steps in all before the copies count as jammed
// FIRE (Bitzek et al. 2006): steps with P > 0 before dt grows; dt factors; mixing α and its decay.
constexpr int kFireDelay = 5;
constexpr double kFireGrow = 1.1, kFireShrink = 0.5, kFireAlpha = 0.1, kFireAlphaDecay = 0.99;
constexpr double kFireDt = 0.1, kFireDtMax = 1.0;

std::uint64_t splitmix64(std::uint64_t& x) {
  std::uint64_t z = (x += 0x9e3779b97f4a7c15ULL);
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}

class Xoshiro256 {
 public:
  explicit Xoshiro256(std::uint64_t seed) {
    for (auto& v : s_) v = splitmix64(seed);
  }
  std::uint64_t next() {
    const std::uint64_t result = rotl(s_[1] * 5, 7) * 9, t = s_[1] << 17;
    s_[2] ^= s_[0];
    s_[3] ^= s_[1];
    s_[1] ^= s_[2];
    s_[0] ^= s_[3];
    s_[2] ^= t;
    s_[3] = rotl(s_[3], 45);
    return result;
  }
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }  // [0, 1)

 private:
  static std::uint64_t rotl(std::uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  std::array<std::uint64_t, 4> s_{};
};

// Unit quaternion w + v (v = xi + yj + zk).
struct Quaternion {
  double w = 1;
  Vec3 v;
};

// A uniformly random unit quaternion, hence a uniformly random rotation (Shoemake 1992, Graphics Gems III).
Quaternion random_orientation(Xoshiro256& rng) {
  const double u1 = rng.uniform(), u2 = 2 * M_PI * rng.uniform(), u3 = 2 * M_PI * rng.uniform();
  const double a = std::sqrt(1 - u1), b = std::sqrt(u1);
  return {b * std::cos(u3), {a * std::sin(u2), a * std::cos(u2), b * std::sin(u3)}};
}

Mat3 rotation_of(const Quaternion& q) {
  const double w = q.w, x = q.v.x, y = q.v.y, z = q.v.z;
  Mat3 R;
  R(0, 0) = 1 - 2 * (y * y + z * z), R(0, 1) = 2 * (x * y - z * w), R(0, 2) = 2 * (x * z + y * w);
  R(1, 0) = 2 * (x * y + z * w), R(1, 1) = 1 - 2 * (x * x + z * z), R(1, 2) = 2 * (y * z - x * w);
  R(2, 0) = 2 * (x * z - y * w), R(2, 1) = 2 * (y * z + x * w), R(2, 2) = 1 - 2 * (x * x + y * y);
  return R;
}

// q turned further by the rotation vector theta (space frame): exp(theta / 2) q, renormalised.
Quaternion turned(const Quaternion& q, const Vec3& theta) {
  const double angle = norm(theta);
  if (angle == 0) return q;
  const double c = std::cos(angle / 2), s = std::sin(angle / 2) / angle;
  const Vec3 u = s * theta;
  Quaternion r{c * q.w - dot(u, q.v), c * q.v + q.w * u + cross(u, q.v)};
  const double len = std::sqrt(r.w * r.w + dot(r.v, r.v));
  r.w /= len;
  r.v /= len;
  return r;
}

std::string number(double v) {
  std::ostringstream s;
  s.precision(4);
  s << v;
  return s.str();
}

// The overdamped rigid-body relaxation of step 2 (see the header), at one size s of the copies.
class Relaxation {
 public:
  Relaxation(const Grid& grid, const WallGeometry* walls, const std::vector<Vec3>& shape, double clearance,
             std::vector<Vec3>& centre, std::vector<Quaternion>& orientation)
      : grid_(grid), walls_(walls), shape_(shape), c_(clearance), centre_(centre), orientation_(orientation), N_(centre.size()) {
    double sum = 0;
    for (const auto& p : shape) R_ = std::max(R_, norm(p)), sum += dot(p, p);
    mean_r2_ = sum / static_cast<double>(shape.size());
    X_.assign(N_, std::vector<Vec3>(shape.size()));
    arm_ = X_;
    moved_.assign(N_, 0.0);
  }

  /// Relaxation steps taken so far, at all sizes.
  long steps() const { return steps_; }

  /// Every node's largest move when the size changes from s to s_new (the pair list accounts for it).
  void resize(double s, double s_new) {
    for (auto& m : moved_) m += std::abs(s_new - s) * R_;
  }

  /// Relaxes at size s; true when no two nodes of different copies lie within the clearance and no node within it
  /// of a wall.
  bool relax(double s, const std::function<bool()>& stop_requested) {
    std::vector<Vec3> v(N_), u(N_), F(N_), G(N_);  // velocities, angular ones times sqrt(I); forces, torques / sqrt(I)
    const double sqrtI = s * std::sqrt(mean_r2_);  // scalar moment of inertia of a unit mass spread over the nodes
    double dt = kFireDt, alpha = kFireAlpha;
    int positive = 0;
    for (int iteration = 0; iteration < kMaxIterations; ++iteration, ++steps_) {
      if (stop_requested && stop_requested()) throw StopRequested("a stop was requested while packing the cells");
      positions(s);
      if (stale()) rebuild();
      if (forces(F, G, sqrtI)) return true;
      // FIRE: the power P = F·v; uphill steps stop the motion, downhill ones steer v towards F and lengthen dt.
      double P = 0, vv = 0, FF = 0;
      for (std::size_t i = 0; i < N_; ++i) {
        P += dot(F[i], v[i]) + dot(G[i], u[i]);
        vv += dot(v[i], v[i]) + dot(u[i], u[i]);
        FF += dot(F[i], F[i]) + dot(G[i], G[i]);
      }
      if (P > 0) {
        const double mix = FF > 0 ? alpha * std::sqrt(vv / FF) : 0;
        for (std::size_t i = 0; i < N_; ++i) {
          v[i] = (1 - alpha) * v[i] + mix * F[i];
          u[i] = (1 - alpha) * u[i] + mix * G[i];
        }
        if (++positive > kFireDelay) dt = std::min(dt * kFireGrow, kFireDtMax), alpha *= kFireAlphaDecay;
      } else {
        positive = 0;
        dt *= kFireShrink;
        alpha = kFireAlpha;
        std::fill(v.begin(), v.end(), Vec3{});
        std::fill(u.begin(), u.end(), Vec3{});
      }
      // Semi-implicit Euler with unit mass; each copy's nodes move at most kMaxStep clearances.
      for (std::size_t i = 0; i < N_; ++i) {
        v[i] += dt * F[i];
        u[i] += dt * G[i];
        Vec3 dx = dt * v[i], dtheta = (dt / sqrtI) * u[i];
        const double reach = norm(dx) + norm(dtheta) * s * R_;
        if (reach > kMaxStep * c_) {
          const double cut = kMaxStep * c_ / reach;
          dx *= cut, dtheta *= cut;
        }
        centre_[i] = wrap(centre_[i] + dx);
        orientation_[i] = turned(orientation_[i], dtheta);
        moved_[i] += std::min(reach, kMaxStep * c_);
      }
    }
    positions(s);
    if (stale()) rebuild();
    return forces(F, G, sqrtI);
  }

 private:
  Vec3 wrap(Vec3 x) const {
    for (int a = 0; a < 3; ++a)
      if (grid_.periodic(a)) {
        const double lo = grid_.origin()[a], L = grid_.length(a);
        x[a] = lo + std::fmod(std::fmod(x[a] - lo, L) + L, L);
      }
    return x;
  }

  void positions(double s) {
    for (std::size_t i = 0; i < N_; ++i) {
      const Mat3 R = rotation_of(orientation_[i]);
      for (std::size_t k = 0; k < shape_.size(); ++k) {
        arm_[i][k] = s * (R * shape_[k]);
        X_[i][k] = centre_[i] + arm_[i][k];
      }
    }
  }

  // A pair missing from the list was (kTarget + kSkin) clearances apart or more when it was built; it cannot come
  // within kTarget clearances before the two copies that moved most have moved kSkin clearances together.
  bool stale() const {
    if (!built_) return true;
    double first = 0, second = 0;
    for (double m : moved_)
      if (m > first) second = first, first = m;
      else second = std::max(second, m);
    return first + second > kSkin * c_;
  }

  void rebuild() {
    pairs_.clear();
    for_each_foreign_pair(grid_, X_, (kTarget + kSkin) * c_, [&](const NodePairGap& g) { pairs_.push_back(g); });
    std::fill(moved_.begin(), moved_.end(), 0.0);
    built_ = true;
  }

  // Pair forces (kTarget c - d) along the line of the two nodes, and wall forces (kTarget c - gap) along the wall's
  // normal, summed into forces and torques about the centres in a fixed order; true when all gaps are >= c.
  bool forces(std::vector<Vec3>& F, std::vector<Vec3>& G, double sqrtI) {
    std::fill(F.begin(), F.end(), Vec3{});
    std::vector<Vec3> T(N_);
    const double target = kTarget * c_;
    bool clear = true;
    for (const auto& p : pairs_) {
      const std::size_t a = p.membrane_a, b = p.membrane_b;
      Vec3 d = minimum_image(grid_, X_[a][p.node_a], X_[b][p.node_b]);
      const double len = norm(d);
      if (len >= target) continue;
      clear = clear && len >= c_;
      if (len > 0) d /= len;
      else d = normalized(minimum_image(grid_, centre_[a], centre_[b]) + Vec3{1e-12, 0, 0});
      const Vec3 f = (target - len) * d;
      F[a] += f, T[a] += cross(arm_[a][p.node_a], f);
      F[b] -= f, T[b] -= cross(arm_[b][p.node_b], f);
    }
    for (std::size_t i = 0; i < N_; ++i)
      for (int a = 0; a < 3; ++a) {
        if (grid_.periodic(a)) continue;
        const double lo = grid_.origin()[a], hi = lo + grid_.length(a);
        if (centre_[i][a] - lo > R_ + target && hi - centre_[i][a] > R_ + target) continue;
        for (std::size_t k = 0; k < shape_.size(); ++k) {
          const double x = X_[i][k][a];
          double push = 0;
          if (x - lo < target) push = target - (x - lo), clear = clear && x - lo >= c_;
          if (hi - x < target) push = -(target - (hi - x)), clear = clear && hi - x >= c_;
          if (push == 0) continue;
          Vec3 f;
          f[a] = push;
          F[i] += f, T[i] += cross(arm_[i][k], f);
        }
      }
    if (walls_)
      for (std::size_t i = 0; i < N_; ++i) {
        if (walls_->distance(centre_[i]) > R_ + target) continue;
        for (std::size_t k = 0; k < shape_.size(); ++k) {
          const double gap = walls_->distance(X_[i][k]);
          if (gap >= target) continue;
          clear = clear && gap >= c_;
          const Vec3 f = (target - gap) * walls_->normal(X_[i][k]);
          F[i] += f, T[i] += cross(arm_[i][k], f);
        }
      }
    for (std::size_t i = 0; i < N_; ++i) G[i] = T[i] / sqrtI;
    return clear;
  }

  const Grid& grid_;
  const WallGeometry* walls_;  // the [[wall]] shapes, or null
  const std::vector<Vec3>& shape_;
  const double c_;
  std::vector<Vec3>& centre_;
  std::vector<Quaternion>& orientation_;
  const std::size_t N_;
  double R_ = 0, mean_r2_ = 0;
  std::vector<std::vector<Vec3>> X_, arm_;  // node positions, and their offsets from the centres
  std::vector<NodePairGap> pairs_;
  std::vector<double> moved_;  // largest node displacement of each copy since the pair list was built
  bool built_ = false;
  long steps_ = 0;
};

}  // namespace

CellPacking::CellPacking(const Grid& grid, const std::vector<Vec3>& shape, double max_node_spacing,
                         const PackingRequest& request, const char* key) {
  const double c = request.clearance;
  const std::size_t N = request.count;
  if (max_node_spacing > kSpacingShare * c)
    throw InputError(std::string(key) + ": the template membrane's nodes lie up to " + number(max_node_spacing) +
                     " m apart; the test of the gaps between copies needs them closer than " +
                     number(kSpacingShare * c) + " m (raise membrane[0].mesh.level, or packing.clearance)");
  double R = 0;  // bounding radius of one copy at full size
  for (const auto& p : shape) R = std::max(R, norm(p));
  double box = 1;
  std::array<double, 3> lo{}, span{};
  for (int a = 0; a < 3; ++a) {
    box *= grid.length(a);
    lo[a] = grid.origin()[a];
    span[a] = grid.length(a);
  }
  // Start size: bounding spheres (with half the clearance) filling kStartFill of the box's fluid, each fitting
  // where the fluid is widest.
  if (request.walls) box = request.walls->fluid_volume(grid);
  const double r_start = std::cbrt(kStartFill * box / (4.0 / 3.0 * M_PI * static_cast<double>(N))) - c / 2;
  double s = std::min(1.0, r_start / R);
  if (request.walls) {
    double widest = 0;
    for (int k = 0; k < grid.n(2); ++k)
      for (int j = 0; j < grid.n(1); ++j)
        for (int i = 0; i < grid.n(0); ++i) widest = std::max(widest, request.walls->distance(grid.cell_position(i, j, k)));
    s = std::min(s, 0.9 * (widest - c) / R);
  }
  if (s < 0.05)
    throw InputError(std::string(key) + ": " + std::to_string(N) + " copies of the template membrane (bounding radius " +
                     number(R) + " m) cannot start small enough in this box with clearance " + number(c) + " m");

  Xoshiro256 rng(request.seed);
  std::vector<Quaternion> orientation(N);
  std::vector<Vec3> centre(N);
  // 1. Random sequential addition at size s, by bounding spheres.
  const auto place_range = [&](int a, double radius) {
    return grid.periodic(a) ? std::array<double, 2>{lo[a], lo[a] + span[a]}
                            : std::array<double, 2>{lo[a] + c + radius, lo[a] + span[a] - c - radius};
  };
  for (std::size_t i = 0; i < N; ++i) {
    orientation[i] = random_orientation(rng);
    bool placed = false;
    for (int attempt = 0; attempt < 100000 && !placed; ++attempt) {
      Vec3 p;
      for (int a = 0; a < 3; ++a) {
        const auto [from, to] = place_range(a, s * R);
        if (to <= from)
          throw InputError(std::string(key) + ": the box is too small along " + "xyz"[a] + " for one copy of the template membrane");
        p[a] = from + (to - from) * rng.uniform();
      }
      placed = (!request.walls || request.walls->distance(p) >= s * R + c) &&
               std::all_of(centre.begin(), centre.begin() + static_cast<long>(i),
                           [&](const Vec3& q) { return norm(minimum_image(grid, p, q)) >= 2 * s * R + c; });
      if (placed) centre[i] = p;
    }
    if (!placed)
      throw InputError(std::string(key) + ": could not place copy " + std::to_string(i) + " of " + std::to_string(N) +
                       " at the start size");
  }

  // 2. Grow and relax. A size that does not relax within kMaxIterations steps is stepped back to the last clear size
  // times 1 + g/2 (the copies keep their places) and the growth step g halves; the copies are jammed when g falls
  // below kGrowthMin or when a size fails after kMaxTotal steps in all.
  Relaxation relaxation(grid, request.walls.get(), shape, c, centre, orientation);
  double growth = std::min(kGrowthMax, kMaxStep * c / R), s_clear = s;  // a growth step moves nodes <= kMaxStep c
  while (true) {
    double next = 1;
    if (relaxation.relax(s, request.stop_requested)) {
      s_clear = s;
      if (s == 1.0) break;
      next = std::min(1.0, s * (1 + growth));
    } else {
      growth /= 2;
      if (growth < kGrowthMin || relaxation.steps() > kMaxTotal)
        throw InputError(std::string(key) + ": the copies jam at " + number(100 * s_clear) +
                         " % of their size (volume fraction reached: " + number(s_clear * s_clear * s_clear) +
                         " of the one asked for); ask for fewer cells, a larger box or a smaller packing.clearance");
      next = std::min(1.0, s_clear * (1 + growth));
    }
    relaxation.resize(s, next);
    s = next;
  }
  for (std::size_t i = 0; i < N; ++i) placements_.push_back({rotation_of(orientation[i]), centre[i]});
}

}  // namespace immerse
