#!/usr/bin/python3
"""Paper II Fig. 8 on our own input: for horizons 1..H, N runs of the selective look-ahead tree
(`quadval recombine --algo lookahead --runs N --report`), then box plots (SVG, no plotting
library needed) of the quality (% of Blossom's), the share recombined and the time per run.

    scripts/lookahead_boxplots.py build-look/quadval /tmp/quadval-look/square-hole-35k.msh \
        --horizons 1-10 --runs 128 --out /tmp/quadval-look/boxplots

Writes OUT/h<k>.json (the reports), OUT/table.csv (median, quartiles) and OUT/<measure>.svg.
Boxes as in the paper: median line, interquartile box, whiskers to the most extreme points
within 1.5 IQR, crosses for the points beyond.
"""
import argparse
import json
import os
import statistics
import subprocess
import sys


def quartiles(v):
    v = sorted(v)
    def q(p):
        x = p * (len(v) - 1)
        i = int(x)
        return v[i] if i + 1 >= len(v) else v[i] + (x - i) * (v[i + 1] - v[i])
    return q(0.25), q(0.5), q(0.75)


def box_svg(title, ylabel, series, path):
    w, h, left, bottom, top = 640, 360, 70, 40, 30
    allv = [x for _, v in series for x in v]
    lo, hi = min(allv), max(allv)
    if hi == lo:
        hi = lo + 1
    pad = 0.05 * (hi - lo)
    lo, hi = lo - pad, hi + pad
    ys = lambda x: top + (h - top - bottom) * (hi - x) / (hi - lo)
    step = (w - left - 20) / len(series)
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{w}" height="{h}" font-family="sans-serif" font-size="11">',
           f'<text x="{w/2}" y="18" text-anchor="middle" font-size="13">{title}</text>',
           f'<line x1="{left}" y1="{top}" x2="{left}" y2="{h-bottom}" stroke="black"/>',
           f'<line x1="{left}" y1="{h-bottom}" x2="{w-20}" y2="{h-bottom}" stroke="black"/>',
           f'<text x="14" y="{(h)/2}" transform="rotate(-90 14 {h/2})" text-anchor="middle">{ylabel}</text>']
    for k in range(6):
        val = lo + k * (hi - lo) / 5
        out.append(f'<text x="{left-4}" y="{ys(val)+4}" text-anchor="end">{val:.4g}</text>')
        out.append(f'<line x1="{left-3}" y1="{ys(val)}" x2="{left}" y2="{ys(val)}" stroke="black"/>')
    for i, (label, v) in enumerate(series):
        q1, med, q3 = quartiles(v)
        iqr = q3 - q1
        inside = [x for x in v if q1 - 1.5 * iqr <= x <= q3 + 1.5 * iqr]
        wlo, whi = min(inside), max(inside)
        cx = left + step * (i + 0.5)
        bw = step * 0.5
        out.append(f'<line x1="{cx}" y1="{ys(whi)}" x2="{cx}" y2="{ys(q3)}" stroke="black" stroke-dasharray="3,2"/>')
        out.append(f'<line x1="{cx}" y1="{ys(q1)}" x2="{cx}" y2="{ys(wlo)}" stroke="black" stroke-dasharray="3,2"/>')
        for y in (whi, wlo):
            out.append(f'<line x1="{cx-bw/4}" y1="{ys(y)}" x2="{cx+bw/4}" y2="{ys(y)}" stroke="black"/>')
        out.append(f'<rect x="{cx-bw/2}" y="{ys(q3)}" width="{bw}" height="{max(ys(q1)-ys(q3), 0.5)}" fill="none" stroke="blue"/>')
        out.append(f'<line x1="{cx-bw/2}" y1="{ys(med)}" x2="{cx+bw/2}" y2="{ys(med)}" stroke="red" stroke-width="2"/>')
        for x in v:
            if x < wlo or x > whi:
                out.append(f'<text x="{cx}" y="{ys(x)+4}" text-anchor="middle" fill="red">+</text>')
        out.append(f'<text x="{cx}" y="{h-bottom+15}" text-anchor="middle">{label}</text>')
    out.append(f'<text x="{(w+left)/2}" y="{h-6}" text-anchor="middle">horizon</text></svg>')
    with open(path + ".tmp", "w") as f:
        f.write("\n".join(out))
    os.replace(path + ".tmp", path)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("quadval")
    ap.add_argument("mesh")
    ap.add_argument("--horizons", default="1-10")
    ap.add_argument("--runs", type=int, default=128)
    ap.add_argument("--out", default="/tmp/quadval-look/boxplots")
    a = ap.parse_args()
    h0, h1 = (int(x) for x in a.horizons.split("-"))
    os.makedirs(a.out, exist_ok=True)
    rows, quality, share, seconds = [], [], [], []
    for h in range(h0, h1 + 1):
        report = os.path.join(a.out, f"h{h}.json")
        if not os.path.exists(report):
            subprocess.run([a.quadval, "recombine", a.mesh, "-o", os.path.join(a.out, f"h{h}.msh"),
                            "--algo", "lookahead", "--horizon", str(h), "--runs", str(a.runs),
                            "--no-optimize", "--compare-blossom", "-q", "--report", report], check=True)
        j = json.load(open(report))["lookahead"]
        ref, n = j["blossom_quality"], json.load(open(report))["statistics"]["input_triangles"]
        q = [100 * r["quality"] / ref for r in j["runs"]]
        s = [100 * 2 * r["quads"] / n for r in j["runs"]]
        t = [r["seconds"] for r in j["runs"]]
        quality.append((str(h), q)); share.append((str(h), s)); seconds.append((str(h), t))
        rows.append((h, statistics.median(q), min(q), max(q), statistics.median(s), min(s), statistics.median(t)))
        print(f"h={h}: quality median {rows[-1][1]:.2f}% [{rows[-1][2]:.2f}, {rows[-1][3]:.2f}], "
              f"recombined median {rows[-1][4]:.2f}% (min {rows[-1][5]:.2f}), time median {rows[-1][6]:.3f} s",
              file=sys.stderr)
    with open(os.path.join(a.out, "table.csv"), "w") as f:
        f.write("horizon,quality_median_pct,quality_min_pct,quality_max_pct,recombined_median_pct,recombined_min_pct,seconds_median\n")
        for r in rows:
            f.write(",".join(f"{x:.6g}" for x in r) + "\n")
    box_svg("Quality (% of Blossom)", "%", quality, os.path.join(a.out, "quality.svg"))
    box_svg("Triangles recombined (%)", "%", share, os.path.join(a.out, "recombined.svg"))
    box_svg("Time per run (s)", "s", seconds, os.path.join(a.out, "time.svg"))
    return 0


if __name__ == "__main__":
    sys.exit(main())
