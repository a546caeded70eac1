#include "immerse/fluid/FftHelmholtzSolver.hpp"

#include <fftw3.h>
#include <omp.h>

#include <cmath>
#include <mutex>
#include <stdexcept>
#include <utility>

#include "immerse/fluid/FftAxis.hpp"
#include "immerse/fluid/MacStencilGrid.hpp"

namespace immerse {

namespace {

// FFTW's threading must be initialized once per process before any plan is made.
void init_fftw_threads() {
  static std::once_flag once;
  std::call_once(once, [] {
    fftw_init_threads();
    fftw_make_planner_thread_safe();
  });
}

}  // namespace

FftHelmholtzSolver::FftHelmholtzSolver(const Grid& grid, Layout layout, FftPlanning planning, Array3* in_place) : layout_(layout) {
  init_fftw_threads();
  std::array<fftw_r2r_kind, 3> fwd{}, bwd{};
  for (int a = 0; a < 3; ++a) {
    FftAxis axis = fft_axis(grid, layout, a);
    m_[a] = axis.count;
    lo_[a] = axis.first;
    fwd[a] = axis.forward;
    bwd[a] = axis.backward;
    normalization_ *= axis.normalization;
    lambda_[a] = std::move(axis.lambda);
  }
  const std::size_t total = static_cast<std::size_t>(m_[0]) * m_[1] * m_[2];
  threaded_ = static_cast<long>(total) >= MacStencilGrid::kMinCellsForThreads;
  const bool whole = lo_ == std::array<int, 3>{0, 0, 0};  // the unknowns are the whole array
  if (in_place && whole && in_place->nx() == m_[0] && in_place->ny() == m_[1] && in_place->nz() == m_[2]) {
    target_ = in_place;
    data_ = in_place->data();
  } else {
    buf_ = fftw_alloc_real(total);
    if (buf_ == nullptr) throw std::bad_alloc();
    data_ = buf_;
  }
  // Array3 is x fastest: in FFTW's row-major terms the dimensions are {z, y, x}.
  const int dims[3] = {m_[2], m_[1], m_[0]};
  const fftw_r2r_kind kf[3] = {fwd[2], fwd[1], fwd[0]}, kb[3] = {bwd[2], bwd[1], bwd[0]};
  const unsigned flags = planning == FftPlanning::Measure ? FFTW_MEASURE : FFTW_ESTIMATE;
  const int threads = threaded_ ? omp_get_max_threads() : 1;
  for (int t = 0; t < (threads > 1 ? 2 : 1); ++t) {
    fftw_plan_with_nthreads(t == 0 ? 1 : threads);
    forward_[t] = fftw_plan_r2r(3, dims, data_, data_, kf, flags);
    backward_[t] = fftw_plan_r2r(3, dims, data_, data_, kb, flags);
    if (forward_[t] == nullptr || backward_[t] == nullptr)
      throw std::runtime_error("FFTW could not plan a fast solver");
  }
}

FftHelmholtzSolver::~FftHelmholtzSolver() {
  for (int t = 0; t < 2; ++t) {
    if (forward_[t]) fftw_destroy_plan(forward_[t]);
    if (backward_[t]) fftw_destroy_plan(backward_[t]);
  }
  if (buf_) fftw_free(buf_);
}

int FftHelmholtzSolver::plan_index() const { return forward_[1] != nullptr && omp_get_max_threads() > 1 ? 1 : 0; }

void FftHelmholtzSolver::set_symbol(double alpha, double beta) {
  const int mx = m_[0], my = m_[1], mz = m_[2];
  const double* lx = lambda_[0].data();
  const double* ly = lambda_[1].data();
  const double* lz = lambda_[2].data();
  inverse_.resize(static_cast<std::size_t>(mx) * my * mz);
  tabulate_inverse_symbol(lx, ly, lz, mx, my, mz, alpha, beta, normalization_, inverse_.data(), threaded_);
  alpha_ = alpha;
  beta_ = beta;
}

void FftHelmholtzSolver::solve(Array3& x, double alpha, double beta) {
  const int mx = m_[0], my = m_[1], mz = m_[2];
  const int ox = lo_[0], oy = lo_[1], oz = lo_[2];
  double* const b = data_;
  if (target_ && &x != target_) throw std::logic_error("FftHelmholtzSolver::solve: this solver works in place on another array");
  if (!target_) {
#pragma omp parallel for collapse(2) schedule(static) if (threaded_)
    for (int k = 0; k < mz; ++k)
      for (int j = 0; j < my; ++j)
        for (int i = 0; i < mx; ++i) b[i + mx * (j + my * static_cast<std::size_t>(k))] = x(i + ox, j + oy, k + oz);
  }
  if (!(alpha == alpha_ && beta == beta_)) set_symbol(alpha, beta);
  const int t = plan_index();
  fftw_execute(forward_[t]);
  const double* const inv = inverse_.data();
  const long total = static_cast<long>(inverse_.size());
#pragma omp parallel for simd schedule(static) if (parallel : threaded_)
  for (long n = 0; n < total; ++n) b[n] *= inv[n];
  fftw_execute(backward_[t]);
  if (target_) return;
#pragma omp parallel for collapse(2) schedule(static) if (threaded_)
  for (int k = 0; k < mz; ++k)
    for (int j = 0; j < my; ++j)
      for (int i = 0; i < mx; ++i) x(i + ox, j + oy, k + oz) = b[i + mx * (j + my * static_cast<std::size_t>(k))];
}

void FftHelmholtzSolver::transform_round_trip() {
  const int t = plan_index();
  fftw_execute(forward_[t]);
  fftw_execute(backward_[t]);
}

}  // namespace immerse
