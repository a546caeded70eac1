#pragma once
// Pointwise MAC kernel of the variable part of the viscous stress (docs/viscosity-contrast.md): with
// μ(x) = μ (1 + χ(x)), χ at the cell centres,
//
//   [∇_h·(χ (∇_h u + ∇_h uᵀ))]_d = Σ_e (χ S_de)(q + ½e_e) − (χ S_de)(q − ½e_e)) / h   at face q of component d,
//   S_dd = 2 (u_d(q + e_d) − u_d(q)) / h at cell q,  χ at the cell;
//   S_de = (u_d(q) − u_d(q − e_e)) / h + (u_e(q) − u_e(q − e_d)) / h at the d-e edge q (e ≠ d),
//          χ there the mean of the four cells q, q − e_d, q − e_e, q − e_d − e_e.
//
// At a no-slip wall the velocity takes the values of the Laplacian (MacStencil_K.hpp): the normal component its
// wall value on the wall face, a tangential one the ghost 2 u_w − u_0 beyond the wall; χ beyond a wall is that of
// the cell inside (χ_g = χ_0), so that an edge on the wall takes the mean of its two cells inside. For constant χ and
// D_h u = 0 it equals χ ∇_h² u (the Laplacian of MacStencil_K.hpp) on every face, walls included.
// Verified by: the tests ViscosityContrast.StressOfConstantViscosityIsTheLaplacian*,
// ViscosityContrast.ManufacturedFlowIsSecondOrderInSpaceAndTime and ViscosityContrast.ManufacturedFlow*Wall*.
#include <algorithm>

#include "immerse/core/Array3.hpp"
#include "immerse/fluid/MacStencilGrid.hpp"
#include "immerse/fluid/MacStencil_K.hpp"
#include "immerse/grid/FaceField.hpp"

namespace immerse::mac {

/// q shifted by s along axis a (wrapped on a periodic axis).
inline Index shifted(const MacStencilGrid& g, Index q, int a, int s) {
  q[a] += s;
  if (g.periodic[a]) q[a] = wrap(q[a], g.n[a]);
  return q;
}

/// Component c at index r of its own array, r at most one index beyond the stored unknowns along one wall axis: the
/// normal wall velocity on a wall face (axis c), the ghost 2 u_w − u_0 beyond a wall (axis ≠ c).
inline double wall_velocity(const FaceField& u, const MacStencilGrid& g, int c, Index r) {
  double base = 0, sign = 1;
  for (int a = 0; a < 3; ++a) {
    if (g.periodic[a]) continue;
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
  return base + sign * at(u[c], r);
}

/// χ at cell r, r at most one index beyond the cells along a wall axis (then the cell inside).
inline double wall_chi(const Array3& chi, const MacStencilGrid& g, Index r) {
  for (int a = 0; a < 3; ++a)
    if (!g.periodic[a]) r[a] = std::clamp(r[a], 0, g.n[a] - 1);
  return at(chi, r);
}

/// Reads of the kernel: Walls, through the wall values above (any face); otherwise straight from the arrays (faces
/// at least two indices from every wall, where every index read is stored).
template <bool Walls>
struct StressReads {
  const FaceField& u;
  const Array3& chi;
  const MacStencilGrid& g;
  double vel(int c, const Index& r) const { return Walls ? wall_velocity(u, g, c, r) : at(u[c], r); }
  double cell(const Index& r) const { return Walls ? wall_chi(chi, g, r) : at(chi, r); }
};

/// χ at the d-e edge q: the mean of its four cells.
template <class Reads>
inline double edge_chi(const Reads& s, const Index& q, int d, int e) {
  const Index qd = shifted(s.g, q, d, -1);
  return 0.25 * (s.cell(q) + s.cell(qd) + s.cell(shifted(s.g, q, e, -1)) + s.cell(shifted(s.g, qd, e, -1)));
}

/// S_de at the d-e edge q (e ≠ d).
template <class Reads>
inline double edge_strain(const Reads& s, const Index& q, int d, int e) {
  return (s.vel(d, q) - s.vel(d, shifted(s.g, q, e, -1)) + s.vel(e, q) - s.vel(e, shifted(s.g, q, d, -1))) * s.g.inv_h;
}

/// [∇_h·(χ (∇_h u + ∇_h uᵀ))]_d at face q of component d through the reads s.
template <class Reads>
inline double stress_divergence(const Reads& s, int d, const Index& q) {
  const MacStencilGrid& g = s.g;
  const Index qm = shifted(g, q, d, -1), qp = shifted(g, q, d, +1);
  const double s_here = 2.0 * (s.vel(d, qp) - s.vel(d, q)) * g.inv_h;
  const double s_back = 2.0 * (s.vel(d, q) - s.vel(d, qm)) * g.inv_h;
  double v = s.cell(q) * s_here - s.cell(qm) * s_back;
  for (int e = 0; e < 3; ++e) {
    if (e == d) continue;
    const Index qe = shifted(g, q, e, +1);
    v += edge_chi(s, qe, d, e) * edge_strain(s, qe, d, e) - edge_chi(s, q, d, e) * edge_strain(s, q, d, e);
  }
  return v * g.inv_h;
}

/// Whether face q of component d lies within one index of a wall face or wall cell, where the kernel reads wall
/// values.
inline bool near_wall(const MacStencilGrid& g, const Index& q) {
  for (int a = 0; a < 3; ++a)
    if (!g.periodic[a] && (q[a] < 2 || q[a] > g.n[a] - 3)) return true;
  return false;
}

/// [∇_h·(χ (∇_h u + ∇_h uᵀ))]_d at any unknown face q of component d (see the header comment).
inline double stress_divergence(const FaceField& u, const Array3& chi, const MacStencilGrid& g, int d, const Index& q) {
  if (near_wall(g, q)) return stress_divergence(StressReads<true>{u, chi, g}, d, q);
  return stress_divergence(StressReads<false>{u, chi, g}, d, q);
}

}  // namespace immerse::mac
