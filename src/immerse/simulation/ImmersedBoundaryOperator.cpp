#include "immerse/simulation/ImmersedBoundaryOperator.hpp"

#include <omp.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <exception>
#include <limits>
#include <string>
#include <utility>

#include "immerse/core/Error.hpp"
#include "immerse/core/ThreadThresholds.hpp"
#include "immerse/coupling/NodeDiagnostics.hpp"
#include "immerse/fluid/MacStencilGrid.hpp"
#include "immerse/simulation/InversionReport.hpp"
#include "immerse/timestep/LogEvent.hpp"

namespace immerse {

namespace {

/// dst = src (resized), copied by the threads: the trial state's positions and velocities are saved at every
/// evaluation of the implicit residual.
template <class T>
void parallel_assign(std::span<const T> src, std::vector<T>& dst) {
  dst.resize(src.size());
  const long n = static_cast<long>(src.size());
  T* const d = dst.data();
  const T* const s = src.data();
#pragma omp parallel for schedule(static) if (long(sizeof(T) / sizeof(double)) * n >= kMinValuesForThreads)
  for (long i = 0; i < n; ++i) d[i] = s[i];
}

/// out = theta a + (1 - theta) b on every face (out sized on first use, on the grid g).
void blend(const Grid& g, double theta, const FaceField& a, const FaceField& b, FaceField& out) {
  if (out[0].size() == 0) out = FaceField(g);
  for (int d = 0; d < 3; ++d) {
    auto& o = out[d];
    const auto& x = a[d];
    const auto& y = b[d];
#pragma omp parallel for if (MacStencilGrid(g).threaded())
    for (std::size_t i = 0; i < o.size(); ++i) o[i] = theta * x[i] + (1.0 - theta) * y[i];
  }
}

}  // namespace

ImmersedBoundaryOperator::ImmersedBoundaryOperator(NavierStokesSolver& fluid, IBCoupler& coupler,
                                                   std::vector<const ElasticMembrane*> membranes,
                                                   std::vector<std::vector<Vec3>> X0, FluidState fluid_state,
                                                   const ContactSettings& contact, std::vector<double> viscosity_ratio)
    : fluid_(fluid),
      coupler_(coupler),
      membranes_(std::move(membranes)),
      committed_(std::move(fluid_state)),
      force_start_(fluid.grid()),
      force_(fluid.grid()) {
  if (X0.size() != membranes_.size()) throw std::logic_error("ImmersedBoundaryOperator: one position array per membrane");
  for (std::size_t m = 0; m < membranes_.size(); ++m) {
    if (X0[m].size() != membranes_[m]->num_nodes())
      throw InputError("membrane[" + std::to_string(m) + "]: " + std::to_string(X0[m].size()) +
                       " initial positions for a mesh of " + std::to_string(membranes_[m]->num_nodes()) + " nodes");
    offset_.push_back(X_.size());
    X_.insert(X_.end(), X0[m].begin(), X0[m].end());
    Fm_.emplace_back(X0[m].size());
  }
  offset_.push_back(X_.size());
  F_.resize(X_.size());
  U_.resize(X_.size());
  applied_.assign(X_.size(), Vec3{});
  if (contact.range > 0) {
    std::vector<double> moduli;
    for (const auto* m : membranes_) moduli.push_back(small_strain_area_modulus(m->law()));
    contact_.emplace(fluid_.grid(), contact, offset_, std::move(moduli));
    contact_F_.resize(X_.size());
  }
  if (std::ranges::any_of(viscosity_ratio, [](double r) { return r != 1.0; })) {
    if (viscosity_ratio.size() != membranes_.size())
      throw std::logic_error("ImmersedBoundaryOperator: one viscosity ratio per membrane");
    if (!fluid_.params().variable_viscosity)
      throw std::logic_error("ImmersedBoundaryOperator: a viscosity contrast needs a fluid solver with variable viscosity");
    ratio_ = std::move(viscosity_ratio);
    indicator_ = std::make_unique<ViscosityIndicator>(coupler_);
    for (std::size_t m = 0; m < membranes_.size(); ++m) Xmid_.emplace_back(X0[m].size());
  }
  membrane_force_density(X_, force_start_);
  coupler_.interpolate_velocity(committed_.u, X_, U_);
}

void ImmersedBoundaryOperator::update_indicator(std::span<const Vec3> Xf) {
  std::vector<IndicatorSurface> surfaces;
  for (std::size_t m = 0; m < membranes_.size(); ++m) {
    for (std::size_t i = 0; i < Xmid_[m].size(); ++i) Xmid_[m][i] = 0.5 * (X_[offset_[m] + i] + Xf[offset_[m] + i]);
    surfaces.push_back({&membranes_[m]->elements(), &Xmid_[m], ratio_[m]});
  }
  indicator_->compute(surfaces, chi_);
}

void ImmersedBoundaryOperator::nodal_force(std::size_t m, std::span<const Vec3> X) {
  const std::span<const Vec3> Xm = X.subspan(offset_[m], offset_[m + 1] - offset_[m]);
  try {
    check_nodes_in_domain(fluid_.grid(), Xm);
    membranes_[m]->compute_force(Xm, Fm_[m]);
  } catch (const SimulationError& e) {
    std::string details;
    if (const auto element = inverted_element(e.what())) {
      NearestMembrane nearest;
      const auto nodes = nodes_of_element(*membranes_[m], Xm, *element);
      for (std::size_t o = 0; o < membranes_.size(); ++o)
        if (o != m) nearest.consider(fluid_.grid(), nodes, X.subspan(offset_[o], offset_[o + 1] - offset_[o]), o);
      details = inversion_details(fluid_.grid(), *membranes_[m], Xm, *element, nearest);
    }
    throw SimulationError("membrane[" + std::to_string(m) + "] " + e.what() + details);
  }
  for (std::size_t i = 0; i < Fm_[m].size(); ++i) F_[offset_[m] + i] = Fm_[m][i] + applied_[offset_[m] + i];
}

// With many membranes each thread takes whole membranes (each evaluated with one thread: no barrier per pass,
// whatever OMP_MAX_ACTIVE_LEVELS says); with few, one membrane at a time with OpenMP inside ElasticMembrane. A
// membrane's forces do not depend on the thread count either way, and the error reported is that of the
// lowest-numbered failing membrane.
void ImmersedBoundaryOperator::membrane_force_density(std::span<const Vec3> X, FaceField& f) {
  const int M = static_cast<int>(membranes_.size());
  const bool across = omp_get_max_threads() > 1 && M >= 2 * omp_get_max_threads();
  std::vector<std::exception_ptr> error(membranes_.size());
  auto one = [&](int m) {
    try {
      nodal_force(static_cast<std::size_t>(m), X);
    } catch (...) {
      error[m] = std::current_exception();
    }
  };
  // No enclosing region when the membranes go one at a time: a region nested in an inactive one gets freshly
  // created threads in libgomp at every call (tens of microseconds each, once per pass of every force).
  timed(timings_.force, Phase::MembraneForces, [&] {
    if (across) {
#pragma omp parallel
      {
        omp_set_num_threads(1);  // for the regions nested in this thread's membranes
#pragma omp for schedule(dynamic)
        for (int m = 0; m < M; ++m) one(m);
      }
    } else {
      for (int m = 0; m < M; ++m) one(m);
    }
  });
  for (const auto& e : error)
    if (e) std::rethrow_exception(e);
  // After the membranes, which have checked that every node is finite and inside the box.
  if (contact_)
    timed(timings_.contact, Phase::Contact, [&] {
      contact_->compute(X, contact_F_);
      const long n = static_cast<long>(F_.size());
#pragma omp parallel for schedule(static) if (n >= kMinNodesForThreads)
      for (long i = 0; i < n; ++i) F_[static_cast<std::size_t>(i)] += contact_F_[static_cast<std::size_t>(i)];
    });
  timed(timings_.spread, Phase::Spreading, [&] { coupler_.spread_force(X, F_, f); });
}

template <class F>
void ImmersedBoundaryOperator::governed(F&& evaluation) {
  governor_.choose();
  const auto t0 = std::chrono::steady_clock::now();
  const double occasional = evaluation();
  governor_.record(std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count() - occasional);
}

double ImmersedBoundaryOperator::trial_step(std::span<const double> Xf, double theta, double dt) {
  trial_X_.clear();
  trial_U_valid_ = false;
  double occasional = 0;
  if (theta < 1.0 && !start_valid_) {
    timed(occasional, [&] { membrane_force_density(X_, force_start_); });
    start_valid_ = true;
  }
  membrane_force_density(nodes(Xf), force_);
  timed(timings_.fluid, Phase::FluidStep, [&] {
    if (theta < 1.0) blend(fluid_.grid(), theta, force_, force_start_, mixed_);
    if (!prepared_.prepared_for(committed_, dt)) timed(occasional, [&] { fluid_.prepare(committed_, dt, prepared_); });
    if (indicator_) update_indicator(nodes(Xf));
    fluid_.step(prepared_, theta < 1.0 ? mixed_ : force_, trial_, indicator_ ? &chi_ : nullptr);
  });
  ++solves_;
  return occasional;
}

void ImmersedBoundaryOperator::trial_velocity(std::span<const double> Xf, double theta, std::span<const double> Xi,
                                              double dt, std::span<double> U) {
  governed([&] {
    const double occasional = trial_step(Xf, theta, dt);
    timed(timings_.interpolate, Phase::Interpolation, [&] {
      coupler_.interpolate_velocity(trial_.u, nodes(Xi), {reinterpret_cast<Vec3*>(U.data()), U.size() / 3});
    });
    return occasional;
  });
  trial_U_valid_ = Xi.data() == Xf.data() && Xi.size() == Xf.size();
  if (trial_U_valid_) parallel_assign<Vec3>(nodes(U), trial_U_);
  parallel_assign(Xf, trial_X_);
}

void ImmersedBoundaryOperator::trial_mean_velocity(std::span<const double> Xf, std::span<const double> Xi, double dt,
                                                   std::span<double> U) {
  governed([&] {
    const double occasional = trial_step(Xf, 1.0, dt);
    timed(timings_.interpolate, Phase::Interpolation, [&] {
      blend(fluid_.grid(), 0.5, trial_.u, committed_.u, mean_);
      coupler_.interpolate_velocity(mean_, nodes(Xi), {reinterpret_cast<Vec3*>(U.data()), U.size() / 3});
    });
    return occasional;
  });
  parallel_assign(Xf, trial_X_);
}

void ImmersedBoundaryOperator::committed_velocity(std::span<const double> Xi, std::span<double> U) {
  timed(timings_.interpolate, Phase::Interpolation, [&] {
    coupler_.interpolate_velocity(committed_.u, nodes(Xi), {reinterpret_cast<Vec3*>(U.data()), U.size() / 3});
  });
}

void ImmersedBoundaryOperator::commit(std::span<const double> X, double) {
  std::swap(committed_, trial_);
  const auto Xn = nodes(X);
  std::copy(Xn.begin(), Xn.end(), X_.begin());
  // A trial interpolated at the positions that drove it, X^{n+1}, has J(X^{n+1}) u^{n+1} already.
  if (trial_U_valid_ && trial_matches(X))
    std::swap(U_, trial_U_);
  else
    timed(timings_.interpolate, Phase::Interpolation, [&] { coupler_.interpolate_velocity(committed_.u, X_, U_); });
  trial_U_valid_ = false;
  // An implicit step's last trial was driven by X^{n+1} itself: its S(X^{n+1}) f(X^{n+1}) is the next step's start.
  // Otherwise the start force is computed when a trial first needs it (never by the explicit schemes, theta = 1).
  start_valid_ = trial_matches(X);
  if (start_valid_) std::swap(force_start_, force_);
  trial_X_.clear();
}

std::vector<std::size_t> ImmersedBoundaryOperator::membrane_offsets() const {
  std::vector<std::size_t> o(offset_.size());
  std::ranges::transform(offset_, o.begin(), [](std::size_t node) { return 3 * node; });
  return o;
}

std::vector<Vec3> ImmersedBoundaryOperator::membrane_positions(std::size_t m) const {
  return {X_.begin() + static_cast<std::ptrdiff_t>(offset_[m]), X_.begin() + static_cast<std::ptrdiff_t>(offset_[m + 1])};
}

std::vector<Vec3> ImmersedBoundaryOperator::membrane_velocities(std::size_t m) const {
  return {U_.begin() + static_cast<std::ptrdiff_t>(offset_[m]), U_.begin() + static_cast<std::ptrdiff_t>(offset_[m + 1])};
}

void ImmersedBoundaryOperator::set_applied_forces(std::size_t m, const std::vector<Vec3>& F) {
  if (F.size() != offset_[m + 1] - offset_[m]) throw std::logic_error("set_applied_forces: one force per node");
  std::copy(F.begin(), F.end(), applied_.begin() + static_cast<std::ptrdiff_t>(offset_[m]));
  trial_X_.clear();
  start_valid_ = false;
}

void ImmersedBoundaryOperator::correct_positions(std::size_t m, const std::vector<Vec3>& X) {
  const std::size_t n = offset_[m + 1] - offset_[m];
  if (X.size() != n) throw std::logic_error("correct_positions: one position per node");
  std::copy(X.begin(), X.end(), X_.begin() + static_cast<std::ptrdiff_t>(offset_[m]));
  timed(timings_.interpolate, Phase::Interpolation, [&] {
    coupler_.interpolate_velocity(committed_.u, std::span<const Vec3>(X_).subspan(offset_[m], n),
                                  std::span<Vec3>(U_).subspan(offset_[m], n));
  });
  trial_X_.clear();
  trial_U_valid_ = false;
  start_valid_ = false;
}

double ImmersedBoundaryOperator::min_wall_distance() const { return immerse::min_wall_distance(fluid_.grid(), X_); }

}  // namespace immerse
