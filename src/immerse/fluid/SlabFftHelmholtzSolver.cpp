#include "immerse/fluid/SlabFftHelmholtzSolver.hpp"

#include <fftw3-mpi.h>

#include <cmath>
#include <cstddef>
#include <new>
#include <stdexcept>
#include <string>
#include <utility>

#include "immerse/fluid/FftAxis.hpp"

namespace immerse {

SlabFftHelmholtzSolver::SlabFftHelmholtzSolver(const Grid& grid, Layout layout, Communicator comm)
    : layout_(layout), comm_(comm) {
  plan(grid, 0, FftPlanning::Estimate);
}

SlabFftHelmholtzSolver::SlabFftHelmholtzSolver(const Grid& grid, Layout layout, Communicator comm, int block,
                                               FftPlanning planning)
    : layout_(layout), comm_(comm) {
  if (block < 1) throw std::invalid_argument("SlabFftHelmholtzSolver: the block of planes must be at least 1");
  plan(grid, block, planning);
}

void SlabFftHelmholtzSolver::plan(const Grid& grid, int block, FftPlanning planning) {
  shape_ = layout_ == Layout::Pressure ? grid.cell_shape() : grid.face_shape(static_cast<int>(layout_));
  std::array<fftw_r2r_kind, 3> fwd{}, bwd{};
  for (int a = 0; a < 3; ++a) {
    FftAxis axis = fft_axis(grid, layout_, a);
    m_[a] = axis.count;
    lo_[a] = axis.first;
    fwd[a] = axis.forward;
    bwd[a] = axis.backward;
    normalization_ *= axis.normalization;
    lambda_[a] = std::move(axis.lambda);
  }
  const int processes = comm_.size();
  if (block > 0 && static_cast<long>(block) * processes < m_[2])
    throw std::invalid_argument("SlabFftHelmholtzSolver: " + std::to_string(processes) + " blocks of " +
                                std::to_string(block) + " planes do not cover the " + std::to_string(m_[2]) +
                                " planes of unknowns along z");
  if (block == 0 && processes > m_[2])
    throw std::invalid_argument("SlabFftHelmholtzSolver: " + std::to_string(processes) + " processes for " +
                                std::to_string(m_[2]) +
                                " planes of unknowns along z (the slab axis): use at most one process per plane");
  // FFTW-MPI needs its own initialization (idempotent) and, for reproducible plans, one thread per process.
  fftw_init_threads();
  fftw_mpi_init();
  fftw_plan_with_nthreads(1);
  // Array3 is x fastest: in FFTW's row-major terms the dimensions are {z, y, x}, z distributed.
  ptrdiff_t local_n0 = 0, local_0_start = 0;
  const ptrdiff_t n[3] = {m_[2], m_[1], m_[0]};
  const ptrdiff_t b = block > 0 ? block : FFTW_MPI_DEFAULT_BLOCK;
  const ptrdiff_t alloc = fftw_mpi_local_size_many(3, n, 1, b, comm_.comm(), &local_n0, &local_0_start);
  local_planes_ = static_cast<int>(local_n0);
  first_plane_ = static_cast<int>(local_0_start);
  buf_ = fftw_alloc_real(static_cast<std::size_t>(alloc > 0 ? alloc : 1));
  if (buf_ == nullptr) throw std::bad_alloc();
  const fftw_r2r_kind fk[3] = {fwd[2], fwd[1], fwd[0]}, bk[3] = {bwd[2], bwd[1], bwd[0]};
  // Measuring overwrites buf_, which holds nothing yet.
  const unsigned flags = planning == FftPlanning::Measure ? FFTW_MEASURE : FFTW_ESTIMATE;
  forward_ = fftw_mpi_plan_many_r2r(3, n, 1, b, b, buf_, buf_, comm_.comm(), fk, flags);
  backward_ = fftw_mpi_plan_many_r2r(3, n, 1, b, b, buf_, buf_, comm_.comm(), bk, flags);
  if (forward_ == nullptr || backward_ == nullptr) {
    if (forward_) fftw_destroy_plan(forward_);
    if (backward_) fftw_destroy_plan(backward_);
    fftw_free(buf_);
    throw std::runtime_error("FFTW-MPI could not plan a distributed fast solver");
  }
}

SlabFftHelmholtzSolver::~SlabFftHelmholtzSolver() {
  fftw_destroy_plan(forward_);
  fftw_destroy_plan(backward_);
  fftw_free(buf_);
}

void SlabFftHelmholtzSolver::set_symbol(double alpha, double beta) {
  const int mx = m_[0], my = m_[1], nz = local_planes_;
  const double* lx = lambda_[0].data();
  const double* ly = lambda_[1].data();
  const double* lz = lambda_[2].data() + first_plane_;  // the global index of each local plane
  inverse_.resize(static_cast<std::size_t>(mx) * my * nz);
  tabulate_inverse_symbol(lx, ly, lz, mx, my, nz, alpha, beta, normalization_, inverse_.data(), false);
  alpha_ = alpha;
  beta_ = beta;
}

void SlabFftHelmholtzSolver::solve(Array3& x, double alpha, double beta) {
  if (x.nz() != local_planes_)
    throw std::logic_error("SlabFftHelmholtzSolver::solve: the array is not this process's slab (local_shape())");
  solve(x, 0, alpha, beta);
}

void SlabFftHelmholtzSolver::solve(Array3& x, int plane0, double alpha, double beta) {
  const int mx = m_[0], my = m_[1], nz = local_planes_;
  const int ox = lo_[0], oy = lo_[1];
  if (x.nx() != shape_[0] || x.ny() != shape_[1] || plane0 < 0 || x.nz() < plane0 + nz)
    throw std::logic_error("SlabFftHelmholtzSolver::solve: the array does not hold this process's planes");
  double* const b = buf_;
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < my; ++j)
      for (int i = 0; i < mx; ++i) b[i + mx * (j + my * static_cast<std::size_t>(k))] = x(i + ox, j + oy, k + plane0);
  if (!(alpha == alpha_ && beta == beta_)) set_symbol(alpha, beta);
  fftw_execute(forward_);
  const double* const inv = inverse_.data();
  const std::size_t total = inverse_.size();
  for (std::size_t n = 0; n < total; ++n) b[n] *= inv[n];
  fftw_execute(backward_);
  for (int k = 0; k < nz; ++k)
    for (int j = 0; j < my; ++j)
      for (int i = 0; i < mx; ++i) x(i + ox, j + oy, k + plane0) = b[i + mx * (j + my * static_cast<std::size_t>(k))];
}

}  // namespace immerse
