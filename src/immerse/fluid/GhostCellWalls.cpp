#include "immerse/fluid/GhostCellWalls.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <map>
#include <numbers>
#include <string>

#include "immerse/core/Error.hpp"
#include "immerse/fluid/FftHelmholtzSolver.hpp"

extern "C" {
// LAPACK (Fortran calling convention; the hidden length of the character argument last).
void dgetrf_(const int* m, const int* n, double* a, const int* lda, int* ipiv, int* info);
void dgetrs_(const char* trans, const int* n, const int* nrhs, const double* a, const int* lda, const int* ipiv,
             double* b, const int* ldb, int* info, std::size_t trans_length);
void zgetrf_(const int* m, const int* n, std::complex<double>* a, const int* lda, int* ipiv, int* info);
void zgetrs_(const char* trans, const int* n, const int* nrhs, const std::complex<double>* a, const int* lda,
             const int* ipiv, std::complex<double>* b, const int* ldb, int* info, std::size_t trans_length);
}

namespace immerse {

namespace {

struct LatticeIndex {
  std::array<int, 3> n;
  std::size_t flat(int i, int j, int k) const {
    const auto wrap = [](int q, int m) { return ((q % m) + m) % m; };
    return wrap(i, n[0]) +
           static_cast<std::size_t>(n[0]) * (wrap(j, n[1]) + static_cast<std::size_t>(n[1]) * wrap(k, n[2]));
  }
  std::array<int, 3> ijk(std::size_t f) const {
    const int i = static_cast<int>(f % n[0]);
    const std::size_t r = f / n[0];
    return {i, static_cast<int>(r % n[1]), static_cast<int>(r / n[1])};
  }
  /// The periodic 7-point ∇_h² of u at point f.
  double laplacian(const double* u, std::size_t f, double inv_h2) const {
    const auto [x, y, z] = ijk(f);
    return (u[flat(x - 1, y, z)] + u[flat(x + 1, y, z)] + u[flat(x, y - 1, z)] + u[flat(x, y + 1, z)] +
            u[flat(x, y, z - 1)] + u[flat(x, y, z + 1)] - 6.0 * u[f]) *
           inv_h2;
  }
};

}  // namespace

GhostCellWalls::GhostCellWalls(const Grid& grid, const WallGeometry& walls)
    : grid_(grid),
      alpha_(std::numeric_limits<double>::quiet_NaN()),
      beta_(alpha_),
      scratch_(grid.n(0), grid.n(1), grid.n(2)) {
  for (int a = 0; a < 3; ++a)
    if (!grid.periodic(a))
      throw InputError(std::string("boundary.") + axis_name(a) +
                       " = \"wall\": [[wall]] needs a box periodic along every "
                       "axis (the [[wall]] shapes are the walls)");
  const LatticeIndex L{grid.n()};
  const double h = grid.h();
  const std::size_t count = static_cast<std::size_t>(grid.n(0)) * grid.n(1) * grid.n(2);
  // Walls invariant along an axis (tubes along it, boxes spanning it): the rows of one plane normal to it, repeated
  // plane by plane.
  for (int a = 0; a < 3 && axis_ < 0; ++a)
    if (walls.invariant_along(a)) axis_ = a;
  const auto plane_of = [&](std::size_t f) { return axis_ < 0 ? 0 : L.ijk(f)[axis_]; };
  const auto shifted = [&](std::size_t f, int s) {
    std::array<int, 3> q = L.ijk(f);
    q[axis_] += s;
    return L.flat(q[0], q[1], q[2]);
  };
  planes_ = axis_ < 0 ? 1 : grid.n(axis_);
  for (int d = 0; d < 3; ++d) {
    Component& c = comp_[d];
    c.fluid.assign(count, 0);
    for (int k = 0; k < grid.n(2); ++k)
      for (int j = 0; j < grid.n(1); ++j)
        for (int i = 0; i < grid.n(0); ++i) {
          std::array<int, 3> q{i, j, k};
          if (axis_ >= 0) q[axis_] = 0;
          c.fluid[L.flat(i, j, k)] = walls.distance(grid.face_position(d, q[0], q[1], q[2])) > 0;
        }
    c.row_start.push_back(0);
    for (std::size_t f = 0; f < count; ++f) {
      if (!c.fluid[f]) {
        c.solid.push_back(f);
        continue;
      }
      if (plane_of(f) != 0) continue;  // (invariant walls: repeated below)
      const auto [i, j, k] = L.ijk(f);
      const std::array<int, 3> q{i, j, k};
      const Vec3 x = grid.face_position(d, i, j, k);
      // Shortley–Weller: per axis, the arms to the neighbours or to the wall crossing in between (value 0).
      std::map<std::size_t, double> row;
      double diag = 0;
      bool cut = false;
      for (int a = 0; a < 3; ++a) {
        std::array<double, 2> arm{h, h};
        std::array<std::size_t, 2> nb{};
        for (int side = 0; side < 2; ++side) {
          std::array<int, 3> qn = q;
          qn[a] += side ? 1 : -1;
          nb[side] = L.flat(qn[0], qn[1], qn[2]);
          if (c.fluid[nb[side]]) continue;
          cut = true;
          Vec3 e{};
          e[a] = side ? h : -h;
          double lo = 0, hi = 1;  // φ(x + lo e) > 0 ≥ φ(x + hi e)
          for (int it = 0; it < 50; ++it) {
            const double mid = 0.5 * (lo + hi);
            (walls.distance(x + mid * e) > 0 ? lo : hi) = mid;
          }
          arm[side] = std::max(0.5 * (lo + hi), 1e-6) * h;
        }
        const double hl = arm[0], hr = arm[1];
        diag -= 2.0 / (hl * hr);
        if (c.fluid[nb[0]]) row[nb[0]] += 2.0 / (hl * (hl + hr));
        if (c.fluid[nb[1]]) row[nb[1]] += 2.0 / (hr * (hl + hr));
      }
      if (!cut) continue;
      row[f] += diag;  // the Laplacian's row; factorization() and solve() take α + β times it
      c.cut.push_back(f);
      for (const auto& [col, v] : row) {
        c.col.push_back(col);
        c.val.push_back(v);
        c.diag.push_back(col == f);
      }
      c.row_start.push_back(c.col.size());
    }
    // Invariant walls: plane s holds the rows of plane 0 shifted by s (cut point s·n_ring + i).
    const std::size_t ring = c.cut.size();
    for (int s = 1; s < planes_; ++s)
      for (std::size_t i = 0; i < ring; ++i) {
        c.cut.push_back(shifted(c.cut[i], s));
        for (std::size_t e = c.row_start[i]; e < c.row_start[i + 1]; ++e) {
          c.col.push_back(shifted(c.col[e], s));
          c.val.push_back(c.val[e]);
          c.diag.push_back(c.diag[e]);
        }
        c.row_start.push_back(c.col.size());
      }
  }
}

const GhostCellWalls::Factorization& GhostCellWalls::factorization(double alpha, double beta, Array3& x,
                                                                    FftHelmholtzSolver& fast) {
  ++uses_;
  alpha_ = alpha;
  beta_ = beta;
  for (Factorization& f : factors_)
    if (f.alpha == alpha && f.beta == beta) {
      f.used = uses_;
      return f;
    }
  // Keep up to 8 step sizes (the trials of an adaptive or halved step, a cycle of steps), within 1 GB.
  std::size_t bytes = 0;
  for (const Component& c : comp_) {
    const std::size_t ring = c.cut.size() / planes_;
    bytes += axis_ < 0 ? c.cut.size() * c.cut.size() * sizeof(double)
                       : planes_ * ring * ring * sizeof(std::complex<double>);
  }
  const std::size_t keep = std::clamp<std::size_t>(bytes > 0 ? (std::size_t{1} << 30) / bytes : 8, 1, 8);
  if (factors_.size() >= keep) {
    const auto oldest = std::min_element(factors_.begin(), factors_.end(),
                                         [](const Factorization& a, const Factorization& b) { return a.used < b.used; });
    factors_.erase(oldest);
  }
  Factorization& fac = factors_.emplace_back();
  fac.alpha = alpha;
  fac.beta = beta;
  fac.used = uses_;
  scratch_.values() = x.values();
  std::fill(x.values().begin(), x.values().end(), 0.0);
  x(0, 0, 0) = 1.0;
  fast.solve(x, alpha, beta);
  const std::vector<double> green = x.values();
  x.values() = scratch_.values();
  const LatticeIndex L{grid_.n()};
  for (int d = 0; d < 3; ++d) {
    const Component& c = comp_[d];
    std::vector<std::array<int, 3>> at(c.col.size());
    std::vector<double> a(c.col.size());
    for (std::size_t e = 0; e < c.col.size(); ++e) {
      at[e] = L.ijk(c.col[e]);
      a[e] = beta * c.val[e] + (c.diag[e] ? alpha : 0.0);
    }
    // C_ij = Σ_e a_ie G(q_e − q_j) for the rows `rows` and the columns `cols` (column-major, rows fastest).
    const auto fill = [&](std::size_t row0, int rows, std::size_t col0, int cols, double* out) {
#pragma omp parallel for schedule(static)
      for (int j = 0; j < cols; ++j) {
        const std::array<int, 3> qj = L.ijk(c.cut[col0 + j]);
        for (int i = 0; i < rows; ++i) {
          double sum = 0;
          for (std::size_t e = c.row_start[row0 + i]; e < c.row_start[row0 + i + 1]; ++e)
            sum += a[e] * green[L.flat(at[e][0] - qj[0], at[e][1] - qj[1], at[e][2] - qj[2])];
          out[static_cast<std::size_t>(j) * rows + i] = sum;
        }
      }
    };
    int info = 0;
    if (axis_ < 0) {
      const int n = static_cast<int>(c.cut.size());
      std::vector<double>& lu = fac.lu[d];
      lu.assign(static_cast<std::size_t>(n) * n, 0.0);
      fac.pivot[d].assign(n, 0);
      if (n == 0) continue;
      fill(0, n, 0, n, lu.data());
      dgetrf_(&n, &n, lu.data(), &n, fac.pivot[d].data(), &info);
    } else {
      // Block circulant: C_(s,i),(s',j) = c_ij(s − s'); the DFT along the axis turns it into the blocks
      // Ĉ_m = Σ_δ c(δ) ω^(−mδ), ω = e^(2πi/P), one n_ring × n_ring system per wavenumber m.
      const int n = static_cast<int>(c.cut.size() / planes_), P = planes_;
      const std::size_t block = static_cast<std::size_t>(n) * n;
      fac.blocks[d].assign(P * block, 0.0);
      fac.pivot[d].assign(static_cast<std::size_t>(P) * n, 0);
      if (n == 0) continue;
      std::vector<double> cd(P * block);
      for (int delta = 0; delta < P; ++delta) fill(static_cast<std::size_t>(delta) * n, n, 0, n, cd.data() + delta * block);
      for (int m = 0; m < P; ++m) {
        std::complex<double>* const b = fac.blocks[d].data() + m * block;
        for (int delta = 0; delta < P; ++delta) {
          const double angle = -2 * std::numbers::pi * static_cast<double>((m * delta) % P) / P;
          const std::complex<double> w(std::cos(angle), std::sin(angle));
          const double* const cdd = cd.data() + delta * block;
          for (std::size_t q = 0; q < block; ++q) b[q] += cdd[q] * w;
        }
        zgetrf_(&n, &n, b, &n, fac.pivot[d].data() + static_cast<std::size_t>(m) * n, &info);
        if (info != 0) break;
      }
    }
    if (info != 0)
      throw SimulationError("GhostCellWalls: the capacitance matrix of velocity component " + std::to_string(d) +
                            " is singular (LAPACK info " + std::to_string(info) + ")");
  }
  return fac;
}

void GhostCellWalls::block_solve(const Factorization& fac, int d) {
  const int P = planes_, n = static_cast<int>(comp_[d].cut.size()) / planes_, one = 1;
  const std::size_t block = static_cast<std::size_t>(n) * n;
  std::vector<std::complex<double>> hat(static_cast<std::size_t>(P) * n, 0.0);
  std::vector<std::complex<double>> w(P);  // ω^(−k), k = 0 … P − 1
  for (int k = 0; k < P; ++k) {
    const double angle = -2 * std::numbers::pi * k / P;
    w[k] = {std::cos(angle), std::sin(angle)};
  }
  for (int m = 0; m < P; ++m) {
    std::complex<double>* const h = hat.data() + static_cast<std::size_t>(m) * n;
    for (int s = 0; s < P; ++s) {
      const std::complex<double> ws = w[(m * s) % P];
      const double* const r = rhs_.data() + static_cast<std::size_t>(s) * n;
      for (int i = 0; i < n; ++i) h[i] += r[i] * ws;
    }
    int info = 0;
    zgetrs_("N", &n, &one, fac.blocks[d].data() + m * block, &n, fac.pivot[d].data() + static_cast<std::size_t>(m) * n, h,
            &n, &info, 1);
  }
  for (int s = 0; s < P; ++s) {
    double* const y = rhs_.data() + static_cast<std::size_t>(s) * n;
    for (int i = 0; i < n; ++i) y[i] = 0;
    for (int m = 0; m < P; ++m) {
      const std::complex<double> ws = std::conj(w[(m * s) % P]);
      const std::complex<double>* const h = hat.data() + static_cast<std::size_t>(m) * n;
      for (int i = 0; i < n; ++i) y[i] += (h[i] * ws).real();
    }
    for (int i = 0; i < n; ++i) y[i] /= P;
  }
}

double GhostCellWalls::row_times(const Component& c, std::size_t i, const double* u) const {
  double sum = 0;
  for (std::size_t e = c.row_start[i]; e < c.row_start[i + 1]; ++e)
    sum += (beta_ * c.val[e] + (c.diag[e] ? alpha_ : 0.0)) * u[c.col[e]];
  return sum;
}

void GhostCellWalls::solve(int d, Array3& x, double alpha, double beta, FftHelmholtzSolver& fast) {
  const Factorization& fac = factorization(alpha, beta, x, fast);
  const Component& c = comp_[d];
  double* const u = x.data();
  const int n = static_cast<int>(c.cut.size());
  rhs_.resize(n);
  for (int i = 0; i < n; ++i) rhs_[i] = u[c.cut[i]];  // b at the cut rows
  for (const std::size_t f : c.solid) u[f] = 0.0;
  fast.solve(x, alpha, beta);  // v = H⁻¹ b
  if (n == 0) {
    for (const std::size_t f : c.solid) u[f] = 0.0;
    return;
  }
  for (int i = 0; i < n; ++i) rhs_[i] = row_times(c, i, u) - rhs_[i];  // Wᵀ v = a v − b
  if (axis_ < 0) {
    const int one = 1;
    int info = 0;
    dgetrs_("N", &n, &one, fac.lu[d].data(), &n, fac.pivot[d].data(), rhs_.data(), &n, &info, 1);
  } else {
    block_solve(fac, d);
  }
  scratch_.values() = x.values();
  std::fill(x.values().begin(), x.values().end(), 0.0);
  for (int i = 0; i < n; ++i) u[c.cut[i]] = rhs_[i];
  fast.solve(x, alpha, beta);  // H⁻¹ E C⁻¹ Wᵀ v
  const std::vector<double>& v = scratch_.values();
  std::vector<double>& out = x.values();
  for (std::size_t f = 0; f < out.size(); ++f) out[f] = v[f] - out[f];
  for (const std::size_t f : c.solid) u[f] = 0.0;  // the wall's velocity: no flux through it in D u*
}

void GhostCellWalls::add_explicit_correction(int d, const Array3& un, double c, Array3& rhs) const {
  const Component& comp = comp_[d];
  const LatticeIndex L{grid_.n()};
  const double inv_h2 = 1.0 / (grid_.h() * grid_.h());
  const double* const u = un.data();
  for (std::size_t i = 0; i < comp.cut.size(); ++i) {
    double cut = 0;
    for (std::size_t e = comp.row_start[i]; e < comp.row_start[i + 1]; ++e) cut += comp.val[e] * u[comp.col[e]];
    rhs.data()[comp.cut[i]] += c * (cut - L.laplacian(u, comp.cut[i], inv_h2));
  }
}

void GhostCellWalls::laplacian(int d, const Array3& u, Array3& out) const {
  const Component& c = comp_[d];
  const LatticeIndex L{grid_.n()};
  const double inv_h2 = 1.0 / (grid_.h() * grid_.h());
  const double* const v = u.data();
  double* const o = out.data();
  for (std::size_t f = 0; f < u.size(); ++f) {
    if (!c.fluid[f]) {
      o[f] = 0;
      continue;
    }
    o[f] = L.laplacian(v, f, inv_h2);
  }
  for (std::size_t i = 0; i < c.cut.size(); ++i) {
    double sum = 0;
    for (std::size_t k = c.row_start[i]; k < c.row_start[i + 1]; ++k) sum += c.val[k] * v[c.col[k]];
    o[c.cut[i]] = sum;
  }
}

void GhostCellWalls::steady_flow(int d, double f, double mu, Array3& u, FftHelmholtzSolver& fast) {
  const Component& c = comp_[d];
  const double h = grid_.h();
  std::fill(u.values().begin(), u.values().end(), 0.0);
  if (f == 0) return;
  // The slowest mode of −L_c: about (2.405/R)² for the widest circle R of fluid, below half the box's longest side.
  double R = 0.5 * std::max({grid_.length(0), grid_.length(1), grid_.length(2)});
  std::vector<double> alphas;
  for (double a = 12 / (h * h); a > 0.25 * std::pow(2.405 / R, 2); a /= 4) alphas.push_back(a);
  Array3 r(u.shape()[0], u.shape()[1], u.shape()[2]), lap = r;
  const double target = 1e-12 * std::abs(f) / mu;
  for (int cycle = 0; cycle < 200; ++cycle) {
    for (const double alpha : alphas) {
      laplacian(d, u, lap);
      double worst = 0;
      for (std::size_t q = 0; q < u.size(); ++q) {
        r.data()[q] = c.fluid[q] ? -f / mu - lap.data()[q] : 0.0;
        worst = std::max(worst, std::abs(r.data()[q]));
      }
      if (worst <= target) return;
      solve(d, r, alpha, -1.0, fast);
      for (std::size_t q = 0; q < u.size(); ++q) u.data()[q] -= r.data()[q];
    }
  }
  throw SimulationError("GhostCellWalls::steady_flow: the iterations did not converge in 200 cycles");
}

FluidEnergy GhostCellWalls::energy(const FluidParams& params, const FaceField& u) const {
  const double h3 = grid_.h() * grid_.h() * grid_.h();
  FluidEnergy e;
  for (int d = 0; d < 3; ++d) {
    const Component& c = comp_[d];
    const double* const v = u[d].data();
    Array3 lap(u[d].shape()[0], u[d].shape()[1], u[d].shape()[2]);
    laplacian(d, u[d], lap);
    for (std::size_t f = 0; f < u[d].size(); ++f) {
      if (!c.fluid[f]) continue;
      e.kinetic += 0.5 * params.rho * v[f] * v[f] * h3;
      e.dissipation -= params.mu * v[f] * lap.data()[f] * h3;
      e.body += params.body_force[d] * v[f] * h3;
    }
  }
  return e;
}

bool GhostCellWalls::open_along(int d) const {
  // Breadth-first search over the fluid points, each labelled with its winding along d (how often the path to it
  // crossed the box's end along d): two paths that reach one point with different windings close around the box.
  const LatticeIndex L{grid_.n()};
  const std::vector<unsigned char>& fluid = comp_[d].fluid;
  constexpr int unseen = std::numeric_limits<int>::min();
  std::vector<int> winding(fluid.size(), unseen);
  std::vector<std::size_t> queue;
  for (std::size_t start = 0; start < fluid.size(); ++start) {
    if (!fluid[start] || winding[start] != unseen) continue;
    winding[start] = 0;
    queue.assign(1, start);
    for (std::size_t head = 0; head < queue.size(); ++head) {
      const std::size_t f = queue[head];
      const std::array<int, 3> q = L.ijk(f);
      for (int a = 0; a < 3; ++a)
        for (const int step : {-1, 1}) {
          std::array<int, 3> r = q;
          r[a] += step;
          const std::size_t g = L.flat(r[0], r[1], r[2]);
          if (!fluid[g]) continue;
          const int w = winding[f] + (a == d ? (r[a] < 0 ? -1 : r[a] >= L.n[a] ? 1 : 0) : 0);
          if (winding[g] == unseen) {
            winding[g] = w;
            queue.push_back(g);
          } else if (winding[g] != w) {
            return true;
          }
        }
    }
  }
  return false;
}

double GhostCellWalls::cut_residual(int d, const Array3& x, const Array3& b) const {
  const Component& c = comp_[d];
  double worst = 0;
  for (std::size_t i = 0; i < c.cut.size(); ++i)
    worst = std::max(worst, std::abs(row_times(c, i, x.data()) - b.data()[c.cut[i]]));
  return worst;
}

}  // namespace immerse
