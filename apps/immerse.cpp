// immerse: implicit immersed-boundary simulation of elastic membranes in 3D incompressible flow.
#include <CLI/CLI.hpp>
#include <fcntl.h>
#include <unistd.h>

#include <csignal>
#include <cstdio>
#include <filesystem>
#include <iostream>

#include "immerse/cli/RunCommand.hpp"
#include "immerse/core/Error.hpp"
#include "immerse/io/Provenance.hpp"
#include "immerse/timestep/PetscSession.hpp"
#include "immerse/verify/StudyRunner.hpp"

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

namespace {

/// The bundled scenarios: the installed copy next to an installed program (PREFIX/share/immerse/scenarios), else
/// the source tree's.
std::filesystem::path bundled_scenarios() {
  std::error_code ec;
  const auto exe = std::filesystem::read_symlink("/proc/self/exe", ec);
  if (!ec) {
    const auto installed = exe.parent_path() / IMMERSE_INSTALLED_SCENARIOS;
    if (std::filesystem::is_directory(installed, ec)) return installed.lexically_normal();
  }
  return std::filesystem::path(IMMERSE_SOURCE_DIR) / "scenarios";
}

/// A standard output that was closed (`| head`) is not an error of the command: what is left goes nowhere.
void silence_closed_stdout() {
  if (!std::cout || std::fflush(stdout) != 0) {
    std::cout.clear();
    std::clearerr(stdout);
    if (const int null = open("/dev/null", O_WRONLY); null >= 0) dup2(null, STDOUT_FILENO);
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"immerse " IMMERSE_VERSION
               ": implicit immersed-boundary simulation of elastic membranes (capsules, red blood cells)\n"
               "in 3D incompressible flow (MAC-grid Navier-Stokes, 6-node curved membrane elements,\n"
               "Jacobian-free Newton-Krylov membrane update)."};
  app.set_version_flag("--version", std::string("immerse ") + IMMERSE_VERSION);
  app.require_subcommand(1);

  immerse::CommandLine run_opts;
  bool help_config = false;
  auto* run = app.add_subcommand("run", "Run the experiment described by a TOML file");
  run->add_option("file", run_opts.file, "Configuration (e.g. scenarios/capsule_shear_quick.toml)");
  run->add_option("--set", run_opts.sets, "Override a key: --set scenario.G=0.05 (repeatable; dotted names as in the file)");
  run->add_option("--out", run_opts.out, "Output folder (diagnostics.csv, config.resolved.toml, ParaView frames, checkpoint.h5)")
      ->capture_default_str();
  auto* restart = run->add_option("--restart", run_opts.restart,
                                  "Continue from a checkpoint written by the same configuration (in its folder: "
                                  "continues that run's files)");
  run->add_flag("--overwrite", run_opts.overwrite,
                "Replace the run already in the --out folder (its files are removed first; other files are kept)");
  run->add_flag("--verbose", run_opts.verbose,
                "Also print the whole resolved configuration (always saved as OUT/config.resolved.toml)");
  run->add_flag("--help-config", help_config, "List every configuration key with its default, range and meaning");
  auto* scenarios = app.add_subcommand("scenarios", "List the bundled scenario files");

  auto* verify = app.add_subcommand("verify", "Run a verification study (no NAME: list them; 'all': run every study)");
  std::string study;
  bool quick = false;
  verify->add_option("name", study, "Study to run");
  verify->add_flag("--quick", quick, "Use the small size the test suite uses");

  try {
    app.parse(argc, argv);
    run_opts.command_line = immerse::io::Provenance::quote_command_line(argc, argv);
    run_opts.program = argv[0];
  } catch (const CLI::ParseError& e) {
    if (e.get_exit_code() == 0) return app.exit(e);  // --help, --version
    std::cerr << "immerse: error: " << e.what() << " (see immerse --help)\n";
    return 2;
  }
  try {
    if (*scenarios) {
      immerse::list_scenarios(bundled_scenarios(), std::cout);
      return 0;
    }
    if (*run && help_config) {
      immerse::print_config_help(std::cout);
      return 0;
    }
    if (*run && run_opts.file.empty()) throw immerse::InputError("run: a configuration FILE.toml is required");
    if (*run && restart->count() > 0 && run_opts.restart.empty())
      throw immerse::InputError(
          "--restart: an empty name was given: must name a checkpoint file (e.g. out/checkpoint.h5)");
    immerse::PetscSession petsc;
    if (*run) {
      const int status = immerse::run_command(run_opts, std::cout, std::cerr);
      // The outcome is decided and reported: a late stop request must not turn it into death by signal.
      for (int sig : {SIGINT, SIGTERM, SIGHUP, SIGQUIT, SIGPIPE}) std::signal(sig, SIG_IGN);
      silence_closed_stdout();
      return status;
    }
    if (*verify) {
      std::signal(SIGPIPE, SIG_IGN);  // `immerse verify NAME | head -1`: the study still ends with its verdict
      const int status = run_verify(study, quick);
      silence_closed_stdout();
      return status;
    }
  } catch (const immerse::InputError& e) {
    std::cerr << "immerse: error: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "immerse: fatal: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
