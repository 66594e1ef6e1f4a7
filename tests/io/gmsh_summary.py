#!/usr/bin/python3
"""Reads mesh files with the Gmsh Python API and writes what Gmsh sees as JSON, so that
quadval's tests can compare their own reading (and writing) with Gmsh's.

Usage: gmsh_summary.py OUT.json MESH.msh [MESH.msh ...]
Output: {MESH: {"nodes": {tag: [x, y, z]}, "elements": {tag: [type, [node tags]]}}}, or
{MESH: {"error": Gmsh's message}} for a file Gmsh refused.
Exit code 77 (and a message) when the gmsh module is missing.
"""
import json
import sys

try:
    import gmsh
except ImportError as e:
    print(f"gmsh Python module not available: {e}", file=sys.stderr)
    sys.exit(77)


def summary(path):
    gmsh.clear()
    gmsh.open(path)
    tags, coords, _ = gmsh.model.mesh.getNodes()
    nodes = {str(int(t)): [coords[3 * i], coords[3 * i + 1], coords[3 * i + 2]] for i, t in enumerate(tags)}
    elements = {}
    types, elem_tags, node_tags = gmsh.model.mesh.getElements()
    for etype, etags, entags in zip(types, elem_tags, node_tags):
        _, _, _, num_nodes, _, _ = gmsh.model.mesh.getElementProperties(etype)
        for i, t in enumerate(etags):
            elements[str(int(t))] = [int(etype), [int(n) for n in entags[i * num_nodes:(i + 1) * num_nodes]]]
    return {"nodes": nodes, "elements": elements}


def start():
    gmsh.initialize(["-noenv"], readConfigFiles=False)
    gmsh.option.setNumber("General.Terminal", 1)
    gmsh.option.setNumber("General.Verbosity", 2)


def main():
    out, meshes = sys.argv[1], sys.argv[2:]
    start()
    result = {}
    for m in meshes:
        try:
            result[m] = summary(m)
        except Exception as e:  # Gmsh's own message, for the test to judge
            result[m] = {"error": str(e)}
            # A failed open leaves Gmsh in a state where later files read empty: restart it.
            gmsh.finalize()
            start()
    gmsh.finalize()
    with open(out, "w") as f:
        json.dump(result, f)


if __name__ == "__main__":
    main()
