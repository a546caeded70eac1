#include "immerse/simulation/CellPacking.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <sstream>

#include "immerse/core/Error.hpp"
#include "immerse/simulation/MembraneClearance.hpp"

namespace immerse {
namespace {

constexpr double kGrowth = 1.02;          // largest size factor per growth step
constexpr int kMaxSweeps = 100;           // pushes at one size before the packer gives up
constexpr double kStartFill = 0.2;        // bounding spheres at s0 fill at most this fraction of the box
constexpr double kSpacingShare = 1 / 1.2; // nodes must lie closer than this times the clearance

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

// A uniformly random rotation from a uniformly random unit quaternion (Shoemake 1992, Graphics Gems III).
Mat3 random_rotation(Xoshiro256& rng) {
  const double u1 = rng.uniform(), u2 = 2 * M_PI * rng.uniform(), u3 = 2 * M_PI * rng.uniform();
  const double a = std::sqrt(1 - u1), b = std::sqrt(u1);
  const double x = a * std::sin(u2), y = a * std::cos(u2), z = b * std::sin(u3), w = b * std::cos(u3);
  Mat3 R;
  R(0, 0) = 1 - 2 * (y * y + z * z), R(0, 1) = 2 * (x * y - z * w), R(0, 2) = 2 * (x * z + y * w);
  R(1, 0) = 2 * (x * y + z * w), R(1, 1) = 1 - 2 * (x * x + z * z), R(1, 2) = 2 * (y * z - x * w);
  R(2, 0) = 2 * (x * z - y * w), R(2, 1) = 2 * (y * z + x * w), R(2, 2) = 1 - 2 * (x * x + y * y);
  return R;
}

std::string number(double v) {
  std::ostringstream s;
  s.precision(4);
  s << v;
  return s.str();
}

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
  // Start size: bounding spheres (with half the clearance) filling kStartFill of the box.
  const double r_start = std::cbrt(kStartFill * box / (4.0 / 3.0 * M_PI * static_cast<double>(N))) - c / 2;
  double s = std::min(1.0, r_start / R);
  if (s < 0.05)
    throw InputError(std::string(key) + ": " + std::to_string(N) + " copies of the template membrane (bounding radius " +
                     number(R) + " m) cannot start small enough in this box with clearance " + number(c) + " m");

  Xoshiro256 rng(request.seed);
  std::vector<Mat3> rotation(N);
  std::vector<Vec3> centre(N);
  // 1. Random sequential addition at size s, by bounding spheres.
  const auto place_range = [&](int a, double radius) {
    return grid.periodic(a) ? std::array<double, 2>{lo[a], lo[a] + span[a]}
                            : std::array<double, 2>{lo[a] + c + radius, lo[a] + span[a] - c - radius};
  };
  for (std::size_t i = 0; i < N; ++i) {
    rotation[i] = random_rotation(rng);
    bool placed = false;
    for (int attempt = 0; attempt < 100000 && !placed; ++attempt) {
      Vec3 p;
      for (int a = 0; a < 3; ++a) {
        const auto [from, to] = place_range(a, s * R);
        if (to <= from)
          throw InputError(std::string(key) + ": the box is too small along " + "xyz"[a] + " for one copy of the template membrane");
        p[a] = from + (to - from) * rng.uniform();
      }
      placed = std::all_of(centre.begin(), centre.begin() + static_cast<long>(i),
                           [&](const Vec3& q) { return norm(minimum_image(grid, p, q)) >= 2 * s * R + c; });
      if (placed) centre[i] = p;
    }
    if (!placed)
      throw InputError(std::string(key) + ": could not place copy " + std::to_string(i) + " of " + std::to_string(N) +
                       " at the start size");
  }

  // 2. Grow and push apart; the close node pairs come from the cell list of MembraneClearance. The growth factor
  // adapts: halved when pushing apart takes many sweeps, doubled (up to kGrowth) when it takes few.
  std::vector<std::vector<Vec3>> turned(N), X(N);  // rotation[i] * shape, and the copies' nodes at size s
  for (std::size_t i = 0; i < N; ++i)
    for (const auto& p : shape) turned[i].push_back(rotation[i] * p);
  const auto wrap = [&](Vec3 x) {
    for (int a = 0; a < 3; ++a)
      if (grid.periodic(a)) x[a] = lo[a] + std::fmod(std::fmod(x[a] - lo[a], span[a]) + span[a], span[a]);
    return x;
  };
  const std::size_t n = shape.size();
  double growth = kGrowth - 1;
  while (true) {
    bool clear = false;
    int sweeps = 0;
    for (; sweeps < kMaxSweeps && !clear; ++sweeps) {
      for (std::size_t i = 0; i < N; ++i) {
        X[i].resize(n);
        for (std::size_t k = 0; k < n; ++k) X[i][k] = wrap(centre[i] + s * turned[i][k]);
      }
      std::map<std::pair<std::size_t, std::size_t>, double> depth;  // deepest node overlap of each pair of copies
      for_each_foreign_pair(grid, X, c, [&](const NodePairGap& g) {
        double& deepest = depth[{g.membrane_b, g.membrane_a}];
        deepest = std::max(deepest, c - g.distance);
      });
      std::vector<Vec3> push(N);
      for (const auto& [pair, d] : depth) {
        Vec3 dir = minimum_image(grid, centre[pair.second], centre[pair.first]);
        const double len = norm(dir);
        dir = len > 0 ? dir / len : Vec3{1, 0, 0};
        const double move = 0.5 * d + 0.01 * c;
        push[pair.first] -= move * dir;
        push[pair.second] += move * dir;
      }
      bool walls_clear = true;
      for (std::size_t i = 0; i < N; ++i)
        for (int a = 0; a < 3; ++a) {
          if (grid.periodic(a)) continue;
          double low = lo[a] + span[a], high = lo[a];
          for (const auto& x : X[i]) low = std::min(low, x[a]), high = std::max(high, x[a]);
          if (low < lo[a] + c) push[i][a] += lo[a] + c - low + 0.01 * c, walls_clear = false;
          if (high > lo[a] + span[a] - c) push[i][a] -= high - (lo[a] + span[a] - c) + 0.01 * c, walls_clear = false;
        }
      clear = depth.empty() && walls_clear;
      for (std::size_t i = 0; i < N; ++i) centre[i] = wrap(centre[i] + push[i]);
    }
    if (clear && s == 1.0) break;
    if (!clear || growth < 1e-3)
      throw InputError(std::string(key) + ": the copies jam at " + number(100 * s) +
                       " % of their size (volume fraction reached: " + number(s * s * s) +
                       " of the one asked for); ask for fewer cells, a larger box or a smaller packing.clearance");
    if (sweeps > 40) growth /= 2;
    if (sweeps < 8) growth = std::min(kGrowth - 1, 2 * growth);
    s = std::min(1.0, s * (1 + growth));
  }
  for (std::size_t i = 0; i < N; ++i) placements_.push_back({rotation[i], centre[i]});
}

}  // namespace immerse
