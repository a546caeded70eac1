// immerse: implicit immersed-boundary simulation of elastic membranes in 3D incompressible flow.
#include <CLI/CLI.hpp>
#include <iostream>

#include "immerse/core/Error.hpp"
#include "immerse/timestep/PetscSession.hpp"
#include "immerse/verify/Runner.hpp"

namespace {

int run_verify(const std::string& name, bool quick) {
  using namespace immerse::verify;
  if (name.empty()) {
    list_studies(std::cout);
    return 0;
  }
  bool ok = true;
  if (name == "all") {
    for (const auto& s : all_studies()) ok = run_study(s, quick, std::cout) && ok;
  } else {
    ok = run_study(find_study(name), quick, std::cout);
  }
  return ok ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"immerse " IMMERSE_VERSION
               ": implicit immersed-boundary simulation of elastic membranes (capsules, red blood cells)\n"
               "in 3D incompressible flow (MAC-grid Navier-Stokes, 6-node curved membrane elements,\n"
               "Jacobian-free Newton-Krylov membrane update)."};
  app.set_version_flag("--version", std::string("immerse ") + IMMERSE_VERSION);
  app.require_subcommand(1);

  auto* verify = app.add_subcommand("verify", "Run a verification study (no NAME: list them; 'all': run every study)");
  std::string study;
  bool quick = false;
  verify->add_option("name", study, "Study to run");
  verify->add_flag("--quick", quick, "Use the small size the test suite uses");

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    return app.exit(e) == 0 ? 0 : 2;
  }
  try {
    immerse::PetscSession petsc;
    if (*verify) return run_verify(study, quick);
  } catch (const immerse::InputError& e) {
    std::cerr << "immerse: error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "immerse: fatal: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
