#include "immerse/verify/Study.hpp"

namespace immerse::verify {

std::vector<Study> membrane_studies() { return {}; }

}  // namespace immerse::verify
