#!/usr/bin/python3
"""Side by side: `quadval recombine` (Blossom-Quad with LEMON) and Gmsh 4.8.4's Blossom
recombination (Mesh.RecombinationAlgorithm = 1, default smoothing and topology optimisation)
on the same triangle meshes. Prints one row per tool and mesh: quads, triangles left, eta_min,
eta_mean, % interior vertices of degree 4, time (median of --runs), peak memory.

eta (Paper I eq. 3) and the degree statistics are computed here, in numpy, from each tool's
output mesh, so both rows are measured the same way.

    /usr/bin/python3 bench/compare_gmsh_recombine.py --quadval build/quadval
    /usr/bin/python3 bench/compare_gmsh_recombine.py --quadval build/quadval --sizes 100000 1000000 \
        --gmsh-max-triangles 120000

Generated meshes (unit square, Mesh.Algorithm 6, curves meshed with RecombineAll so that the
triangle count is even) are cached under /tmp/quadval_recombine_bench/.
"""
import argparse
import json
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


def generated_mesh(triangles):
    os.makedirs(CACHE, exist_ok=True)
    path = os.path.join(CACHE, f"square-{triangles}.msh")
    if os.path.exists(path):
        return path
    # Unit square, uniform size: about 2.3 / h^2 triangles for Frontal-Delaunay.
    h = (2.3 / triangles) ** 0.5
    gmsh.clear()
    gmsh.model.add("square")
    gmsh.model.occ.addRectangle(0, 0, 0, 1, 1)
    gmsh.model.occ.synchronize()
    gmsh.option.setNumber("Mesh.MeshSizeMin", h)
    gmsh.option.setNumber("Mesh.MeshSizeMax", h)
    gmsh.option.setNumber("Mesh.Algorithm", 6)
    gmsh.option.setNumber("Mesh.RecombinationAlgorithm", 1)
    gmsh.option.setNumber("Mesh.RecombineAll", 1)  # curves get parity-preserving node counts
    gmsh.model.mesh.generate(1)
    gmsh.option.setNumber("Mesh.RecombineAll", 0)
    gmsh.model.mesh.generate(2)
    gmsh.write(path)
    return path


def run_quadval(exe, path, runs):
    out = os.path.join(CACHE, "quadval_out.msh")
    report = os.path.join(CACHE, "quadval_report.json")
    times, rss = [], 0
    for _ in range(runs):
        t0 = time.perf_counter()
        r = subprocess.run(["/usr/bin/time", "-f", "%M", exe, "recombine", path, "-o", out,
                            "--report", report, "-q"], capture_output=True, text=True)
        times.append(time.perf_counter() - t0)
        if r.returncode != 0:
            sys.exit(f"quadval failed on {path}: {r.stderr}")
        rss = max(rss, int(r.stderr.strip().splitlines()[-1]))
    with open(report) as f:
        rep = json.load(f)
    xyz, q, t = read_with_gmsh(out)
    row = summarize(xyz, q, t)
    row.update(seconds=statistics.median(times), recombine_seconds=rep["statistics"]["total_seconds"],
               rss_mb=rss / 1024)
    return row


def run_gmsh(path, runs):
    times = []
    for _ in range(runs):
        gmsh.open(path)
        gmsh.option.setNumber("Mesh.RecombinationAlgorithm", 1)
        t0 = time.perf_counter()
        gmsh.model.mesh.recombine()
        times.append(time.perf_counter() - t0)
    out = os.path.join(CACHE, "gmsh_out.msh")
    gmsh.write(out)
    xyz, q, t = read_with_gmsh(out)
    row = summarize(xyz, q, t)
    row.update(seconds=statistics.median(times), recombine_seconds=statistics.median(times),
               rss_mb=float("nan"))
    return row


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--quadval", default=os.path.join(HERE, "..", "build", "quadval"))
    ap.add_argument("--runs", type=int, default=3, help="runs per case; the median time is shown")
    ap.add_argument("--sizes", type=int, nargs="*", default=[100000, 1000000],
                    help="generated square meshes, approximate triangle counts")
    ap.add_argument("--gmsh-max-triangles", type=int, default=40000,
                    help="skip Gmsh above this size (it needs ~170 s at 100k, hours at 1M)")
    args = ap.parse_args()
    os.makedirs(CACHE, exist_ok=True)
    gmsh.initialize()
    gmsh.option.setNumber("General.Terminal", 0)
    cases = [os.path.join(SHARED, "rect-sin-a6.msh"), os.path.join(SHARED, "uniform-10k-a6.msh")]
    cases += [generated_mesh(n) for n in args.sizes]
    header = f"{'mesh':24} {'tool':8} {'tris in':>9} {'quads':>8} {'tris':>5} {'eta_min':>7} " \
             f"{'eta_mean':>8} {'deg4%':>6} {'dmin':>4} {'dmax':>4} {'time s':>8} {'RSS MB':>7} {'B/tri':>6}"
    print(header)
    for path in cases:
        _, _, t = read_with_gmsh(path)
        n = len(t)
        rows = [("quadval", run_quadval(args.quadval, path, args.runs))]
        if n <= args.gmsh_max_triangles:
            rows.append(("gmsh", run_gmsh(path, args.runs)))
        for tool, r in rows:
            per_tri = r["rss_mb"] * 2**20 / n if r["rss_mb"] == r["rss_mb"] else float("nan")
            print(f"{os.path.basename(path):24} {tool:8} {n:9d} {r['quads']:8d} {r['triangles']:5d} "
                  f"{r['eta_min']:7.3f} {r['eta_mean']:8.3f} {r['degree4']:6.1f} {r['dmin']:4d} "
                  f"{r['dmax']:4d} {r['seconds']:8.3f} {r['rss_mb']:7.1f} {per_tri:6.0f}", flush=True)
    gmsh.finalize()


if __name__ == "__main__":
    main()
