// PETSc options of the implicit schemes' solvers, given in solver.petsc_options or in the environment variable
// PETSC_OPTIONS, with the real program: options read while solving (-snes_converged_reason, -ksp_converged_reason)
// and at the end (-log_view, -options_left) work from both; an option nothing used stops the run after its first
// solve with status 2, naming the option and where it came from.
#include <gtest/gtest.h>

#include <algorithm>

#include "test_run_support.hpp"

using namespace immerse::testing;

namespace {

struct Source {
  const char* name;
  bool environment;  ///< PETSC_OPTIONS, else solver.petsc_options
};

void PrintTo(const Source& s, std::ostream* os) { *os << s.name; }

class PetscOptionsTest : public ::testing::TestWithParam<Source> {
 protected:
  /// One step of the small run (JFNK) with `options` from the source under test; the other source is empty.
  RunResult run(const std::string& options, const std::vector<std::string>& extra_sets = {}) {
    auto sets = small_membrane_sets(1);
    sets.insert(sets.end(), extra_sets.begin(), extra_sets.end());
    std::vector<std::string> env{"PETSC_OPTIONS"};
    if (GetParam().environment)
      env = {"PETSC_OPTIONS=" + options};
    else
      sets.push_back("solver.petsc_options=\"" + options + "\"");
    return run_immerse(run_args(scenario_file("oscillating_membrane_quick.toml"), out(), sets), dir_ / "run", env);
  }
  fs::path out() const { return dir_ / "out"; }
  ScratchDir dir_{"petsc_options"};
};

bool has_line_starting(const std::string& text, const std::string& start) {
  return text.rfind(start, 0) == 0 || text.find("\n" + start) != std::string::npos;
}

TEST_P(PetscOptionsTest, ConvergedReasonsArePrinted) {
  const auto r = run("-snes_converged_reason -ksp_converged_reason");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err, "");
  EXPECT_TRUE(has_line_starting(r.out, "Nonlinear solve converged due to CONVERGED_FNORM_RELATIVE iterations "))
      << r.out;
  EXPECT_TRUE(has_line_starting(r.out, "  Linear solve converged due to ")) << r.out;
}

TEST_P(PetscOptionsTest, MonitorsAndViewArePrinted) {
  const auto r = run("-snes_monitor -ksp_monitor -snes_view");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("SNES Function norm"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("KSP Residual norm"), std::string::npos) << r.out;
  EXPECT_TRUE(has_line_starting(r.out, "SNES Object: ")) << r.out;
}

// The table of -log_view has a row per phase of the step profile the run prints, and the nonlinear solver's.
TEST_P(PetscOptionsTest, LogViewListsTheImmerseEvents) {
  const auto r = run("-log_view");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("PETSc Performance Summary"), std::string::npos) << r.out;
  for (const char* event :
       {"MembraneForces ", "ContactForces ", "Spreading ", "FluidStep ", "Interpolation ", "ImplicitResidual ",
        "SNESSolve "})
    EXPECT_TRUE(has_line_starting(r.out, event)) << event << " missing from\n" << r.out;
}

// The options the solver used count as used in PETSc's own report at the end.
TEST_P(PetscOptionsTest, OptionsLeftFindsNoUnusedOption) {
  const auto r = run("-options_left -ksp_gmres_restart 40 -snes_monitor");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("-ksp_gmres_restart 40\n"), std::string::npos) << r.out;  // in PETSc's option table
  EXPECT_NE(r.out.find("There are no unused options."), std::string::npos) << r.out;
}

// Reported after the first solve (its converged reason is printed first): status 2, one line naming the option and its
// source, and the folder the run had created removed again.
TEST_P(PetscOptionsTest, UnusedOptionStopsTheRunAfterTheFirstSolve) {
  const auto r = run("-snes_converged_reason -snes_bogus 3");
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_TRUE(has_line_starting(r.out, "Nonlinear solve converged due to ")) << r.out;
  const std::string source = GetParam().environment ? "PETSC_OPTIONS" : "solver.petsc_options";
  EXPECT_EQ(r.err.rfind("immerse: error: " + source + ": option -snes_bogus was used by none of the 'jfnk' solver's "
                        "PETSc objects (SNES, KSP, PC, MatMFFD) in its first solve",
                        0),
            0u)
      << r.err;
  EXPECT_EQ(std::count(r.err.begin(), r.err.end(), '\n'), 1) << r.err;
  EXPECT_FALSE(fs::exists(out()));
}

// An option only JFNK has is unused by Anderson's solver.
TEST_P(PetscOptionsTest, KrylovOptionIsUnusedByAnderson) {
  const auto r = run("-ksp_monitor", {"time.scheme=\"anderson\""});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_NE(r.err.find("option -ksp_monitor was used by none of the 'anderson' solver's PETSc objects (SNES only"),
            std::string::npos)
      << r.err;
}

INSTANTIATE_TEST_SUITE_P(Run, PetscOptionsTest,
                         ::testing::Values(Source{"configuration", false}, Source{"environment", true}),
                         [](const auto& p) { return std::string(p.param.name); });

// Both sources at once: solver.petsc_options wins where both give an option; PETSC_OPTIONS may hold options of PETSc
// itself, read when it starts (-malloc_debug).
TEST(PetscOptionsBoth, ConfigurationWinsAndPetscsOwnOptionsCount) {
  ScratchDir dir("petsc_options_both");
  auto sets = small_membrane_sets(1);
  sets.push_back("solver.petsc_options=\"-ksp_gmres_restart 40 -options_left\"");
  const auto r = run_immerse(run_args(scenario_file("oscillating_membrane_quick.toml"), dir / "out", sets),
                             dir / "run", {"PETSC_OPTIONS=-ksp_gmres_restart 30 -malloc_debug -snes_converged_reason"});
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("-ksp_gmres_restart 40\n"), std::string::npos) << r.out;
  EXPECT_EQ(r.out.find("-ksp_gmres_restart 30\n"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("There are no unused options."), std::string::npos) << r.out;
  EXPECT_TRUE(has_line_starting(r.out, "Nonlinear solve converged due to ")) << r.out;
}

// Options from both sources unused: one line naming each under its source.
TEST(PetscOptionsBoth, UnusedOptionsAreNamedUnderTheirSource) {
  ScratchDir dir("petsc_options_both_unused");
  auto sets = small_membrane_sets(1);
  sets.push_back("solver.petsc_options=\"-snes_bogus 3 -snes_other\"");
  const auto r = run_immerse(run_args(scenario_file("oscillating_membrane_quick.toml"), dir / "out", sets),
                             dir / "run", {"PETSC_OPTIONS=-ksp_bogus"});
  EXPECT_EQ(r.status, 2) << r.err;
  EXPECT_EQ(r.err.rfind("immerse: error: solver.petsc_options: options -snes_bogus, -snes_other; PETSC_OPTIONS: "
                        "option -ksp_bogus were used by none of the 'jfnk' solver's PETSc objects",
                        0),
            0u)
      << r.err;
}

}  // namespace
