#pragma once
// A verification study: a named numerical experiment that measures quantities (errors,
// convergence orders, residuals) and compares each with what the method must achieve.
// `immerse verify <name> [--quick]` runs one; the test suite runs every quick form.
#include <functional>
#include <ostream>
#include <string>
#include <vector>

namespace immerse::verify {

/// One measured quantity against its bound.
struct Check {
  std::string what;      ///< e.g. "order of u (L2), space"
  double measured;       ///< the number the study measured
  std::string relation;  ///< "<=" or ">="
  double expected;       ///< the bound
  bool pass() const;
};

struct Study {
  std::string name;
  std::string description;  ///< one line
  std::function<std::vector<Check>(bool quick)> run;
};

/// GoogleTest prints a study parameter by its name.
inline void PrintTo(const Study& s, std::ostream* os) { *os << s.name; }

/// Every study of the program, in the order `immerse verify` lists them.
std::vector<Study> all_studies();

// Each area contributes its studies (defined beside its physics).
std::vector<Study> fluid_studies();
std::vector<Study> membrane_studies();
std::vector<Study> coupling_studies();
std::vector<Study> integrator_studies();

}  // namespace immerse::verify
