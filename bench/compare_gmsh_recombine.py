#!/usr/bin/python3
"""Side by side: `quadval recombine` (Blossom-Quad, exact matching by
src/recombine/blossom_solver.cpp) and Gmsh 4.8.4's Blossom
recombination (Mesh.RecombinationAlgorithm = 1, default Mesh.Smoothing and topology
optimisation) on the same triangle meshes. Prints one row per tool and mesh: quads, triangles
left, eta_min, eta_mean, % interior vertices of degree 4, time (median of --runs), peak memory.

Route for Gmsh (why): gmsh.model.mesh.recombine() on a mesh *loaded from a .msh file* skips
Gmsh's smoothing (a discrete surface has no parametrisation to move nodes in), which gives
eta_min 0.061 on rect-sin-a6 instead of Gmsh's real 0.422. So each case is built as a
geometry inside Gmsh, triangulated by Gmsh (Mesh.Algorithm 6; Mesh.RecombineAll on for the
1D step only, so the triangle count is even), the triangle mesh is written for quadval, and
then gmsh.model.mesh.recombine() runs on that same in-memory model, which still has its CAD
surface: this is Gmsh's own pipeline (Blossom + smoothing + topology optimisation) and
reproduces the data README exactly on rect-sin-a6 (1,916 triangles, the same nodes as
rect-sin-a6.msh -> 932 quads, eta_min 0.422, eta_mean 0.754, 73.2% degree 4). The two Gmsh
times are its triangulation (not compared) and its recombination (the `time s` column).

eta (Paper I eq. 3) and the degree statistics are computed here, in numpy, from each tool's
output mesh, so both rows are measured the same way. `time s` is wall time, `CPU s` the
process CPU time (user + system; quadval's includes its OpenMP threads), the fairer figure when
other jobs share the machine.

    /usr/bin/python3 bench/compare_gmsh_recombine.py --quadval build/quadval
    /usr/bin/python3 bench/compare_gmsh_recombine.py --quadval build/quadval \
        --cases rect-sin-a6 uniform-10k-a6 square-hole-35k
    /usr/bin/python3 bench/compare_gmsh_recombine.py --algo blossom lookahead   # both routes

Cases: rect-sin-a6 (../shared/data/tri/rect-sin.geo), uniform-N-a6 (unit square, uniform size,
about N triangles; N = 10k reproduces uniform-10k-a6.msh's 10,076), uniform-N-a5 (the same
square triangulated by Gmsh's Delaunay, Mesh.Algorithm 5: fewer equilateral triangles, so
fewer equal costs; see blossom_solver.hpp for why those matter), disk-N-a5 / disk-N-a6 (a
disk of diameter 1, about N triangles, Delaunay or Frontal-Delaunay), box-N-a5 / box-N-a6
(the surface of the unit cube: six faces, as a CAD model has, solved face by face),
square-hole-N (Paper I
section 8.1: the construction of scripts/lookahead_square_hole.py, rebuilt here because Gmsh
needs the geometry). Triangle meshes are cached under /tmp/quadval_recombine_bench/.
"""
import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import time

import numpy as np

import gmsh

HERE = os.path.dirname(os.path.abspath(__file__))
SHARED = os.path.join(HERE, "..", "..", "shared", "data", "tri")
CACHE = "/tmp/quadval_recombine_bench"


def eta_of_quads(xyz, quads):
    """eta (eq. 3) of each quad, corners signed by the quad's diagonal normal."""
    p = xyz[quads]  # (n, 4, 3)
    normal = np.cross(p[:, 2] - p[:, 0], p[:, 3] - p[:, 1])
    worst = np.zeros(len(quads))
    invalid = np.zeros(len(quads), dtype=bool)
    for k in range(4):
        f = p[:, (k + 1) % 4] - p[:, k]
        b = p[:, (k + 3) % 4] - p[:, k]
        c = np.cross(f, b)
        invalid |= np.einsum("ij,ij->i", c, normal) <= 0
        alpha = np.arctan2(np.linalg.norm(c, axis=1), np.einsum("ij,ij->i", f, b))
        worst = np.maximum(worst, np.abs(np.pi / 2 - alpha))
    eta = np.maximum(1 - worst / (np.pi / 2), 0)
    eta[invalid] = 0
    return eta


def degree_stats(num_nodes, elements):
    """Share of interior nodes with 4 elements, over nodes not on the boundary."""
    deg = np.zeros(num_nodes, dtype=np.int64)
    edges = []
    for el in elements:
        k = el.shape[1]
        np.add.at(deg, el.ravel(), 1)
        for i in range(k):
            edges.append(np.sort(np.stack([el[:, i], el[:, (i + 1) % k]], axis=1), axis=1))
    e = np.concatenate(edges)
    uniq, counts = np.unique(e, axis=0, return_counts=True)
    boundary = np.zeros(num_nodes, dtype=bool)
    boundary[uniq[counts == 1].ravel()] = True
    interior = (deg > 0) & ~boundary
    d = deg[interior]
    return 100.0 * np.mean(d == 4), int(d.min()), int(d.max())


def read_with_gmsh(path):
    """Nodes (index by position) and quads/triangles as index arrays."""
    gmsh.open(path)
    return read_model()


def read_model():
    """The current Gmsh model's nodes and 2D quads/triangles, as in read_with_gmsh."""
    tags, coords, _ = gmsh.model.mesh.getNodes()
    xyz = coords.reshape(-1, 3)
    index = np.full(int(tags.max()) + 1, -1, dtype=np.int64)
    index[tags.astype(np.int64)] = np.arange(len(tags))
    quads, tris = [], []
    for t, _, nodes in zip(*gmsh.model.mesh.getElements(2)):
        if t == 3:
            quads.append(index[np.asarray(nodes, dtype=np.int64).reshape(-1, 4)])
        elif t == 2:
            tris.append(index[np.asarray(nodes, dtype=np.int64).reshape(-1, 3)])
    q = np.concatenate(quads) if quads else np.zeros((0, 4), dtype=np.int64)
    t = np.concatenate(tris) if tris else np.zeros((0, 3), dtype=np.int64)
    return xyz, q, t


def summarize(xyz, quads, tris):
    eta = eta_of_quads(xyz, quads) if len(quads) else np.zeros(0)
    els = [a for a in (quads, tris) if len(a)]
    d4, dmin, dmax = degree_stats(len(xyz), els)
    return {"quads": len(quads), "triangles": len(tris),
            "eta_min": float(eta.min()) if len(eta) else 0.0,
            "eta_mean": float(eta.mean()) if len(eta) else 0.0,
            "degree4": d4, "dmin": dmin, "dmax": dmax}


def run_quadval(exe, path, runs, algo="blossom"):
    out = os.path.join(CACHE, "quadval_out.msh")
    report = os.path.join(CACHE, "quadval_report.json")
    times, cpu, rss = [], [], 0
    for _ in range(runs):
        t0 = time.perf_counter()
        r = subprocess.run(["/usr/bin/time", "-f", "%M %U %S", exe, "recombine", path, "-o", out,
                            "--report", report, "-q", "--algo", algo], capture_output=True, text=True)
        times.append(time.perf_counter() - t0)
        if r.returncode != 0:
            sys.exit(f"quadval failed on {path}: {r.stderr}")
        kb, user, system = r.stderr.strip().splitlines()[-1].split()
        rss = max(rss, int(kb))
        cpu.append(float(user) + float(system))
    with open(report) as f:
        rep = json.load(f)
    xyz, q, t = read_with_gmsh(out)
    row = summarize(xyz, q, t)
    row.update(seconds=statistics.median(times), cpu_seconds=statistics.median(cpu),
               recombine_seconds=rep["statistics"]["total_seconds"], rss_mb=rss / 1024)
    return row


def build_rect_sin():
    """Paper I's rectangle with h = 0.1 + 0.08 sin(3x) cos(6y), from the shared .geo."""
    gmsh.open(os.path.join(SHARED, "rect-sin.geo"))


def uniform_model(name, add_shape, h, algorithm):
    """A new model holding one OCC surface (add_shape()), meshed with size h everywhere by
    Gmsh's Delaunay (5) or Frontal-Delaunay (6)."""
    gmsh.option.setNumber("Mesh.Algorithm", algorithm)
    gmsh.model.add(name)
    add_shape()
    gmsh.model.occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMin", h)
    gmsh.option.setNumber("Mesh.MeshSizeMax", h)


def build_uniform(triangles, algorithm=6):
    """Unit square, uniform size: about 2.3 / h^2 triangles for Frontal-Delaunay (6); with
    Delaunay (5), about 2.65 / h^2."""
    h = ((2.3 if algorithm == 6 else 2.65) / triangles) ** 0.5
    uniform_model("square", lambda: gmsh.model.occ.addRectangle(0, 0, 0, 1, 1), h, algorithm)


def build_disk(triangles, algorithm):
    """Unit-diameter disk, uniform size (about 2.5 area / h^2 triangles)."""
    h = ((2.5 * math.pi / 4) / triangles) ** 0.5
    uniform_model("disk", lambda: gmsh.model.occ.addDisk(0.5, 0.5, 0, 0.5, 0.5), h, algorithm)


def build_box(triangles, algorithm):
    """The surface of the unit cube, uniform size: six faces, six components of the dual
    graph, as CAD models give (about 2.3 or 2.65 per face / h^2 triangles, as the square)."""
    h = ((6 * (2.3 if algorithm == 6 else 2.65)) / triangles) ** 0.5
    uniform_model("box", lambda: gmsh.model.occ.addBox(0, 0, 0, 1, 1, 1), h, algorithm)


def build_square_hole(h_min):
    """Paper I section 8.1: unit square minus the disk of radius 0.15 at (0.75, 0.75),
    h = h_min + 4 h_min min(d / 0.3, 1) with d the distance to the boundary (the same
    construction as scripts/lookahead_square_hole.py)."""
    gmsh.model.add("square_hole")
    occ = gmsh.model.occ
    square = occ.addRectangle(0, 0, 0, 1, 1)
    hole = occ.addDisk(0.75, 0.75, 0, 0.15, 0.15)
    occ.cut([(2, square)], [(2, hole)])
    occ.synchronize()
    f = gmsh.model.mesh.field
    dist = f.add("Distance")
    f.setNumbers(dist, "CurvesList", [c for (_, c) in gmsh.model.getEntities(1)])
    f.setNumber(dist, "NumPointsPerCurve", 400)
    th = f.add("Threshold")
    f.setNumber(th, "InField", dist)
    f.setNumber(th, "SizeMin", h_min)
    f.setNumber(th, "SizeMax", 5 * h_min)
    f.setNumber(th, "DistMin", 0.0)
    f.setNumber(th, "DistMax", 0.3)
    f.setAsBackgroundMesh(th)
    gmsh.option.setNumber("Mesh.MeshSizeExtendFromBoundary", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromPoints", 0)
    gmsh.option.setNumber("Mesh.MeshSizeFromCurvature", 0)


def triangulate(build):
    """Fresh model from `build`, triangulated as the shared meshes were made. Returns the
    triangulation time; the model stays loaded (with its geometry) for recombine()."""
    gmsh.clear()
    for name, value in (("Mesh.MeshSizeMin", 0), ("Mesh.MeshSizeMax", 1e22)):
        gmsh.option.setNumber(name, value)
    gmsh.option.setNumber("Mesh.Algorithm", 6)
    build()  # may choose another algorithm
    gmsh.option.setNumber("Mesh.RecombinationAlgorithm", 1)
    t0 = time.perf_counter()
    gmsh.option.setNumber("Mesh.RecombineAll", 1)  # curves get parity-preserving node counts
    gmsh.model.mesh.generate(1)
    gmsh.option.setNumber("Mesh.RecombineAll", 0)
    gmsh.model.mesh.generate(2)
    return time.perf_counter() - t0


def num_triangles():
    _, tags, _ = gmsh.model.mesh.getElements(2)
    return sum(len(t) for t in tags)


def square_hole_builder(target):
    """h_min for about `target` triangles (count ~ h^-2), corrected from trial meshes."""
    h_min = 0.01 * (35000 / target) ** 0.5
    for _ in range(3):
        triangulate(lambda: build_square_hole(h_min))
        h_min *= (num_triangles() / target) ** 0.5
    return lambda: build_square_hole(h_min)


def parse_count(text):
    return int(float(text[:-1]) * 1000) if text.endswith("k") else int(text)


def case_builder(name):
    if name == "rect-sin-a6":
        return build_rect_sin
    for algorithm in (5, 6):
        suffix = f"-a{algorithm}"
        if name.startswith("uniform-") and name.endswith(suffix):
            n = parse_count(name[len("uniform-"):-len(suffix)])
            return lambda: build_uniform(n, algorithm)
        if name.startswith("disk-") and name.endswith(suffix):
            n = parse_count(name[len("disk-"):-len(suffix)])
            return lambda: build_disk(n, algorithm)
        if name.startswith("box-") and name.endswith(suffix):
            n = parse_count(name[len("box-"):-len(suffix)])
            return lambda: build_box(n, algorithm)
    if name.startswith("square-hole-"):
        return square_hole_builder(parse_count(name[len("square-hole-"):]))
    sys.exit(f"unknown case {name!r}: rect-sin-a6, uniform-N-a6, uniform-N-a5, disk-N-a5, "
             "disk-N-a6, box-N-a5, box-N-a6, square-hole-N (N like 35k)")


def triangle_mesh(name, build):
    """Gmsh's triangulation of the case, written once for quadval (cached)."""
    path = os.path.join(CACHE, f"{name}.msh")
    if not os.path.exists(path):
        triangulate(build)
        gmsh.write(path)
    return path


def run_gmsh(build, runs):
    """Gmsh's own pipeline, `runs` times on a fresh model: triangulate, then recombine the
    in-memory model (Blossom + smoothing + topology optimisation, Gmsh defaults)."""
    tri_times, times, cpu = [], [], []
    for _ in range(runs):
        tri_times.append(triangulate(build))
        t0, c0 = time.perf_counter(), time.process_time()
        gmsh.model.mesh.recombine()
        times.append(time.perf_counter() - t0)
        cpu.append(time.process_time() - c0)
    row = summarize(*read_model())
    row.update(seconds=statistics.median(times), cpu_seconds=statistics.median(cpu),
               triangulate_seconds=statistics.median(tri_times), rss_mb=float("nan"))
    return row


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quadval", default=os.path.join(HERE, "..", "build", "quadval"))
    ap.add_argument("--runs", type=int, default=3, help="runs per case; the median time is shown")
    ap.add_argument("--cases", nargs="*",
                    default=["rect-sin-a6", "uniform-10k-a6", "square-hole-35k", "uniform-100k-a6",
                             "uniform-1000k-a6"])
    ap.add_argument("--algo", nargs="+", default=["blossom"],
                    help="quadval's --algo, one row each (blossom, lookahead: its all-quad fast route)")
    ap.add_argument("--gmsh-max-triangles", type=int, default=40000,
                    help="skip Gmsh above this size (it needs ~170 s at 100k, hours at 1M)")
    args = ap.parse_args()
    os.makedirs(CACHE, exist_ok=True)
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    print(f"{'mesh':18} {'tool':8} {'tris in':>9} {'quads':>8} {'tris':>5} {'eta_min':>7} "
          f"{'eta_mean':>8} {'deg4%':>6} {'dmin':>4} {'dmax':>4} {'time s':>8} {'CPU s':>7} {'RSS MB':>7} "
          f"{'B/tri':>6}  notes")
    for name in args.cases:
        build = case_builder(name)
        path = triangle_mesh(name, build)
        _, _, t = read_with_gmsh(path)
        n = len(t)
        rows = [("quadval" if algo == "blossom" else "q/" + algo[:6], run_quadval(args.quadval, path, args.runs, algo))
                for algo in args.algo]
        if n <= args.gmsh_max_triangles:
            rows.append(("gmsh", run_gmsh(build, args.runs)))
        for tool, r in rows:
            per_tri = r["rss_mb"] * 2**20 / n if r["rss_mb"] == r["rss_mb"] else float("nan")
            note = (f"recombine stage {r['recombine_seconds']:.3f} s" if tool != "gmsh" else
                    f"recombine() only; its triangulation {r['triangulate_seconds']:.3f} s")
            print(f"{name:18} {tool:8} {n:9d} {r['quads']:8d} {r['triangles']:5d} "
                  f"{r['eta_min']:7.3f} {r['eta_mean']:8.3f} {r['degree4']:6.1f} {r['dmin']:4d} "
                  f"{r['dmax']:4d} {r['seconds']:8.3f} {r['cpu_seconds']:7.3f} {r['rss_mb']:7.1f} {per_tri:6.0f}  {note}",
                  flush=True)
        if rows[-1][0] == "gmsh":
            g = rows[-1][1]
            for tool, q in rows[:-1]:
                print(f"{'':18} ratio gmsh recombine() / {tool} end to end: wall "
                      f"{g['seconds'] / q['seconds']:.1f}, CPU {g['cpu_seconds'] / q['cpu_seconds']:.1f}",
                      flush=True)
    gmsh.finalize()


if __name__ == "__main__":
    main()
