#pragma once
// Scenario kinds turn nondimensional groups into the dimensional values of a run (SI units throughout).
//
// Shear scenarios (capsule_shear §4.2.1, oblate_shear §4.2.2, bending_shear §4.2.3): a capsule of radius a
// (membrane[0].radius; for an oblate spheroid the radius of the equal-volume sphere) at the box centre, walls at
// z = z_c -+ Lz/2 moving with -+ k Lz/2 along x, so that the undisturbed flow is u = (k (z - z_c), 0, 0). From
//   Re = rho k a^2 / mu,   G = mu k a / E_s  (44),   kappa_B_hat = kappa_B / (a^2 E_s)
// follow k = Re mu / (rho a^2), E_s = mu k a / G and kappa_B = kappa_B_hat a^2 E_s. The fluid starts in the
// undisturbed shear flow; time.dt and time.end are read in units of the shear time 1/k (k dt and k t_end).
//
// rbc_stretch (§4.3): the biconcave cell of eq. (45) with the Yeoh law (23), C10 = mu0/2 and C30 = mu0/30
// (small-strain shear modulus mu0, notes), stretched along x (see StretchSweep).
//
// rbc_channel (§4.4, Fig. 15): 32 copies of the one [[membrane]] (a biconcave cell, Yeoh law as above) in a duct
// with walls at x and z and periodic along y, the flow direction, driven by fluid.body_force (a mean pressure
// gradient). The cells lie flat (disc in x-y) in three layers at z = 0.18 Lz, Lz/2, 0.82 Lz: the outer layers have
// two columns at x = Lx/4, 3Lx/4 of five cells each, the middle layer three staggered columns at x = 0.2 Lx, Lx/2,
// 0.8 Lx of four (10 + 12 + 10). In the paper's 24 x 48 x 12 um duct neighbouring cells are at least 1.2 um apart
// and 0.88 um from the walls; Simulation checks the clearances of any other box. scenario.copies = [cx, cy, cz] repeats
// the arrangement in cx x cy x cz sub-boxes of size (Lx/cx, Ly/cy, Lz/cz): [2, 2, 2] in a 48 x 96 x 24 um duct is
// the 256-cell channel, twice §4.4 along each axis.
#include <array>
#include <vector>

#include "immerse/core/Vec3.hpp"
#include "immerse/io/Config.hpp"

namespace immerse {

/// The configuration with the scenario's derived values written into their keys (for printing and saving). A key of a
/// [[membrane]] entry that does not apply to it (radius to a mesh read from a file, mesh.file to a generated one, ...)
/// is refused when the user gave it and left out of the written configuration otherwise.
io::Config apply_scenario(const io::Config& config);


/// rbc_channel: the copies of the 32-cell arrangement along x, y and z (scenario.copies; InputError unless three whole
/// numbers >= 1).
std::array<int, 3> channel_copies(const io::Config& config);
/// rbc_channel: the centres of the 32 cells (see above) in each sub-box of size (Lx/cx, Ly/cy, Lz/cz), sub-box by
/// sub-box with x fastest.
std::vector<Vec3> channel_cell_centres(const io::Config& config);

/// The shear rate k of a shear scenario or of a plane Couette flow between walls z = const moving along x (0 when
/// there is none).
double shear_rate(const io::Config& config);

}  // namespace immerse
