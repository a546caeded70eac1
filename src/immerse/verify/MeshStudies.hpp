#pragma once
// Verification studies of the membrane meshes, shapes and curved-element geometry:
//   mesh_counts      node/element counts of the generated spheres (paper §4: 4,098/2,048, 10,242/5,120,
//                    16,386/8,192) and that every generated mesh passes validate_closed_mesh
//   sphere_geometry  order of the area and volume errors of the curved unit sphere, ellipsoid (eq. 43) volume
//                    and principal semi-axes, red-blood-cell (eq. 45) volume and area against the reference values
#include <vector>

#include "immerse/verify/Study.hpp"

namespace immerse::verify {

std::vector<Study> mesh_studies();

}  // namespace immerse::verify
