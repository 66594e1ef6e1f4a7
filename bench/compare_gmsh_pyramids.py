#!/usr/bin/python3
"""Pyramids side by side: `quadval check` (certified Jacobian bounds, validity) and Gmsh
4.8.4's AnalyseMeshQuality plugin (Jacobian only, ../shared/data/tools/gmsh_analyse.py) on
the pyramid meshes of ../shared/data/curved and on generated boxes of curved pyramids
(each cell of an N^3 grid split into 6 pyramids around its centre; order 2: the 14 Gmsh
nodes placed by the straight map, the non-vertex ones moved by a smooth field). Prints,
per mesh, elements per second of both (median of --repeat runs, each tool's own timer
around the analysis only) and the ratio.

    /usr/bin/python3 bench/compare_gmsh_pyramids.py --quadval build/quadval --box 12 20
"""
import argparse
import glob
import json
import os
import subprocess
import sys
import tempfile

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
SHARED = os.path.join(HERE, "..", "..", "shared", "data")
CACHE = "/tmp/quadval_pyramid_bench"


def ref_nodes(order):
    """Gmsh's reference nodes of the complete pyramid of this order (via the Gmsh API)."""
    import gmsh
    gmsh.initialize()
    tid = {1: 7, 2: 14}[order]
    _, _, _, n, coords, _ = gmsh.model.mesh.getElementProperties(tid)
    gmsh.finalize()
    return tid, np.asarray(coords).reshape(n, 3)


def pyramid_box(n, order, amp=0.06, seed=5):
    """N^3 cells, 6 pyramids each (base = a cell face, apex = the cell centre), MSH 4.1."""
    path = os.path.join(CACHE, "pyramid_box_%d_o%d.msh" % (n, order))
    if os.path.exists(path):
        return path
    os.makedirs(CACHE, exist_ok=True)
    rng = np.random.default_rng(seed)
    tid, ref = ref_nodes(order)
    corners = np.array([[i, j, k] for k in (0, 1) for j in (0, 1) for i in (0, 1)], float)
    # faces of the unit cell as 4 corner indices, ordered so that the apex (centre) is on
    # the side of the base's normal (x1-x0) x (x3-x0): positive Jacobian in Gmsh's convention
    faces = [(0, 2, 6, 4), (1, 5, 7, 3), (0, 4, 5, 1), (2, 3, 7, 6), (0, 1, 3, 2), (4, 6, 7, 5)]
    g = np.arange(n, dtype=float)
    cells = np.stack(np.meshgrid(g, g, g, indexing="ij"), axis=-1).reshape(-1, 3)
    xi, eta, zeta = ref[:, 0], ref[:, 1], ref[:, 2]
    t = 1 - zeta
    with np.errstate(divide="ignore", invalid="ignore"):
        u = np.where(t > 0, (xi / np.where(t > 0, t, 1) + 1) / 2, 0.5)
        v = np.where(t > 0, (eta / np.where(t > 0, t, 1) + 1) / 2, 0.5)
    w = np.stack([(1 - u) * (1 - v) * t, u * (1 - v) * t, u * v * t, (1 - u) * v * t, zeta], axis=1)  # straight map
    elems = []
    for f in faces:
        base = corners[list(f)]
        verts = np.vstack([base, [[0.5, 0.5, 0.5]]])
        elems.append(w @ verts)  # nodes x 3, unit cell
    elems = np.stack(elems)  # 6 x nodes x 3
    x = (cells[:, None, None, :] + elems[None]).reshape(-1, ref.shape[0], 3)
    if order > 1:  # smooth curving of the non-vertex nodes
        k = rng.uniform(-1.5, 1.5, (3, 3))
        ph = rng.uniform(0, 6.283, 3)
        disp = amp * np.sin(x @ k.T + ph)
        x[:, 5:, :] += disp[:, 5:, :]
    ne, nn = x.shape[0], x.shape[0] * x.shape[1]
    with open(path, "w") as fh:
        fh.write("$MeshFormat\n4.1 0 8\n$EndMeshFormat\n")
        fh.write("$Nodes\n1 %d 1 %d\n3 1 0 %d\n" % (nn, nn, nn))
        np.savetxt(fh, np.arange(1, nn + 1), fmt="%d")
        np.savetxt(fh, x.reshape(-1, 3), fmt="%.17g")
        fh.write("$EndNodes\n$Elements\n1 %d 1 %d\n3 1 %d %d\n" % (ne, ne, tid, ne))
        conn = np.arange(1, nn + 1).reshape(ne, -1)
        np.savetxt(fh, np.column_stack([np.arange(1, ne + 1), conn]), fmt="%d")
        fh.write("$EndElements\n")
    return path


def median(xs):
    return sorted(xs)[len(xs) // 2]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--quadval", default=os.path.join(HERE, "..", "build", "quadval"))
    ap.add_argument("--threads", type=int, default=1)
    ap.add_argument("--box", type=int, nargs="*", default=[12])
    ap.add_argument("--repeat", type=int, default=3)
    a = ap.parse_args()
    meshes = sorted(glob.glob(os.path.join(SHARED, "curved", "*pyramid*.msh")))
    for nbox in a.box:
        meshes += [pyramid_box(nbox, 1), pyramid_box(nbox, 2)]
    tool = os.path.join(SHARED, "tools", "gmsh_analyse.py")
    print("threads: quadval %d, Gmsh 1 (the plugin is serial); median of %d runs" % (a.threads, a.repeat))
    hdr = "%-30s %9s %7s %7s %10s %10s %12s %12s %7s" % (
        "mesh", "elements", "inv(q)", "inv(g)", "t_q [s]", "t_g [s]", "el/s quadval", "el/s gmsh", "ratio")
    print(hdr)
    print("-" * len(hdr))
    with tempfile.TemporaryDirectory() as tmp:
        for m in meshes:
            qjson, gjson = os.path.join(tmp, "q.json"), os.path.join(tmp, "g.json")
            tq, tg, q, g = [], [], None, None
            for _ in range(a.repeat):
                p = subprocess.run([a.quadval, "check", m, "-q", "--threads", str(a.threads), "-o", qjson],
                                   stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
                if p.returncode not in (0, 1):
                    sys.exit("quadval failed on %s (exit %d)" % (m, p.returncode))
                q = json.load(open(qjson))["summary"]
                tq.append(q["seconds"])
                subprocess.run([sys.executable, tool, m, "--measures", "J", "--json", gjson, "--quiet"],
                               stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, check=True)
                g = json.load(open(gjson))
                tg.append(g["t_plugin_run_s"])
            n, t_q, t_g = q["elements"], median(tq), median(tg)
            print("%-30s %9d %7d %7d %10.4f %10.4f %12.3g %12.3g %7.1f" % (
                os.path.basename(m)[:30], n, q["invalid"], g["n_invalid_ratio_le_0"], t_q, t_g, n / t_q, n / t_g,
                t_g / t_q))


if __name__ == "__main__":
    main()
