#pragma once
// The membranes of a run as its configuration describes them: each [[membrane]] entry's mesh (generated or read from
// a Gmsh file), initial and reference positions, force object (ElasticMembrane with its law, bending and constraint
// moduli), the volume it keeps with volume_correction = "normal_shift" and its viscosity ratio; with [packing] the
// copies of membrane[0] placed by CellPacking instead. The geometry is checked (inside the box, clear of the walls by
// one cell, not self-intersecting, not overlapping or nested): InputError naming the membrane otherwise.
//
// Shared by the one-process run (Simulation) and the distributed one (DistributedSimulation): both build the same
// membranes from the same configuration, bit for bit (the packing draws from its seeded generator), so every process
// of a distributed run holds the same replicated meshes and reference positions.
// Verified by: the tests of Simulation (test_simulation_*, test_cell_packing) and ParallelRun.* (the distributed run
// equals the one-process run of the same configuration).
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "immerse/core/Vec3.hpp"
#include "immerse/grid/Grid.hpp"
#include "immerse/io/Config.hpp"
#include "immerse/membrane/ElasticMembrane.hpp"
#include "immerse/membrane/Mesh.hpp"

namespace immerse {

class WallGeometry;

/// "membrane[m]": membrane m as keys and messages name it.
std::string membrane_name(std::size_t m);

struct MembraneSet {
  std::vector<Mesh> meshes;                                 ///< nodes at the initial positions
  std::vector<std::vector<Vec3>> references, initial;       ///< per membrane, global order
  std::vector<std::unique_ptr<ElasticMembrane>> membranes;  ///< the force objects
  /// The initial volume of each membrane whose volume is restored after every step (volume_correction).
  std::vector<std::optional<double>> corrected_volume;
  std::vector<double> viscosity_ratio;  ///< λ = μ_in/μ_out of each membrane
  /// "packing: N copies of membrane[0], volume fraction ..., in T s" when [packing] placed the membranes, else empty.
  std::string packing_summary;
};

/// Builds, packs and checks the membranes of `config` (already through apply_scenario) in the box of `grid`, in the
/// fluid of `walls` (the [[wall]] shapes the fluid solver holds; null without). `stop_requested`, when given, is asked
/// while [packing] places the cells: true throws StopRequested.
MembraneSet build_membrane_set(const io::Config& config, const Grid& grid, std::shared_ptr<const WallGeometry> walls,
                               const std::function<bool()>& stop_requested = {});

}  // namespace immerse
