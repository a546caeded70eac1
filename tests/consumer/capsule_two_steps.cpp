// Two steps of the quick capsule in shear through the library: configuration from a scenario file, the run built
// and advanced by Simulation. Prints the step, time and volume; exits 1 unless two finite steps were taken.
#include <cmath>
#include <iostream>
#include <string>

#include "immerse/membrane/Geometry.hpp"
#include "immerse/scenario/Scenario.hpp"
#include "immerse/simulation/Parameters.hpp"
#include "immerse/simulation/Simulation.hpp"
#include "immerse/timestep/PetscSession.hpp"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::cerr << "usage: capsule_two_steps SCENARIOS_DIR\n";
    return 2;
  }
  immerse::PetscSession petsc;
  const std::string file = std::string(argv[1]) + "/capsule_shear_quick.toml";
  const auto config = immerse::apply_scenario(immerse::run_schema().parse_file(file));
  immerse::Simulation sim(config);
  for (int i = 0; i < 2; ++i) sim.advance([](const std::string& message) { std::cerr << message << "\n"; });
  const auto g = immerse::measure(sim.mesh(0), sim.op().membrane_positions(0));
  std::cout << "step " << sim.step() << "  t = " << sim.time() << "  volume " << g.volume << "\n";
  return sim.step() == 2 && std::isfinite(g.volume) && g.volume > 0 ? 0 : 1;
}
