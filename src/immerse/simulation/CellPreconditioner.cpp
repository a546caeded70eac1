#include "immerse/simulation/CellPreconditioner.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <utility>

namespace immerse {

namespace {

/// The 3×3 Rotne–Prager–Yamakawa block between blobs of radius a at separation d (Stokes, viscosity mu).
void rpy_block(const Vec3& d, double a, double mu, double out[3][3]) {
  const double r = norm(d);
  double s, t;  // out = s I + t r̂ r̂
  if (r >= 2 * a) {
    const double f = 1.0 / (8 * std::numbers::pi * mu * r);
    s = f * (1 + 2 * a * a / (3 * r * r));
    t = f * (1 - 2 * a * a / (r * r));
  } else {
    const double f = 1.0 / (6 * std::numbers::pi * mu * a);
    s = f * (1 - 9 * r / (32 * a));
    t = f * 3 * r / (32 * a);
  }
  const Vec3 e = r > 0 ? d / r : Vec3{0, 0, 0};
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j) out[i][j] = (i == j ? s : 0.0) + t * e[i] * e[j];
}

/// In-place LU factorization with partial pivoting of the n×n row-major matrix a.
void lu_factor(std::vector<double>& a, std::vector<int>& pivot, std::size_t n) {
  pivot.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    std::size_t p = k;
    for (std::size_t i = k + 1; i < n; ++i)
      if (std::abs(a[i * n + k]) > std::abs(a[p * n + k])) p = i;
    pivot[k] = static_cast<int>(p);
    if (p != k)
      for (std::size_t j = 0; j < n; ++j) std::swap(a[k * n + j], a[p * n + j]);
    const double d = a[k * n + k];
    if (d == 0) throw std::runtime_error("CellPreconditioner: singular coarse matrix");
    for (std::size_t i = k + 1; i < n; ++i) {
      const double l = a[i * n + k] /= d;
      double* ri = &a[i * n];
      const double* rk = &a[k * n];
      for (std::size_t j = k + 1; j < n; ++j) ri[j] -= l * rk[j];
    }
  }
}

void lu_solve(const std::vector<double>& a, const std::vector<int>& pivot, std::size_t n, std::vector<double>& b) {
  for (std::size_t k = 0; k < n; ++k) std::swap(b[k], b[static_cast<std::size_t>(pivot[k])]);
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = 0; j < i; ++j) b[i] -= a[i * n + j] * b[j];
  for (std::size_t i = n; i-- > 0;) {
    for (std::size_t j = i + 1; j < n; ++j) b[i] -= a[i * n + j] * b[j];
    b[i] /= a[i * n + i];
  }
}

}  // namespace

CellPreconditioner::CellPreconditioner(std::vector<Cell> cells, double mu, double radius)
    : cells_(std::move(cells)), mu_(mu), radius_(radius), factors_(cells_.size()) {
  // The restriction R = (PᵀP)⁻¹ Pᵀ: R P = I, and R v = 0 for v orthogonal to the interpolants.
  for (std::size_t m = 0; m < cells_.size(); ++m) {
    const CouplingPoints& P = cells_[m].points;
    const std::size_t nc = P.num_points();
    auto& g = factors_[m].gram;
    g.assign(nc * nc, 0.0);
    for (std::size_t i = 0; i < P.num_nodes(); ++i) {
      const auto cols = P.columns(i);
      const auto w = P.weights(i);
      for (std::size_t a = 0; a < cols.size(); ++a)
        for (std::size_t b = 0; b < cols.size(); ++b) g[cols[a] * nc + cols[b]] += w[a] * w[b];
    }
    lu_factor(g, factors_[m].gram_pivot, nc);
  }
}

void CellPreconditioner::prepare_cell(std::size_t m, std::span<const Vec3> X, double c) {
  const Cell& cell = cells_[m];
  const std::size_t nc = cell.points.num_points(), n = 3 * nc;
  std::vector<Vec3> Xc(nc), F0, F;
  cell.points.gather(X, Xc);
  // K_c = −∂f_c/∂X_c by forward differences of the coarse model's forces.
  Vec3 lo = Xc[0], hi = Xc[0];
  for (const Vec3& p : Xc)
    for (int k = 0; k < 3; ++k) lo[k] = std::min(lo[k], p[k]), hi[k] = std::max(hi[k], p[k]);
  const double eps = 1e-7 * norm(hi - lo);
  cell.coarse->compute_force(Xc, F0);
  std::vector<double> K(n * n);  // row-major, K[i * n + j]
  for (std::size_t j = 0; j < n; ++j) {
    const double keep = Xc[j / 3][static_cast<int>(j % 3)];
    Xc[j / 3][static_cast<int>(j % 3)] = keep + eps;
    cell.coarse->compute_force(Xc, F);
    Xc[j / 3][static_cast<int>(j % 3)] = keep;
    for (std::size_t i = 0; i < nc; ++i)
      for (int k = 0; k < 3; ++k) K[(3 * i + static_cast<std::size_t>(k)) * n + j] = -(F[i][k] - F0[i][k]) / eps;
  }
  // M_c, the RPY mobility of the points.
  std::vector<double> M(n * n);
  double b[3][3];
  for (std::size_t i = 0; i < nc; ++i)
    for (std::size_t j = 0; j < nc; ++j) {
      rpy_block(Xc[i] - Xc[j], radius_, mu_, b);
      for (int p = 0; p < 3; ++p)
        for (int q = 0; q < 3; ++q) M[(3 * i + static_cast<std::size_t>(p)) * n + 3 * j + static_cast<std::size_t>(q)] = b[p][q];
    }
  // A_c = I + c M_c K_c.
  Factor& f = factors_[m];
  f.lu.assign(n * n, 0.0);
  for (std::size_t i = 0; i < n; ++i) {
    double* row = &f.lu[i * n];
    for (std::size_t k = 0; k < n; ++k) {
      const double mik = c * M[i * n + k];
      const double* kr = &K[k * n];
      for (std::size_t j = 0; j < n; ++j) row[j] += mik * kr[j];
    }
    row[i] += 1.0;
  }
  lu_factor(f.lu, f.pivot, n);
}

void CellPreconditioner::prepare(std::span<const Vec3> X, std::span<const std::size_t> offsets, double c) {
  if (offsets.size() != cells_.size() + 1) throw std::logic_error("CellPreconditioner: one offset per cell");
  offsets_.assign(offsets.begin(), offsets.end());
  const long cells = static_cast<long>(cells_.size());
#pragma omp parallel for schedule(dynamic)
  for (long m = 0; m < cells; ++m) {
    const auto k = static_cast<std::size_t>(m);
    prepare_cell(k, X.subspan(offsets_[k], offsets_[k + 1] - offsets_[k]), c);
  }
}

void CellPreconditioner::apply(std::span<const Vec3> v, std::span<Vec3> z) {
  const long cells = static_cast<long>(cells_.size());
#pragma omp parallel for schedule(dynamic)
  for (long m = 0; m < cells; ++m) {
    const auto k = static_cast<std::size_t>(m);
    const Cell& cell = cells_[k];
    const std::size_t nc = cell.points.num_points(), n = 3 * nc, count = offsets_[k + 1] - offsets_[k];
    const auto vm = v.subspan(offsets_[k], count);
    const auto zm = z.subspan(offsets_[k], count);
    std::vector<Vec3> r(nc), d(nc);
    cell.points.restrict_forces(vm, r);  // Pᵀ v, then (PᵀP)⁻¹ per component
    std::vector<double> t(nc);
    for (int q = 0; q < 3; ++q) {
      for (std::size_t i = 0; i < nc; ++i) t[i] = r[i][q];
      lu_solve(factors_[k].gram, factors_[k].gram_pivot, nc, t);
      for (std::size_t i = 0; i < nc; ++i) r[i][q] = t[i];
    }
    std::vector<double> y(n);
    for (std::size_t i = 0; i < nc; ++i)
      for (int q = 0; q < 3; ++q) y[3 * i + static_cast<std::size_t>(q)] = r[i][q];
    lu_solve(factors_[k].lu, factors_[k].pivot, n, y);
    for (std::size_t i = 0; i < nc; ++i)
      for (int q = 0; q < 3; ++q) d[i][q] = y[3 * i + static_cast<std::size_t>(q)] - r[i][q];
    cell.points.prolong(d, zm);
    for (std::size_t i = 0; i < count; ++i) zm[i] += vm[i];
  }
}

}  // namespace immerse
