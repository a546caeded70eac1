#include "immerse/fluid/FluidDiagnostics.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "immerse/fluid/MacStencil_K.hpp"

namespace immerse {

namespace {

struct Accumulator {
  double sum2 = 0, max = 0;
  long count = 0;
  void add(double e) {
    sum2 += e * e;
    max = std::max(max, std::abs(e));
    ++count;
  }
  ErrorNorms norms() const { return {count > 0 ? std::sqrt(sum2 / static_cast<double>(count)) : 0.0, max}; }
};

// Serial loop over the unknowns of component d (diagnostics: reproducible sums, no threading needed).
template <class F>
void serial_faces(const MacStencilGrid& g, int d, F&& f) {
  for (int k = g.first(d, 2); k < g.n[2]; ++k)
    for (int j = g.first(d, 1); j < g.n[1]; ++j)
      for (int i = g.first(d, 0); i < g.n[0]; ++i) f(i, j, k);
}

double mean(const Array3& a) {
  double s = 0;
  for (double v : a.values()) s += v;
  return s / static_cast<double>(a.size());
}

}  // namespace

void divergence(const Grid& grid, const FaceField& u, Array3& div) {
  const MacStencilGrid g(grid);
  div = Array3(grid.n(0), grid.n(1), grid.n(2));
  for_each_cell(g, [&](int i, int j, int k) { div(i, j, k) = mac::divergence_cell(u, g, {i, j, k}); });
}

double max_abs_velocity(const Grid& grid, const FaceField& u) {
  const MacStencilGrid g(grid);
  double m = 0;
  for (int d = 0; d < 3; ++d)
    serial_faces(g, d, [&](int i, int j, int k) { m = std::max(m, std::abs(u[d](i, j, k))); });
  return m;
}

double wall_shear_stress(const Grid& grid, const FaceField& u, const Array3* chi, double mu, bool upper,
                         double wall_velocity_x) {
  const double sum = wall_shear_stress_sum(grid, u[0], chi, upper, wall_velocity_x, upper ? grid.n(2) - 1 : 0);
  return mu * sum / (double(grid.n(0)) * double(grid.n(1)));
}

double wall_shear_stress_sum(const Grid& grid, const Array3& ux, const Array3* chi, bool upper, double wall_velocity_x,
                             int k) {
  if (grid.periodic(2) || !grid.periodic(0))
    throw std::invalid_argument("wall_shear_stress: needs walls along z and a periodic x axis");
  const int nx = grid.n(0), ny = grid.n(1);
  const bool contrast = chi != nullptr && chi->size() > 0;
  double sum = 0;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const double dudz = 2.0 * (upper ? wall_velocity_x - ux(i, j, k) : ux(i, j, k) - wall_velocity_x) / grid.h();
      const double c = contrast ? 0.5 * ((*chi)(i, j, k) + (*chi)((i + nx - 1) % nx, j, k)) : 0.0;
      sum += (1.0 + c) * dudz;
    }
  return sum;
}

void apply_operator(const Grid& grid, Layout layout, const Array3& x, double alpha, double beta, Array3& out) {
  const MacStencilGrid g(grid);
  out = Array3(x.nx(), x.ny(), x.nz());
  if (layout == Layout::Pressure) {
    for_each_cell(g, [&](int i, int j, int k) {
      out(i, j, k) = alpha * x(i, j, k) + beta * mac::laplacian_cell_neumann(x, g, {i, j, k});
    });
    return;
  }
  const int d = static_cast<int>(layout);
  for_each_face(g, d, [&](int i, int j, int k) {
    out(i, j, k) = alpha * x(i, j, k) + beta * mac::laplacian_face(x, g, d, {i, j, k});
  });
}

double relative_residual(const Grid& grid, Layout layout, const Array3& x, const Array3& b, double alpha, double beta) {
  Array3 ax;
  apply_operator(grid, layout, x, alpha, beta, ax);
  const MacStencilGrid g(grid);
  const int d = layout == Layout::Pressure ? -1 : static_cast<int>(layout);
  double r = 0, bmax = 0;
  serial_faces(g, d, [&](int i, int j, int k) {
    r = std::max(r, std::abs(ax(i, j, k) - b(i, j, k)));
    bmax = std::max(bmax, std::abs(b(i, j, k)));
  });
  return r / bmax;
}

ErrorNorms velocity_error(const Grid& grid, const FaceField& u, const std::function<Vec3(const Vec3&)>& exact) {
  const MacStencilGrid g(grid);
  Accumulator acc;
  for (int d = 0; d < 3; ++d)
    serial_faces(g, d, [&](int i, int j, int k) { acc.add(u[d](i, j, k) - exact(grid.face_position(d, i, j, k))[d]); });
  return acc.norms();
}

ErrorNorms velocity_difference(const Grid& grid, const FaceField& a, const FaceField& b) {
  const MacStencilGrid g(grid);
  Accumulator acc;
  for (int d = 0; d < 3; ++d) serial_faces(g, d, [&](int i, int j, int k) { acc.add(a[d](i, j, k) - b[d](i, j, k)); });
  return acc.norms();
}

ErrorNorms pressure_error(const Grid& grid, const Array3& p, const std::function<double(const Vec3&)>& exact) {
  Array3 pe;
  sample_pressure(grid, exact, pe);
  return pressure_difference(p, pe);
}

ErrorNorms pressure_difference(const Array3& a, const Array3& b) {
  const double ma = mean(a), mb = mean(b);
  Accumulator acc;
  for (std::size_t n = 0; n < a.size(); ++n) acc.add((a[n] - ma) - (b[n] - mb));
  return acc.norms();
}

void sample_velocity(const Grid& grid, const std::function<Vec3(const Vec3&)>& exact, FaceField& u) {
  u = FaceField(grid);
  for (int d = 0; d < 3; ++d) {
    Array3& ud = u[d];
    for (int k = 0; k < ud.nz(); ++k)
      for (int j = 0; j < ud.ny(); ++j)
        for (int i = 0; i < ud.nx(); ++i) ud(i, j, k) = exact(grid.face_position(d, i, j, k))[d];
  }
}

void sample_pressure(const Grid& grid, const std::function<double(const Vec3&)>& exact, Array3& p) {
  p = Array3(grid.n(0), grid.n(1), grid.n(2));
  for (int k = 0; k < grid.n(2); ++k)
    for (int j = 0; j < grid.n(1); ++j)
      for (int i = 0; i < grid.n(0); ++i) p(i, j, k) = exact(grid.cell_position(i, j, k));
}

}  // namespace immerse
