#!/usr/bin/python3
"""Two or more quadval binaries (e.g. before and after a change) on the same triangle mesh,
run alternately in a shuffled order each round, so that they meet the same machine load:
the median, least and largest wall time of each, and of each stage that `quadval
recombine` logs (read, input, graph, blossom, ... in their order). On the 2-core machines
the speed drifts by 10-30% within minutes, so only such alternating runs compare.

    /usr/bin/python3 bench/ab_recombine.py /tmp/quadval_recombine_bench/square-hole-1000k.msh \\
        --runs 5 /tmp/quadval_before build/quadval

Each binary also writes its output mesh once (to a temporary folder), and the script says
whether those files are the same, byte for byte (they should be, for a change of speed only).
"""
import argparse
import filecmp
import os
import random
import re
import statistics
import subprocess
import sys
import tempfile
import time

STAGE = re.compile(r"^\[(\w+)\].*, ([0-9.]+) ms$")


def run(binary, mesh, out):
    t0 = time.perf_counter()
    try:
        p = subprocess.run([binary, "recombine", mesh, "-o", out], capture_output=True, text=True)
    except OSError as e:
        sys.exit(f"cannot run {binary}: {e.strerror}")
    wall = time.perf_counter() - t0
    if p.returncode != 0:
        sys.exit(f"{binary} failed on {mesh}: {p.stderr.strip()}")
    stages = []
    for line in (p.stdout + p.stderr).splitlines():
        m = STAGE.match(line)
        if m:
            stages.append((m.group(1), float(m.group(2)) / 1e3))
    return wall, stages


def spread(values):
    return f"{statistics.median(values):8.3f} ({min(values):.3f}-{max(values):.3f})"


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("mesh")
    ap.add_argument("binaries", nargs="+")
    ap.add_argument("--runs", type=int, default=5, help="rounds; each runs every binary once")
    args = ap.parse_args()
    walls = {b: [] for b in args.binaries}
    stages = {b: {} for b in args.binaries}
    with tempfile.TemporaryDirectory() as tmp:
        outs = {b: os.path.join(tmp, f"out{i}.msh") for i, b in enumerate(args.binaries)}
        for _ in range(args.runs):
            order = list(args.binaries)
            random.shuffle(order)
            for b in order:
                wall, st = run(b, args.mesh, outs[b])
                walls[b].append(wall)
                for k, (name, seconds) in enumerate(st):
                    stages[b].setdefault((k, name), []).append(seconds)
        first = args.binaries[0]
        same = all(filecmp.cmp(outs[first], outs[b], shallow=False) for b in args.binaries[1:])
    print(f"{os.path.basename(args.mesh)}, {args.runs} alternating rounds; seconds: median (least-largest)")
    for b in args.binaries:
        print(f"\n{b}\n  {'wall':8s} {spread(walls[b])}")
        for (_, name), v in sorted(stages[b].items()):
            print(f"  {name:8s} {spread(v)}")
    print("\noutput files: " + ("the same, byte for byte" if same else "DIFFERENT"))


if __name__ == "__main__":
    main()
