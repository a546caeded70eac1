#include "immerse/fluid/FluidEnergy.hpp"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <utility>

#include "immerse/fluid/MacStencilGrid.hpp"
#include "immerse/fluid/MacStencil_K.hpp"

namespace immerse {

namespace {

// The plane sums: part (Σ u², dissipation, walls, Σ u) by slot (the links of components x, y, z; the cells and the
// xy, xz, yz edges of a variable viscosity) by plane (n_z + 1: the z edges of an upper wall have index n_z).
constexpr int kParts = 4;
constexpr int kSlots = 7;
enum Part { kKinetic, kDissipation, kWalls, kBody };
constexpr int kCellSlot = 3;
constexpr std::array<std::pair<int, int>, 3> kEdgePairs{{{0, 1}, {0, 2}, {1, 2}}};

std::size_t planes_of(const Grid& grid) { return static_cast<std::size_t>(grid.n(2)) + 1; }

std::size_t at(const Grid& grid, int part, int slot, int plane) {
  return (static_cast<std::size_t>(part) * kSlots + static_cast<std::size_t>(slot)) * planes_of(grid) +
         static_cast<std::size_t>(plane);
}

/// The arrays read at the grid's indices: periodic indices wrapped, beyond a wall the values the viscous operator
/// takes, a slab's planes found from the global plane.
struct Field {
  const MacStencilGrid& g;  ///< the whole grid, with its wall velocities
  const FaceField& u;
  const Array3* chi;
  int offset;  ///< local plane k of the arrays is the grid's plane k + offset

  /// The local plane of the grid's plane z (wrapped onto the stored planes along a periodic z).
  int plane(const Array3& a, int z) const {
    int k = z - offset;
    if (k < 0)
      k += g.n[2];
    else if (k >= a.nz())
      k -= g.n[2];
    return k;
  }
  const double* row(const Array3& a, int j, int z) const { return a.data() + a.index(0, j, plane(a, z)); }

  /// Component c at index r of its own array, r at most one index beyond its unknowns along one wall axis: the
  /// normal wall velocity on a wall face, the ghost 2 u_w − u_0 beyond a wall (ViscousStress_K.hpp's wall_velocity).
  double vel(int c, mac::Index r) const {
    double base = 0, sign = 1;
    for (int a = 0; a < 3; ++a) {
      if (g.periodic[a]) {
        if (a < 2) r[a] = mac::wrap(r[a], g.n[a]);
        continue;
      }
      if (a == c) {
        if (r[a] == 0) return g.wall_lower[a][c];
        if (r[a] == g.n[a]) return g.wall_upper[a][c];
      } else if (r[a] < 0 || r[a] == g.n[a]) {
        const bool lower = r[a] < 0;
        r[a] = lower ? 0 : g.n[a] - 1;
        base = 2.0 * (lower ? g.wall_lower[a][c] : g.wall_upper[a][c]);
        sign = -1;
      }
    }
    const Array3& a = u[c];
    return base + sign * a(r[0], r[1], plane(a, r[2]));
  }

  /// χ at cell r, beyond a wall that of the cell inside.
  double cell(mac::Index r) const {
    for (int a = 0; a < 3; ++a)
      if (!g.periodic[a])
        r[a] = std::clamp(r[a], 0, g.n[a] - 1);
      else if (a < 2)
        r[a] = mac::wrap(r[a], g.n[a]);
    return (*chi)(r[0], r[1], plane(*chi, r[2]));
  }

  /// Whether χ is zero on the whole row (j, z) (indices as cell()).
  bool zero_row(int j, int z) const {
    j = g.periodic[1] ? mac::wrap(j, g.n[1]) : std::clamp(j, 0, g.n[1] - 1);
    if (!g.periodic[2]) z = std::clamp(z, 0, g.n[2] - 1);
    const double* r = row(*chi, j, z);
    return std::all_of(r, r + g.n[0], [](double v) { return v == 0.0; });
  }
};

/// A link from an unknown u to the value beyond a wall of velocity u_w (this component): the wall value itself on a
/// wall face (normal), else the ghost 2 u_w − u, half a cell away (weight ½).
inline void wall_link(double u, double uw, bool normal, double& dissipation, double& walls) {
  const double du = normal ? uw - u : 2.0 * (uw - u);
  dissipation += (normal ? 1.0 : 0.5) * du * du;
  walls += uw * du;
}

/// The unknowns of component d on plane z: Σ u², Σ u, and each one's links towards +x, +y, +z, and its wall links.
/// Rows whose faces all have their +x, +y and +z neighbours stored (all but the last face of a row away from the
/// walls) take a loop without branches.
void component_plane(const Field& f, int d, int z, double* out) {
  const MacStencilGrid& g = f.g;
  if (z < g.first(d, 2)) return;  // the lower wall face of u_z
  const Array3& a = f.u[d];
  const int nx = g.n[0], ny = g.n[1];
  const int i0 = g.first(d, 0), j0 = g.first(d, 1);
  const bool wx = !g.periodic[0], wy = !g.periodic[1], wz = !g.periodic[2];
  const bool z_top = wz && z == g.n[2] - 1, z_bottom = wz && z == g.first(d, 2);
  double ku = 0, su = 0, diss = 0, walls = 0;
  for (int j = j0; j < ny; ++j) {
    const double* r = f.row(a, j, z);
    const bool y_top = wy && j == ny - 1, y_bottom = wy && j == j0;
    const double* ry = y_top ? nullptr : f.row(a, j + 1 == ny ? 0 : j + 1, z);
    const double* rz = z_top ? nullptr : f.row(a, j, z + 1);
    const auto face = [&](int i) {
      const double v = r[i];
      ku += v * v;
      su += v;
      double du = 0;
      if (i + 1 < nx)
        du = r[i + 1] - v, diss += du * du;
      else if (!wx)
        du = r[0] - v, diss += du * du;
      else
        wall_link(v, g.wall_upper[0][d], d == 0, diss, walls);
      if (wx && i == i0) wall_link(v, g.wall_lower[0][d], d == 0, diss, walls);
      if (ry)
        du = ry[i] - v, diss += du * du;
      else
        wall_link(v, g.wall_upper[1][d], d == 1, diss, walls);
      if (y_bottom) wall_link(v, g.wall_lower[1][d], d == 1, diss, walls);
      if (rz)
        du = rz[i] - v, diss += du * du;
      else
        wall_link(v, g.wall_upper[2][d], d == 2, diss, walls);
      if (z_bottom) wall_link(v, g.wall_lower[2][d], d == 2, diss, walls);
    };
    int i = i0;
    if (ry && rz && !y_bottom && !z_bottom) {
      if (wx) face(i++);  // the lower x wall link
      double k2 = 0, s1 = 0, d2 = 0;
#pragma omp simd reduction(+ : k2, s1, d2)
      for (int m = i; m < nx - 1; ++m) {
        const double v = r[m], dx = r[m + 1] - v, dy = ry[m] - v, dz = rz[m] - v;
        k2 += v * v;
        s1 += v;
        d2 += dx * dx + dy * dy + dz * dz;
      }
      ku += k2;
      su += s1;
      diss += d2;
      i = std::max(i, nx - 1);
    }
    for (; i < nx; ++i) face(i);
  }
  out[kKinetic] = ku;
  out[kDissipation] = diss;
  out[kWalls] = walls;
  out[kBody] = su;
}

/// The cells of plane z: χ ½ Σ_d S_dd², S_dd = 2 (u_d(q + e_d) − u_d(q)) / h, and at a wall the power ± u_w χ S_dd of
/// the normal component.
void cell_plane(const Field& f, int z, double* out) {
  const MacStencilGrid& g = f.g;
  double diss = 0, walls = 0;
  for (int j = 0; j < g.n[1]; ++j) {
    if (f.zero_row(j, z)) continue;
    for (int i = 0; i < g.n[0]; ++i) {
      const mac::Index q{i, j, z};
      const double c = f.cell(q);
      if (c == 0.0) continue;
      for (int d = 0; d < 3; ++d) {
        mac::Index qp = q;
        ++qp[d];
        const double s = 2.0 * (f.vel(d, qp) - f.vel(d, q)) * g.inv_h;
        diss += 0.5 * c * s * s;
        if (g.periodic[d]) continue;
        if (q[d] == 0) walls -= g.wall_lower[d][d] * c * s;
        if (q[d] == g.n[d] - 1) walls += g.wall_upper[d][d] * c * s;
      }
    }
  }
  out[kDissipation] = diss;
  out[kWalls] = walls;
}

/// The a-b edges with z index z (a < b): w χ_e S_ab², χ_e the mean of the four cells around the edge, S_ab =
/// (u_a(m) − u_a(m − e_b) + u_b(m) − u_b(m − e_a)) / h, w = ½ on a wall, where the tangential component's power
/// ± u_w χ_e S_ab is taken (+ at the upper wall); edges on two walls are read by no unknown.
void edge_plane(const Field& f, int a, int b, int z, double* out) {
  const MacStencilGrid& g = f.g;
  const auto extent = [&](int axis) {
    return (axis == a || axis == b) && !g.periodic[axis] ? g.n[axis] + 1 : g.n[axis];
  };
  const auto on_wall = [&](const mac::Index& m, int axis) {
    return !g.periodic[axis] && (m[axis] == 0 || m[axis] == g.n[axis]);
  };
  const int ex = extent(0), ey = extent(1);
  double diss = 0, walls = 0;
  mac::Index m{0, 0, z};
  for (m[1] = 0; m[1] < ey; ++m[1]) {
    // The cells the edges of this row read: rows m[1] and m[1] − 1 when y is in the pair, planes z and z − 1 when z is.
    bool zero = f.zero_row(m[1], z);
    if (b == 2) zero = zero && f.zero_row(m[1], z - 1);
    if (a == 1 || b == 1) {
      zero = zero && f.zero_row(m[1] - 1, z);
      if (b == 2) zero = zero && f.zero_row(m[1] - 1, z - 1);
    }
    if (zero) continue;
    for (m[0] = 0; m[0] < ex; ++m[0]) {
      const bool on_a = on_wall(m, a), on_b = on_wall(m, b);
      if (on_a && on_b) continue;
      mac::Index ma = m, mb = m;
      --ma[a];
      --mb[b];
      mac::Index mab = ma;
      --mab[b];
      const double c = 0.25 * (f.cell(m) + f.cell(ma) + f.cell(mb) + f.cell(mab));
      if (c == 0.0) continue;
      const double s = (f.vel(a, m) - f.vel(a, mb) + f.vel(b, m) - f.vel(b, ma)) * g.inv_h;
      diss += (on_a || on_b ? 0.5 : 1.0) * c * s * s;
      if (on_b) walls += (m[b] == 0 ? -g.wall_lower[b][a] : g.wall_upper[b][a]) * c * s;
      if (on_a) walls += (m[a] == 0 ? -g.wall_lower[a][b] : g.wall_upper[a][b]) * c * s;
    }
  }
  out[kDissipation] = diss;
  out[kWalls] = walls;
}

}  // namespace

std::size_t fluid_energy_plane_count(const Grid& grid) { return kParts * kSlots * planes_of(grid); }

std::vector<double> fluid_energy_planes(const Grid& grid, const FluidParams& params, const FaceField& u,
                                        const Array3* chi, int z_begin, int z_end, int z_offset) {
  const int nz = grid.n(2);
  if (z_begin < 0 || z_end > nz || z_begin > z_end)
    throw std::invalid_argument("fluid_energy_planes: planes outside the grid");
  const MacStencilGrid g(grid, params);
  const bool variable = chi && chi->size() > 0;
  const Field f{g, u, variable ? chi : nullptr, z_offset};
  // The work: (slot, plane) pairs, each summed by one thread in a fixed order.
  std::vector<std::pair<int, int>> work;
  for (int s = 0; s < (variable ? kSlots : kCellSlot); ++s) {
    for (int z = z_begin; z < z_end; ++z) work.emplace_back(s, z);
    if (s > kCellSlot + 1 && !grid.periodic(2) && z_end == nz) work.emplace_back(s, nz);  // the upper wall's z edges
  }
  std::vector<double> planes(fluid_energy_plane_count(grid), 0.0);
  const long n = static_cast<long>(work.size());
  const bool threaded =
      static_cast<long>(z_end - z_begin) * grid.n(0) * grid.n(1) >= MacStencilGrid::kMinCellsForThreads;
#pragma omp parallel for schedule(dynamic) if (threaded)
  for (long w = 0; w < n; ++w) {
    const auto [s, z] = work[static_cast<std::size_t>(w)];
    double out[kParts] = {0, 0, 0, 0};
    if (s < kCellSlot)
      component_plane(f, s, z, out);
    else if (s == kCellSlot)
      cell_plane(f, z, out);
    else
      edge_plane(f, kEdgePairs[s - kCellSlot - 1].first, kEdgePairs[s - kCellSlot - 1].second, z, out);
    for (int p = 0; p < kParts; ++p) planes[at(grid, p, s, z)] = out[p];
  }
  return planes;
}

FluidEnergy fluid_energy_total(const Grid& grid, const FluidParams& params, std::span<const double> planes) {
  if (planes.size() != fluid_energy_plane_count(grid))
    throw std::invalid_argument("fluid_energy_total: the plane sums do not match the grid");
  double sum[kParts][kSlots] = {};
  for (int p = 0; p < kParts; ++p)
    for (int s = 0; s < kSlots; ++s)
      for (int z = 0; z <= grid.n(2); ++z) sum[p][s] += planes[at(grid, p, s, z)];
  const double h = grid.h(), h3 = h * h * h, mu = params.mu;
  const auto links = [&](int p) { return sum[p][0] + sum[p][1] + sum[p][2]; };
  const auto stress = [&](int p) { return sum[p][3] + sum[p][4] + sum[p][5] + sum[p][6]; };
  FluidEnergy e;
  e.kinetic = 0.5 * params.rho * h3 * links(kKinetic);
  e.dissipation = mu * h * links(kDissipation) + mu * h3 * stress(kDissipation);
  e.walls = mu * h * links(kWalls) + mu * h * h * stress(kWalls);
  for (int d = 0; d < 3; ++d) e.body += params.body_force[d] * h3 * sum[kBody][d];
  return e;
}

FluidEnergy fluid_energy(const Grid& grid, const FluidParams& params, const FaceField& u, const Array3* chi) {
  return fluid_energy_total(grid, params, fluid_energy_planes(grid, params, u, chi, 0, grid.n(2), 0));
}

}  // namespace immerse
