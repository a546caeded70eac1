#pragma once
// The Taylor shape parameter of §4.2.1: D_xz = (L - B)/(L + B), with L and B the maximum and minimum radial
// distances from the centroid of the membrane's section by the plane of shear (the x-z plane through the
// centroid). The section is the polygon where the plane cuts the four flat sub-triangles of each curved element.
// (The inclination is taken from the principal axes instead: the direction of L jumps from node to node as the
// membrane tank-treads.)
// Verified by the test Tutorials.CapsuleInYourShearDeformsAsTheSmallDeformationTheory (D_xz within 15 % of 25G/4).
#include <vector>

#include "immerse/membrane/Mesh.hpp"

namespace immerse {

struct ShearPlaneProfile {
  double L = 0, B = 0;
  double D_xz = 0;
};

ShearPlaneProfile shear_plane_profile(const Mesh& mesh, const std::vector<Vec3>& X, const Vec3& centroid);

}  // namespace immerse
