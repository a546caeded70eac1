#include "immerse/verify/MechanicsStudies.hpp"
#include "immerse/verify/MeshStudies.hpp"
#include "immerse/verify/Study.hpp"

namespace immerse::verify {

std::vector<Study> membrane_studies() {
  auto all = mesh_studies();
  auto mech = mechanics_studies();
  all.insert(all.end(), mech.begin(), mech.end());
  return all;
}

}  // namespace immerse::verify
