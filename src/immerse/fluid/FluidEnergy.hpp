#pragma once
// The energy measures of a MAC velocity field (docs/energy-budget.md): its kinetic energy, and the three rates that
// change it through the viscous term, the walls and the body force of (9). With L the viscous operator of the step,
// μ ∇_h² (MacStencil_K.hpp) plus, with a variable viscosity μ (1 + χ), μ ∇_h·(χ S) (ViscousStress_K.hpp), summation
// by parts over the unknowns gives exactly
//
//   Σ_faces u·(L u) h³ = −dissipation + walls,
//
//   dissipation = μ h Σ_links (Δu)² + μ h Σ_wall links w (u_B − u)²        (|G_h u|² h³ over every velocity link)
//               + μ h³ Σ_cells χ ½ Σ_d S_dd² + μ h³ Σ_edges w χ_e S_de²   (χ |S|²/2 h³, with a variable viscosity)
//   walls       = μ h Σ_wall links u_w (u_B − u) + μ h² Σ_wall cells/edges ± u_w χ S
//
// where a link joins two unknowns of one component (periodic wrap included), a wall link joins an unknown to the
// value beyond a wall that the operator reads, u_B: the normal wall velocity on a wall face (w = 1), or the ghost
// 2 u_w − u of a tangential component (w = ½: the half cell between the unknown and the wall), u_w the wall velocity
// of that component, and the edges on a wall count half (w = ½) with the sign + at an upper wall, − at a lower one.
// kinetic = ρ/2 Σ u² h³ and body = f_body · Σ u h³ over the unknowns of each component.
//
// Sums in a fixed order, whatever the number of threads or processes: each part is summed over one z plane at a time
// (component faces by their cell plane, edges along z by their z index), rows in order, then the planes in order. A
// slab of a distributed run (SlabDecomposition) gives its own planes' sums and zeros elsewhere, so that the element-
// wise sum over the processes adds exactly one non-zero number per entry and the total is the one-process total.
// Verified by: the tests FluidEnergy.* (tests/test_energy_budget.cpp: the identity above on random fields with
// periodic axes, moving walls and a variable viscosity; Taylor-Green decay; Couette flow) and ParallelFluidStep.*
// (the slab sums equal the whole-grid ones on 1, 2 and 3 processes).
#include <span>
#include <vector>

#include "immerse/core/Array3.hpp"
#include "immerse/fluid/FluidParams.hpp"
#include "immerse/grid/FaceField.hpp"
#include "immerse/grid/Grid.hpp"

namespace immerse {

/// The energy measures of the fluid at one instant.
struct FluidEnergy {
  double kinetic = 0;      ///< ρ/2 Σ u² h³ (J)
  double dissipation = 0;  ///< viscous dissipation rate (W)
  double walls = 0;        ///< power the moving walls put into the fluid (W)
  double body = 0;         ///< power of the body force, f_body · Σ u h³ (W)
};

/// The number of plane sums fluid_energy_planes() gives on this grid.
std::size_t fluid_energy_plane_count(const Grid& grid);

/// The parts of the sums of FluidEnergy that come from the cell planes [z_begin, z_end) (the z edges of the upper
/// wall with the last plane), by part and plane, zeros for the other planes. u, and chi when not null (χ at the
/// cells), are whole-grid arrays (z_offset = 0), or slab arrays whose local plane k is the grid's plane k + z_offset
/// and which hold the planes z_begin − 1 … z_end + 1 (SlabDecomposition's, ghost planes filled). Threads over the
/// planes; the result does not depend on their number.
std::vector<double> fluid_energy_planes(const Grid& grid, const FluidParams& params, const FaceField& u,
                                        const Array3* chi, int z_begin, int z_end, int z_offset);

/// The measures from the sums of every plane (added plane by plane in order).
FluidEnergy fluid_energy_total(const Grid& grid, const FluidParams& params, std::span<const double> planes);

/// The measures of the whole-grid field u (chi: χ at the cells, or null for a constant viscosity).
FluidEnergy fluid_energy(const Grid& grid, const FluidParams& params, const FaceField& u, const Array3* chi);

}  // namespace immerse
