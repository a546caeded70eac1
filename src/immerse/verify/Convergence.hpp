#pragma once
// Observed order of convergence from errors on successively refined resolutions.
#include <cmath>
#include <vector>

namespace immerse::verify {

/// Order between two errors whose resolutions differ by `ratio` (e.g. 2 for h -> h/2).
inline double observed_order(double coarse_error, double fine_error, double ratio = 2.0) {
  return std::log(coarse_error / fine_error) / std::log(ratio);
}

/// Smallest order over consecutive pairs of a refinement sequence (coarsest first).
inline double min_observed_order(const std::vector<double>& errors, double ratio = 2.0) {
  double p = INFINITY;
  for (std::size_t i = 1; i < errors.size(); ++i) p = std::fmin(p, observed_order(errors[i - 1], errors[i], ratio));
  return p;
}

}  // namespace immerse::verify
