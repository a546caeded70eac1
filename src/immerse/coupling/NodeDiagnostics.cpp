#include "immerse/coupling/NodeDiagnostics.hpp"

#include <cmath>
#include <limits>
#include <sstream>

#include "immerse/core/Error.hpp"
#include "immerse/core/ThreadThresholds.hpp"

namespace immerse {

namespace {

/// Empty string when node x is inside, else the reason.
std::string outside_reason(const Grid& g, const Vec3& x) {
  if (!isfinite(x)) return "non-finite position";
  for (int a = 0; a < 3; ++a) {
    if (g.periodic(a)) continue;
    const double lo = g.origin()[a], hi = lo + g.length(a);
    std::ostringstream s;
    s.precision(10);
    if (x[a] < lo) s << "beyond the wall " << axis_name(a) << " = " << lo;
    if (x[a] > hi) s << "beyond the wall " << axis_name(a) << " = " << hi;
    if (!s.str().empty()) return s.str();
  }
  return {};
}

}  // namespace

void check_nodes_in_domain(const Grid& grid, std::span<const Vec3> X) {
  const long n = static_cast<long>(X.size());
  std::array<double, 3> lo{}, hi{};
  for (int a = 0; a < 3; ++a) {
    lo[a] = grid.periodic(a) ? -INFINITY : grid.origin()[a];
    hi[a] = grid.periodic(a) ? INFINITY : grid.origin()[a] + grid.length(a);
  }
  long first_bad = n;
#pragma omp parallel for reduction(min : first_bad) if (n >= kMinNodesForThreads)
  for (long l = 0; l < n; ++l) {
    const Vec3& x = X[l];
    bool ok = isfinite(x);
    for (int a = 0; a < 3; ++a) ok = ok && x[a] >= lo[a] && x[a] <= hi[a];
    if (!ok && l < first_bad) first_bad = l;
  }
  if (first_bad == n) return;
  const Vec3& x = X[first_bad];
  std::ostringstream s;
  s.precision(10);
  s << "node " << first_bad << " at (" << x.x << ", " << x.y << ", " << x.z
    << ") is outside the fluid domain: " << outside_reason(grid, x);
  throw SimulationError(s.str());
}

double min_wall_distance(const Grid& grid, std::span<const Vec3> X) {
  check_nodes_in_domain(grid, X);
  const long n = static_cast<long>(X.size());
  double d = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (grid.periodic(a)) continue;
    const double lo = grid.origin()[a], hi = lo + grid.length(a);
#pragma omp parallel for reduction(min : d) if (n >= kMinNodesForThreads)
    for (long l = 0; l < n; ++l) d = std::fmin(d, std::fmin(X[l][a] - lo, hi - X[l][a]));
  }
  return d;
}

}  // namespace immerse
