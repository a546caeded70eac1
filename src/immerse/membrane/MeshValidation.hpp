#pragma once
// Checks that a Mesh is a usable closed membrane (paper §3: the surface of a capsule):
//   every coordinate finite; every element index a node; every node used by some element;
//   no element with a repeated node, zero area (vertex triangle area <= 1e-12 × longest edge²) or an
//   inverted curved shape (the surface Jacobian X_ξ × X_η of eq. 38 reversing against the vertex normal
//   at a node or quadrature point);
//   every vertex edge shared by exactly two elements (one: open surface; more: non-manifold), traversed
//   in opposite directions by them (consistent orientation) and with the same mid-side node;
//   one connected surface (a file of two cells is refused, naming the count);
//   positive enclosed volume (elements counter-clockwise seen from outside).
// Failures throw a one-line InputError: "mesh <label>: element 17 (gmsh id 123) has zero area".
// Verified by the tests MeshValidation.* and GmshReader.Rejects* (one defect each), and the study mesh_counts
// (every generated mesh valid).
#include <cstddef>
#include <string>
#include <vector>

#include "immerse/membrane/Mesh.hpp"

namespace immerse {

/// Ids under which the user knows elements and nodes (e.g. Gmsh's tags), used in messages; empty = none.
struct MeshIds {
  std::vector<std::size_t> elements, nodes;
};

void validate_closed_mesh(const Mesh& mesh, const std::string& label, const MeshIds& ids = {});

/// Flips every element (swaps vertices 1 and 2 and the mid-side nodes accordingly) when the signed
/// enclosed volume is negative. Needs valid node indices; meaningful for a consistently oriented mesh.
void orient_outward(Mesh& mesh);

}  // namespace immerse
