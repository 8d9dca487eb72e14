#!/usr/bin/env python3
"""Issue 6's masking benchmark: merges `synthvis bench --json` rows of BENCH.md's layers scene,
prints the table of frame times against depth complexity D per --hsr mode and order, the
targets' ratios, and draws an SVG plot (time vs D, one line per mode and order)."""
import argparse
import json
import statistics
import sys

ap = argparse.ArgumentParser()
ap.add_argument("runs", nargs="+", help="bench --json files (one row or a list each)")
ap.add_argument("--json", help="write the merged rows here")
ap.add_argument("--svg", help="write the plot here")
a = ap.parse_args()

rows = []
for path in a.runs:
    with open(path) as f:
        data = json.load(f)
    rows += data if isinstance(data, list) else [data]
rows = [r for r in rows if r.get("renderer") == "synthvis"]
if a.json:
    with open(a.json, "w") as f:
        json.dump(rows, f, indent=1)

runs = {}  # (hsr, order, D) -> every run's median ms
for r in rows:
    runs.setdefault((r["hsr"], r["order"], int(r["layers"])), []).append(r["median_ms"])
times = {k: statistics.median(v) for k, v in runs.items()}  # the median over runs
ds = sorted({k[2] for k in times})
modes = ["zbuffer", "priority", "hybrid"]
orders = ["random", "f2b", "b2f"]

rounds = max(len(v) for v in runs.values())
if rounds > 1:
    print(f"(each cell the median of {rounds} runs)")
print("| D | " + " | ".join(f"{m} {o}" for m in modes for o in orders) + " |")
print("|---" * (1 + len(modes) * len(orders)) + "|")
for d in ds:
    cells = [f"{times[(m, o, d)]:.1f}" if (m, o, d) in times else "–" for m in modes for o in orders]
    print(f"| {d} | " + " | ".join(cells) + " |")


def t(m, o, d):
    return times.get((m, o, d), float("nan"))


print()
print("targets (ms/ms):")
print(f"  priority f2b vs zbuffer random, D=4:  {t('zbuffer', 'random', 4) / t('priority', 'f2b', 4):.2f}x (target >= 3)")
print(f"  priority f2b vs zbuffer random, D=16: {t('zbuffer', 'random', 16) / t('priority', 'f2b', 16):.2f}x (target >= 6)")
print(f"  priority f2b vs zbuffer f2b, D=8:     {t('zbuffer', 'f2b', 8) / t('priority', 'f2b', 8):.2f}x (target >= 1.3)")
print(f"  priority f2b D=16 / D=1:              {t('priority', 'f2b', 16) / t('priority', 'f2b', 1):.2f} (target <= 2)")
for d in ds:
    print(f"  D={d:2}: hybrid/priority f2b {t('hybrid', 'f2b', d) / t('priority', 'f2b', d):.2f} (<= 1.5); "
          + ", ".join(f"hybrid/zbuffer {o} {t('hybrid', o, d) / t('zbuffer', o, d):.2f}" for o in orders)
          + " (<= 1)")

if a.svg:
    W, H, L, R, T, B = 720, 440, 70, 190, 30, 50
    ymax = max(times.values()) * 1.05
    import math
    xs = {d: L + (W - L - R) * (math.log2(d) / math.log2(max(ds))) for d in ds}

    def y(v):
        return T + (H - T - B) * (1 - v / ymax)

    colour = {"zbuffer": "#c0392b", "priority": "#2471a3", "hybrid": "#229954"}
    dash = {"random": "", "f2b": "6,3", "b2f": "2,3"}
    out = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{W}" height="{H}" font-family="sans-serif" font-size="12">',
           f'<rect width="{W}" height="{H}" fill="white"/>',
           f'<text x="{L}" y="18" font-size="14">layers, 1920×1080, --aa 16, textured + fog, 2 threads: ms per frame vs depth complexity D</text>']
    step = 10 ** math.floor(math.log10(ymax / 5))
    step *= 5 if ymax / step > 25 else 2 if ymax / step > 10 else 1
    v = 0.0
    while v <= ymax:
        out.append(f'<line x1="{L}" x2="{W - R}" y1="{y(v):.1f}" y2="{y(v):.1f}" stroke="#ddd"/>')
        out.append(f'<text x="{L - 6}" y="{y(v) + 4:.1f}" text-anchor="end">{v:g}</text>')
        v += step
    for d in ds:
        out.append(f'<text x="{xs[d]:.1f}" y="{H - B + 18}" text-anchor="middle">{d}</text>')
    out.append(f'<text x="{(L + W - R) / 2}" y="{H - 10}" text-anchor="middle">D (layers covering every pixel)</text>')
    ly = T + 10
    for m in modes:
        for o in orders:
            pts = [(xs[d], y(times[(m, o, d)])) for d in ds if (m, o, d) in times]
            if not pts:
                continue
            path = " ".join(f"{px:.1f},{py:.1f}" for px, py in pts)
            out.append(f'<polyline points="{path}" fill="none" stroke="{colour[m]}" stroke-width="2" stroke-dasharray="{dash[o]}"/>')
            out.append(f'<line x1="{W - R + 12}" x2="{W - R + 42}" y1="{ly}" y2="{ly}" stroke="{colour[m]}" stroke-width="2" stroke-dasharray="{dash[o]}"/>')
            out.append(f'<text x="{W - R + 48}" y="{ly + 4}">{m} {o}</text>')
            ly += 18
    out.append("</svg>")
    with open(a.svg, "w") as f:
        f.write("\n".join(out) + "\n")
    print(f"wrote {a.svg}", file=sys.stderr)
