#pragma once
#include <iosfwd>
#include <string>

#include "immerse/verify/Study.hpp"

namespace immerse::verify {

/// The study called `name`; throws InputError naming the known studies if there is none.
Study find_study(const std::string& name);

/// Runs a study, prints one line per check (measured, relation, expected, PASS/FAIL) and returns
/// true when every check passes.
bool run_study(const Study& study, bool quick, std::ostream& out);

/// Prints the name and description of every study.
void list_studies(std::ostream& out);

}  // namespace immerse::verify
