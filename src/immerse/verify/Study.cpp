#include "immerse/verify/Study.hpp"

#include <cmath>

namespace immerse::verify {

bool Check::pass() const {
  if (!std::isfinite(measured)) return false;
  return relation == "<=" ? measured <= expected : measured >= expected;
}

std::vector<Study> all_studies() {
  std::vector<Study> all;
  for (auto&& part : {fluid_studies(), membrane_studies(), coupling_studies(), integrator_studies()})
    all.insert(all.end(), part.begin(), part.end());
  return all;
}

}  // namespace immerse::verify
