#pragma once
// The Taylor shape parameter of §4.2.1: D_xz = (L - B)/(L + B), with L and B the maximum and minimum radial
// distances from the centroid of the membrane's section by the plane of shear (the x-z plane through the
// centroid). The section is that of the curved elements (eq. 38): each element's parent triangle is divided into
// kDivisions² flat triangles at points of the curved surface, and the plane cuts their edges. (Cut through the four
// flat sub-triangles of each element instead, a sphere of 642 nodes has D_xz = 1.7e-3 at rest, the deformation of
// G = 0.0003; through the curved elements 8.6e-5, and 1.9e-6 with 10,242 nodes.) The maximum and the minimum take
// any node-scale roughness of the surface at full weight; the equivalent ellipsoid's D_ellipsoid (diagnostics.csv)
// does not.
// (The inclination is taken from the principal axes instead: the direction of L jumps from node to node as the
// membrane tank-treads.)
// Verified by the tests ShearPlaneProfile.* (tests/test_shear_plane_profile.cpp: a sphere and an ellipsoid of known
// axes) and Tutorials.CapsuleInYourShearDeformsAsTheSmallDeformationTheory (D_xz within 15 % of 25G/4).
#include <vector>

#include "immerse/membrane/Mesh.hpp"

namespace immerse {

struct ShearPlaneProfile {
  /// Flat triangles per side of each element's parent triangle.
  static constexpr int kDivisions = 16;
  double L = 0, B = 0;
  double D_xz = 0;
};

ShearPlaneProfile shear_plane_profile(const Mesh& mesh, const std::vector<Vec3>& X, const Vec3& centroid);

}  // namespace immerse
