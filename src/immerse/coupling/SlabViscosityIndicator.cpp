#include "immerse/coupling/SlabViscosityIndicator.hpp"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <utility>

#include "immerse/coupling/ViscosityIndicator.hpp"
#include "immerse/fluid/MacStencil_K.hpp"
#include "immerse/membrane/VolumeAreaConstraint.hpp"

namespace immerse {

SlabViscosityIndicator::SlabViscosityIndicator(SlabIBCoupler& coupler, std::vector<double> ratio)
    : coupler_(coupler),
      slabs_(coupler.decomposition()),
      ratio_(std::move(ratio)),
      halo_(slabs_, Vec3{}, Vec3{}),
      local_(slabs_.grid()),
      work_(slabs_.make(Layout::Pressure)),
      solver_(std::make_unique<SlabFftHelmholtzSolver>(slabs_.grid(), Layout::Pressure, slabs_.communicator(),
                                                       slabs_.block())) {
  local_.n[2] = slabs_.local_shape(Layout::Pressure)[2];
  local_.periodic[2] = true;
  if (solver_->first_array_plane() != slabs_.cells().begin || solver_->local_planes() != slabs_.cells().count())
    throw std::logic_error("SlabViscosityIndicator: the Poisson solver's planes are not the decomposition's");
  for (int d = 0; d < 3; ++d) normals_[d] = slabs_.make(velocity_layout(d));
}

void SlabViscosityIndicator::compute(std::span<const OwnedIndicatorSurface> surfaces, Array3& chi) {
  const Grid& grid = slabs_.grid();
  const Communicator& comm = slabs_.communicator();
  if (chi.shape() != slabs_.local_shape(Layout::Pressure)) chi = slabs_.make(Layout::Pressure);
  // The bounds of the clipping and the floor, from every membrane's λ (known on every process), as in one process.
  double lower = 0, upper = 0, scale = 0;
  for (const double r : ratio_) {
    const double w = r - 1;
    if (w == 0) continue;
    lower = std::min(lower, w);
    upper = std::max(upper, w);
    scale = std::max(scale, std::abs(w));
  }
  target_ = 0;
  if (scale == 0) {
    std::fill(chi.values().begin(), chi.values().end(), 0.0);
    return;
  }
  X_.clear();
  N_.clear();
  std::vector<double> volumes;  // (global index, (λ − 1) V) of the owned contributing membranes
  for (const OwnedIndicatorSurface& s : surfaces) {
    const double w = ratio_.at(static_cast<std::size_t>(s.id)) - 1;
    if (w == 0) continue;
    const SurfaceGradients sg = surface_gradients(*s.elements, *s.X, false);
    volumes.insert(volumes.end(), {static_cast<double>(s.id), w * sg.volume});
    X_.insert(X_.end(), s.X->begin(), s.X->end());
    for (const Vec3& n : sg.d_volume) N_.push_back(w * n);
  }
  // The target added in global membrane order, as ViscosityIndicator adds it.
  const std::vector<double> all = comm.all_gather(volumes);
  std::vector<std::pair<int, double>> by_id;
  for (std::size_t q = 0; q + 1 < all.size(); q += 2) by_id.emplace_back(static_cast<int>(all[q]), all[q + 1]);
  std::ranges::sort(by_id);
  for (const auto& [id, v] : by_id) target_ += v;

  coupler_.spread_force(X_, N_, normals_);
  // The wall faces carry no G (∂χ/∂n = 0 at the walls); along z the halo's zero wall value stands for them.
  for (int d = 0; d < 2; ++d) {
    if (grid.periodic(d)) continue;
    Array3& G = normals_[d];
    for (int k = 0; k < G.nz(); ++k)
      for (int j = 0; j < G.ny(); ++j)
        for (int i = 0; i < G.nx(); ++i) {
          const int q = d == 0 ? i : j;
          if (q == 0 || q == grid.n(d)) G(i, j, k) = 0.0;
        }
  }
  const int off = slabs_.offset();
  if (!grid.periodic(2)) {
    Array3& G = normals_[2];
    for (const int wall : {0, grid.n(2)}) {
      const int k = wall - off;
      if (k < 0 || k >= G.nz()) continue;
      for (int j = 0; j < G.ny(); ++j)
        for (int i = 0; i < G.nx(); ++i) G(i, j, k) = 0.0;
    }
  }
  halo_.exchange(normals_[2], Layout::VelocityZ);  // D_h G reads G_z on the upper face of the highest owned cell
  const PlaneRange cells = slabs_.cells();
  const int k0 = cells.begin - off, k1 = cells.end - off;
  for (int k = k0; k < k1; ++k)
    for (int j = 0; j < grid.n(1); ++j)
      for (int i = 0; i < grid.n(0); ++i) work_(i, j, k) = -mac::divergence_cell(normals_, local_, {i, j, k});
  solver_->solve(work_, k0, 0.0, 1.0);
  // The free constant: Σ χ h³ = Σ_m (λ_m − 1) V_m, the sum over the cells of each process and then the processes.
  const double cell = grid.h() * grid.h() * grid.h();
  const std::size_t plane = static_cast<std::size_t>(grid.n(0)) * grid.n(1);
  const std::size_t first = work_.index(0, 0, k0), last = work_.index(0, 0, k1 - 1) + plane;
  double local_sum = 0;
  for (std::size_t q = first; q < last; ++q) local_sum += work_[q];
  const double sum = comm.sum(local_sum);
  const double total = static_cast<double>(grid.n(0)) * grid.n(1) * grid.n(2);
  const double shift = (target_ / cell - sum) / total;
  const double floor = ViscosityIndicator::kFloor * scale;
  for (std::size_t q = first; q < last; ++q) {
    const double x = std::clamp(work_[q] + shift, lower, upper);
    chi[q] = std::abs(x) < floor ? 0.0 : x;
  }
  halo_.exchange(chi, Layout::Pressure);
}

}  // namespace immerse
