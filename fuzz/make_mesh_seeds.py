#!/usr/bin/env python3
"""Writes the seed meshes of fuzz/corpus/mesh/: the octahedron (8 triangles) as a closed membrane, in Gmsh
ASCII formats 2.2 and 4.1, with 6-node triangles (mid-side nodes on the unit sphere) and with 3-node triangles.
Usage: python3 fuzz/make_mesh_seeds.py fuzz/corpus/mesh"""
import itertools
import math
import sys

AXES = {(1, 0, 0): 1, (-1, 0, 0): 2, (0, 1, 0): 3, (0, -1, 0): 4, (0, 0, 1): 5, (0, 0, -1): 6}


def octahedron(six_node):
    nodes = {tag: p for p, tag in AXES.items()}
    mids = {}
    triangles = []
    for sx, sy, sz in itertools.product((1, -1), repeat=3):
        v = [AXES[(sx, 0, 0)], AXES[(0, sy, 0)], AXES[(0, 0, sz)]]
        if sx * sy * sz < 0:
            v[1], v[2] = v[2], v[1]  # counter-clockwise seen from outside
        if six_node:
            for a, b in ((v[0], v[1]), (v[1], v[2]), (v[2], v[0])):
                key = (min(a, b), max(a, b))
                if key not in mids:
                    m = [(x + y) / 2 for x, y in zip(nodes[a], nodes[b])]
                    r = math.sqrt(sum(c * c for c in m))
                    mids[key] = len(nodes) + 1
                    nodes[mids[key]] = tuple(c / r for c in m)
                v.append(mids[key])
        triangles.append(v)
    return nodes, triangles


def v22(nodes, triangles):
    etype = 9 if len(triangles[0]) == 6 else 2
    out = ["$MeshFormat", "2.2 0 8", "$EndMeshFormat", "$Nodes", str(len(nodes))]
    out += [f"{t} {p[0]:.17g} {p[1]:.17g} {p[2]:.17g}" for t, p in sorted(nodes.items())]
    out += ["$EndNodes", "$Elements", str(len(triangles))]
    out += [f"{e + 1} {etype} 2 0 1 " + " ".join(map(str, t)) for e, t in enumerate(triangles)]
    out += ["$EndElements"]
    return "\n".join(out) + "\n"


def v41(nodes, triangles):
    etype = 9 if len(triangles[0]) == 6 else 2
    n, m = len(nodes), len(triangles)
    out = ["$MeshFormat", "4.1 0 8", "$EndMeshFormat", "$Nodes", f"1 {n} 1 {n}", f"2 1 0 {n}"]
    out += [str(t) for t in sorted(nodes)]
    out += [f"{p[0]:.17g} {p[1]:.17g} {p[2]:.17g}" for _, p in sorted(nodes.items())]
    out += ["$EndNodes", "$Elements", f"1 {m} 1 {m}", f"2 1 {etype} {m}"]
    out += [f"{e + 1} " + " ".join(map(str, t)) for e, t in enumerate(triangles)]
    out += ["$EndElements"]
    return "\n".join(out) + "\n"


if __name__ == "__main__":
    folder = sys.argv[1]
    for six in (True, False):
        mesh = octahedron(six)
        for name, writer in (("v22", v22), ("v41", v41)):
            with open(f"{folder}/octahedron_{name}_{6 if six else 3}node.msh", "w") as f:
                f.write(writer(*mesh))
