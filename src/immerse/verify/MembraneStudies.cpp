#include "immerse/verify/MeshStudies.hpp"
#include "immerse/verify/Study.hpp"

namespace immerse::verify {

std::vector<Study> membrane_studies() { return mesh_studies(); }

}  // namespace immerse::verify
