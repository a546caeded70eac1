#include "immerse/verify/Study.hpp"

namespace immerse::verify {

std::vector<Study> coupling_studies() { return {}; }

}  // namespace immerse::verify
