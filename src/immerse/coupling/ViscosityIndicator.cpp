#include "immerse/coupling/ViscosityIndicator.hpp"

#include <algorithm>
#include <array>
#include <cmath>

#include "immerse/fluid/MacStencilGrid.hpp"
#include "immerse/fluid/MacStencil_K.hpp"
#include "immerse/membrane/VolumeAreaConstraint.hpp"

namespace immerse {

ViscosityIndicator::ViscosityIndicator(IBCoupler& coupler, FftPlanning planning)
    : coupler_(coupler),
      work_(coupler.grid().n(0), coupler.grid().n(1), coupler.grid().n(2)),
      solver_(std::make_unique<FftHelmholtzSolver>(coupler.grid(), Layout::Pressure, planning, &work_)),
      normals_(coupler.grid()) {}

void ViscosityIndicator::compute(std::span<const IndicatorSurface> surfaces, Array3& chi) {
  const Grid& grid = coupler_.grid();
  if (chi.shape() != grid.cell_shape()) chi = Array3(grid.n(0), grid.n(1), grid.n(2));
  X_.clear();
  N_.clear();
  target_ = 0;
  double lower = 0, upper = 0, scale = 0;
  for (const IndicatorSurface& s : surfaces) {
    const double w = s.ratio - 1;
    if (w == 0) continue;
    const SurfaceGradients sg = surface_gradients(*s.elements, *s.X, false);
    target_ += w * sg.volume;
    lower = std::min(lower, w);
    upper = std::max(upper, w);
    scale = std::max(scale, std::abs(w));
    X_.insert(X_.end(), s.X->begin(), s.X->end());
    for (const Vec3& n : sg.d_volume) N_.push_back(w * n);
  }
  if (X_.empty()) {
    std::fill(chi.values().begin(), chi.values().end(), 0.0);
    return;
  }
  coupler_.spread_force(X_, N_, normals_);
  // ∇_h² χ = −D_h G with ∂χ/∂n = 0 at the walls: the wall faces carry no G (what the kernel spreads there is dropped),
  // so the Neumann problem is compatible, Σ D_h G = 0.
  const MacStencilGrid g(grid);
  for (int d = 0; d < 3; ++d) {
    if (g.periodic[d]) continue;
    Array3& G = normals_[d];
    const int e1 = (d + 1) % 3, e2 = (d + 2) % 3;
    for (const int wall : {0, g.n[d]}) {
      std::array<int, 3> q{};
      q[d] = wall;
      for (q[e2] = 0; q[e2] < G.n(e2); ++q[e2])
        for (q[e1] = 0; q[e1] < G.n(e1); ++q[e1]) G(q[0], q[1], q[2]) = 0.0;
    }
  }
  for_each_cell(g, [&](int i, int j, int k) { work_(i, j, k) = -mac::divergence_cell(normals_, g, {i, j, k}); });
  solver_->solve(work_, 0.0, 1.0);
  // The free constant: Σ χ h³ = Σ_m (λ_m − 1) V_m (a serial sum: the same in every thread count).
  const double cell = grid.h() * grid.h() * grid.h();
  const auto& v = work_.values();
  double sum = 0;
  for (const double x : v) sum += x;
  const double shift = (target_ / cell - sum) / static_cast<double>(v.size());
  const double floor = kFloor * scale;
  auto& out = chi.values();
  const long n = static_cast<long>(v.size());
#pragma omp parallel for schedule(static) if (g.threaded())
  for (long i = 0; i < n; ++i) {
    const double x = std::clamp(v[i] + shift, lower, upper);
    out[i] = std::abs(x) < floor ? 0.0 : x;
  }
}

}  // namespace immerse
