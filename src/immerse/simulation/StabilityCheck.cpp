#include "immerse/simulation/StabilityCheck.hpp"

#include <cmath>
#include <sstream>

namespace immerse {

namespace {

std::ostringstream message(const StepPlace& at) {
  std::ostringstream s;
  s.precision(10);
  s << "unstable at step " << at.step << ", t = " << at.time << ": ";
  return s;
}

}  // namespace

std::string node_instability(const StepPlace& at, std::size_t membrane, std::size_t node, const Vec3& x, const Vec3& u,
                             double max_speed) {
  const char* what = !isfinite(x)               ? "position is not finite"
                     : !isfinite(u)             ? "velocity is not finite"
                     : norm(u) > max_speed      ? "speed exceeds time.max_speed (runaway)"
                                                : nullptr;
  if (!what) return {};
  auto s = message(at);
  s << "membrane[" << membrane << "] node " << node << " " << what << " (|u| = " << norm(u) << " m/s, bound "
    << max_speed << ")";
  return s.str();
}

std::string fluid_instability(const StepPlace& at, const FluidState& f, const std::array<std::array<int, 2>, 4>& planes,
                              int plane_offset, double max_speed) {
  for (int l = 0; l < 4; ++l) {
    const bool velocity = l < 3;
    const Array3& a = velocity ? f.u[l] : f.p;
    const std::string symbol = velocity ? std::string("u_") + "xyz"[l] : "p";
    for (int k = planes[l][0]; k < planes[l][1]; ++k)
      for (int j = 0; j < a.ny(); ++j)
        for (int i = 0; i < a.nx(); ++i) {
          const double v = a(i, j, k);
          if (velocity ? std::abs(v) <= max_speed : std::isfinite(v)) continue;
          auto s = message(at);
          s << "fluid " << (velocity ? "velocity " + symbol + " at face" : std::string("pressure at cell")) << " ("
            << i << ", " << j << ", " << k + plane_offset << ") ";
          if (std::isfinite(v))
            s << "exceeds time.max_speed (runaway) (|" << symbol << "| = " << std::abs(v) << " m/s, bound " << max_speed
              << ")";
          else
            s << "is not finite";
          return s.str();
        }
  }
  return {};
}

}  // namespace immerse
