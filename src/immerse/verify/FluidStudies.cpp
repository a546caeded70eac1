#include "immerse/verify/Study.hpp"

namespace immerse::verify {

std::vector<Study> fluid_studies() { return {}; }

}  // namespace immerse::verify
