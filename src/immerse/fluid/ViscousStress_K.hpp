#pragma once
// Pointwise MAC kernel of the variable part of the viscous stress (docs/viscosity-contrast.md): with
// μ(x) = μ (1 + χ(x)), χ at the cell centres,
//
//   [∇_h·(χ (∇_h u + ∇_h uᵀ))]_d = Σ_e (χ S_de)(q + ½e_e) − (χ S_de)(q − ½e_e)) / h   at face q of component d,
//   S_dd = 2 (u_d(q + e_d) − u_d(q)) / h at cell q,  χ at the cell;
//   S_de = (u_d(q) − u_d(q − e_e)) / h + (u_e(q) − u_e(q − e_d)) / h at the d-e edge q (e ≠ d),
//          χ there the mean of the four cells q, q − e_d, q − e_e, q − e_d − e_e.
//
// It reads the velocity at faces and χ at cells one index either side of the face (wrapped on periodic axes, and
// never across a wall: callers apply it only where every index read is stored, i.e. where χ vanishes within three
// cells of every wall). For constant χ and D_h u = 0 it equals χ ∇_h² u (the Laplacian of MacStencil_K.hpp).
// Verified by: the tests ViscosityContrast.StressOfConstantViscosityIsTheLaplacian,
// ViscosityContrast.ManufacturedFlowIsSecondOrderInSpaceAndTime and ViscosityContrast.ManufacturedFlowInAClosedBox*.
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

/// χ at the d-e edge q: the mean of its four cells.
inline double edge_chi(const Array3& chi, const MacStencilGrid& g, const Index& q, int d, int e) {
  const Index qd = shifted(g, q, d, -1);
  return 0.25 * (at(chi, q) + at(chi, qd) + at(chi, shifted(g, q, e, -1)) + at(chi, shifted(g, qd, e, -1)));
}

/// S_de at the d-e edge q (e ≠ d).
inline double edge_strain(const FaceField& u, const MacStencilGrid& g, const Index& q, int d, int e) {
  return (at(u[d], q) - at(u[d], shifted(g, q, e, -1)) + at(u[e], q) - at(u[e], shifted(g, q, d, -1))) * g.inv_h;
}

/// [∇_h·(χ (∇_h u + ∇_h uᵀ))]_d at face q of component d (see the header comment).
inline double stress_divergence(const FaceField& u, const Array3& chi, const MacStencilGrid& g, int d, const Index& q) {
  const Index qm = shifted(g, q, d, -1), qp = shifted(g, q, d, +1);
  const double s_here = 2.0 * (at(u[d], qp) - at(u[d], q)) * g.inv_h;
  const double s_back = 2.0 * (at(u[d], q) - at(u[d], qm)) * g.inv_h;
  double s = at(chi, q) * s_here - at(chi, qm) * s_back;
  for (int e = 0; e < 3; ++e) {
    if (e == d) continue;
    const Index qe = shifted(g, q, e, +1);
    s += edge_chi(chi, g, qe, d, e) * edge_strain(u, g, qe, d, e) - edge_chi(chi, g, q, d, e) * edge_strain(u, g, q, d, e);
  }
  return s * g.inv_h;
}

}  // namespace immerse::mac
