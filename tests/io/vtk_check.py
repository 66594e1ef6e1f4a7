#!/usr/bin/python3
"""VTK (and Gmsh) as oracles for quadval's VTU output.

  vtk_check.py refs OUT.json
      Gmsh's reference node coordinates {type id: [[u, v, w], ...]} for every element type
      gmsh.model.mesh.getElementProperties knows (exit 77 without gmsh).
  vtk_check.py check FILE.vtu EXPECT.json
      Reads FILE.vtu with vtkXMLUnstructuredGridReader. EXPECT.json lists, per cell,
      {"vtk_type", "family", "A" (3x3), "b" (3), "geometric", "tag"}: the cell must have
      that VTK type and, when geometric, each of its points must equal A r + b, where r is
      VTK's own parametric coordinate of the point (cell.GetParametricCoords()) mapped onto
      Gmsh's reference element of the family. CellData "element_tag" must equal "tag" and
      "twice_tag" twice that. Prints each failure; exit 0 if none, 1 otherwise, 77 without vtk.
  vtk_check.py obj FILE.obj OUT.json
      Reads FILE.obj with vtkOBJReader and writes {"points": [[x, y, z], ...], "polygons":
      [[i, ...], ...]} (0-based) as VTK sees them, for quadval's OBJ output (exit 77 without vtk).
"""
import json
import sys


def gmsh_refs(out):
    try:
        import gmsh
    except ImportError as e:
        print(f"gmsh Python module not available: {e}", file=sys.stderr)
        sys.exit(77)
    gmsh.initialize(["-noenv"], readConfigFiles=False)
    gmsh.option.setNumber("General.Terminal", 0)
    refs = {}
    for t in range(1, 141):
        try:
            _, dim, _, n, coords, _ = gmsh.model.mesh.getElementProperties(t)
        except Exception:
            continue  # a type Gmsh cannot build (prisms of order >= 3, unused ids)
        if n <= 0:
            continue
        pts = []
        for i in range(n):
            p = [coords[dim * i + k] if k < dim else 0.0 for k in range(3)]
            pts.append(p)
        refs[str(t)] = pts
    gmsh.finalize()
    with open(out, "w") as f:
        json.dump(refs, f)


def to_gmsh_reference(family, xi):
    """VTK parametric coordinates -> Gmsh reference coordinates (lagrange_basis.hpp)."""
    x, y, z = xi
    if family == "point":
        return (0.0, 0.0, 0.0)
    if family == "line":
        return (2 * x - 1, 0.0, 0.0)
    if family in ("triangle", "tetrahedron"):
        return (x, y, z)
    if family == "quadrangle":
        return (2 * x - 1, 2 * y - 1, 0.0)
    if family == "hexahedron":
        return (2 * x - 1, 2 * y - 1, 2 * z - 1)
    if family == "prism":
        return (x, y, 2 * z - 1)
    if family == "pyramid":  # VTK's pyramid is a collapsed hexahedron with its apex at (0, 0, 1)
        return ((1 - z) * (2 * x - 1), (1 - z) * (2 * y - 1), z)
    raise ValueError(family)


def check(vtu, expect_file):
    try:
        import vtk
    except ImportError as e:
        print(f"vtk Python module not available: {e}", file=sys.stderr)
        sys.exit(77)
    expect = json.load(open(expect_file))
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(vtu)
    reader.Update()
    grid = reader.GetOutput()
    failures = []
    if grid.GetNumberOfCells() != len(expect):
        failures.append(f"{grid.GetNumberOfCells()} cells, expected {len(expect)}")
    tags = grid.GetCellData().GetArray("element_tag")
    twice = grid.GetCellData().GetArray("twice_tag")
    if tags is None or twice is None:
        failures.append("missing CellData element_tag or twice_tag")
    for i, e in enumerate(expect[: grid.GetNumberOfCells()]):
        name = f"cell {i} (Gmsh type {e['gmsh_type']})"
        if grid.GetCellType(i) != e["vtk_type"]:
            failures.append(f"{name}: VTK type {grid.GetCellType(i)}, expected {e['vtk_type']}")
            continue
        if tags is not None and (tags.GetValue(i) != e["tag"] or twice.GetValue(i) != 2.0 * e["tag"]):
            failures.append(f"{name}: element_tag {tags.GetValue(i)}, expected {e['tag']}")
        if not e["geometric"]:
            continue
        cell = grid.GetCell(i)
        pc = cell.GetParametricCoords()
        n = cell.GetNumberOfPoints()
        A, b = e["A"], e["b"]
        for j in range(n):
            r = to_gmsh_reference(e["family"], (pc[3 * j], pc[3 * j + 1], pc[3 * j + 2]))
            want = [sum(A[d][k] * r[k] for k in range(3)) + b[d] for d in range(3)]
            got = cell.GetPoints().GetPoint(j)
            if max(abs(want[d] - got[d]) for d in range(3)) > 1e-9:
                failures.append(f"{name}: point {j} at {tuple(got)}, VTK's parametric point maps to {tuple(want)}")
                break
    for f in failures[:50]:
        print(f)
    print(f"{grid.GetNumberOfCells()} cells checked, {len(failures)} failures")
    sys.exit(1 if failures else 0)


def obj(path, out):
    try:
        import vtk
    except ImportError as e:
        print(f"vtk Python module not available: {e}", file=sys.stderr)
        sys.exit(77)
    r = vtk.vtkOBJReader()
    r.SetFileName(path)
    r.Update()
    data = r.GetOutput()
    points = [list(data.GetPoint(i)) for i in range(data.GetNumberOfPoints())]
    polygons = []
    for c in range(data.GetNumberOfCells()):
        ids = data.GetCell(c).GetPointIds()
        polygons.append([ids.GetId(k) for k in range(ids.GetNumberOfIds())])
    with open(out, "w") as f:
        json.dump({"points": points, "polygons": polygons}, f)


if __name__ == "__main__":
    if sys.argv[1] == "refs":
        gmsh_refs(sys.argv[2])
    elif sys.argv[1] == "obj":
        obj(sys.argv[2], sys.argv[3])
    else:
        check(sys.argv[2], sys.argv[3])
