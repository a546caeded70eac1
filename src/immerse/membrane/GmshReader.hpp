#pragma once
// Reads a closed membrane surface from a Gmsh mesh file, ASCII format 2.2 or 4.1 (a UTF-8 byte-order mark allowed).
// Surface elements: type 9 (6-node triangle; Gmsh's order v0 v1 v2 m01 m12 m20 is ours) and type 2 (3-node
// triangle, promoted to a quadratic element with straight-edge midpoints, shared with a neighbouring type-9
// element's mid-side node when there is one). Other element types (points, lines, ...) are ignored and so are
// nodes no triangle uses. The result is checked with validate_closed_mesh (messages name the file and the
// Gmsh ids) after orient_outward, so a consistently but inward-oriented surface is accepted and flipped.
// Verified by the tests GmshReader.* (each supported form and each defect),
// RobustnessCorpus.MeshFilesReadOrAreRefusedWithOneLine and Tutorials.CellFromGmshDeformsLikeTheGeneratedCell.
#include <istream>
#include <string>

#include "immerse/membrane/Mesh.hpp"

namespace immerse {

/// Reads and validates `path`; InputError naming the file and the defect otherwise.
Mesh read_gmsh(const std::string& path);
/// Same from a stream; `label` names the source in messages.
Mesh read_gmsh(std::istream& in, const std::string& label);

}  // namespace immerse
