#!/usr/bin/python3
"""Record Gmsh's reference nodes and Lagrange shape functions for every element type.

Writes tests/data/gmsh_lagrange_reference.json, the outside oracle of
tests/mesh/reference_nodes_test.cpp and tests/mesh/lagrange_basis_test.cpp.

Run with the Debian Gmsh 4.8.4 Python API:  /usr/bin/python3 scripts/make_gmsh_reference_data.py

For each id 1..140 that gmsh.model.mesh.getElementProperties accepts it records the name,
dimension, order, node count and reference node coordinates (3 per node, unused ones 0).
For the Lagrange families (not the order-0 one-node types, polygons, Xfem) it also records
gmsh.model.mesh.getBasisFunctions(type, points, "Lagrange") at a few seeded random points
inside the reference element, and "gmsh_kronecker_error" = max |N_i(node_j) - delta_ij| of
Gmsh's own functions at its own nodes: Gmsh builds them from monomials, so at high orders
that error (up to 0.1 for 1000-node hexahedra) is the accuracy of its values, and the tests
compare with a tolerance derived from it. Ids Gmsh rejects are listed with its message.
"""
import json
import os
import sys

import gmsh
import numpy as np

FAMILIES = {"Line": "line", "Triangle": "triangle", "Quadrilateral": "quadrangle",
            "Tetrahedron": "tetrahedron", "Hexahedron": "hexahedron", "Prism": "prism",
            "Pyramid": "pyramid", "Point": "point"}
NON_LAGRANGE_WORDS = ("Xfem", "Border", "Child", "Mini", "Polygon", "Polyhedron", "Trihedron")


def random_points(family, n, rng):
    """n points strictly inside Gmsh's reference element of the family, as (n, 3)."""
    u = rng.uniform(0.02, 0.98, size=(n, 3))
    if family == "point":
        return np.zeros((n, 3))
    if family == "line":
        u[:, 0] = 2 * u[:, 0] - 1
        u[:, 1:] = 0
    elif family == "quadrangle":
        u[:, :2] = 2 * u[:, :2] - 1
        u[:, 2] = 0
    elif family == "hexahedron":
        u = 2 * u - 1
    elif family in ("triangle", "prism"):
        flip = u[:, 0] + u[:, 1] > 1
        u[flip, :2] = 1 - u[flip, :2]
        u[:, 2] = 0 if family == "triangle" else 2 * u[:, 2] - 1
    elif family == "tetrahedron":
        e = -np.log(rng.uniform(0.05, 1.0, size=(n, 4)))
        u = (e / e.sum(axis=1, keepdims=True))[:, :3]
    elif family == "pyramid":
        z = 0.95 * u[:, 2]
        u = np.stack([(2 * u[:, 0] - 1) * (1 - z), (2 * u[:, 1] - 1) * (1 - z), z], axis=1)
    return u


def main():
    out_path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests", "data",
                            "gmsh_lagrange_reference.json")
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    rng = np.random.default_rng(20240601)
    types, rejected = [], []
    for t in range(1, 141):
        try:
            name, dim, order, num_nodes, coords, num_primary = \
                gmsh.model.mesh.getElementProperties(t)
        except Exception as e:  # Gmsh raises for ids it cannot build
            rejected.append({"id": t, "gmsh_error": str(e)})
            continue
        c = np.zeros((num_nodes, 3))
        if num_nodes and dim:  # the point type gives one coordinate, 0
            c[:, :dim] = np.array(coords).reshape(num_nodes, dim)
        entry = {"id": t, "name": name, "dim": dim, "order": order, "num_nodes": num_nodes,
                 "num_primary_nodes": num_primary, "nodes": c.flatten().tolist()}
        family = FAMILIES.get(name.split()[0])
        lagrange = (family is not None and num_nodes > 0 and (order >= 1 or family == "point")
                    and not any(w in name for w in NON_LAGRANGE_WORDS))
        if lagrange:
            npts = 2 if num_nodes > 200 else 4
            pts = random_points(family, npts, rng)
            _, values, _ = gmsh.model.mesh.getBasisFunctions(t, pts.flatten().tolist(),
                                                             "Lagrange")
            _, at_nodes, _ = gmsh.model.mesh.getBasisFunctions(t, c.flatten().tolist(),
                                                               "Lagrange")
            kron = np.abs(np.array(at_nodes).reshape(num_nodes, num_nodes) -
                          np.eye(num_nodes)).max()
            entry.update({"family": family, "points": pts.flatten().tolist(),
                          "values": list(values), "gmsh_kronecker_error": float(kron)})
        types.append(entry)
    version = gmsh.option.getString("General.Version")
    gmsh.finalize()
    data = {"generator": "scripts/make_gmsh_reference_data.py",
            "gmsh_version": version,
            "layout": "nodes: num_nodes x 3; points: #points x 3; values: #points x num_nodes, "
                      "row-major",
            "types": types, "rejected": rejected}
    with open(out_path + ".tmp", "w") as f:
        json.dump(data, f, separators=(",", ":"))
        f.write("\n")
    os.replace(out_path + ".tmp", out_path)
    print(f"{out_path}: {len(types)} types, {len(rejected)} rejected", file=sys.stderr)


if __name__ == "__main__":
    main()
