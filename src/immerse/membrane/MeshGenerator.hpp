#pragma once
// Quadratic triangle meshes of the unit sphere (paper Fig. 1a): a base polyhedron whose triangles are split
// 1 -> 4 `level` times, every new vertex projected onto the sphere; each resulting triangle then becomes a
// 6-node element whose mid-side nodes are projected onto the sphere too.
//   icosahedral: 20·4^level elements, 10·4^(level+1) + 2 nodes (level 2: 642/320, 3: 2,562/1,280, 4: 10,242/5,120)
//   octahedral:   8·4^level elements,  4·4^(level+1) + 2 nodes (level 3: 1,026/512, 4: 4,098/2,048, 5: 16,386/8,192)
// Verified by: the study mesh_counts (node and element counts, every mesh valid) and the tests MeshGenerator.*.
#include "immerse/membrane/Mesh.hpp"

namespace immerse {

/// Unit sphere from the icosahedron; InputError naming "mesh.level" unless 0 <= level <= 6.
Mesh icosahedral_sphere(int level);
/// Unit sphere from the octahedron; InputError naming "mesh.level" unless 0 <= level <= 7.
Mesh octahedral_sphere(int level);

}  // namespace immerse
