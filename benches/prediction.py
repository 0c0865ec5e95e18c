#!/usr/bin/env python3
"""How well glint's octree cost prediction ranks and sizes the measured
figures: reads `glint bench --sweep --format json` on stdin, prints a
markdown table (one row per scene and setting) and, over all rows, the
Spearman rank correlation and the worst ratios of predicted to measured
intersection tests per ray, traversal steps per ray and render time.
Then, per scene, the suggested setting (least build + predicted render)
against the sweep's fastest (least build + measured render).

    glint bench scenes/spd/*.nff --size 512x512 --samples 1 --sweep \
        --sweep-leaf-sizes 2,4,8 --format json | python3 benches/prediction.py
"""

import json
import sys


def ranks(values):
    order = sorted(range(len(values)), key=lambda i: values[i])
    r = [0.0] * len(values)
    i = 0
    while i < len(order):
        j = i
        while j + 1 < len(order) and values[order[j + 1]] == values[order[i]]:
            j += 1
        for k in range(i, j + 1):
            r[order[k]] = (i + j) / 2 + 1
        i = j + 1
    return r


def spearman(a, b):
    ra, rb = ranks(a), ranks(b)
    n = len(a)
    ma, mb = sum(ra) / n, sum(rb) / n
    cov = sum((x - ma) * (y - mb) for x, y in zip(ra, rb))
    va = sum((x - ma) ** 2 for x in ra) ** 0.5
    vb = sum((y - mb) ** 2 for y in rb) ** 0.5
    return cov / (va * vb) if va and vb else float("nan")


def name(row):
    return row["scene"].rsplit("/", 1)[-1]


rows = json.load(sys.stdin)
print("| scene | max depth | leaf size | N_IT measured | predicted | N_TS measured | predicted | render (s) | predicted (s) |")
print("|---|---:|---:|---:|---:|---:|---:|---:|---:|")
for r in rows:
    p, o = r["predicted"], r["octree_params"]
    print(
        f"| {name(r)} | {o['max_depth']} | {o['leaf_size']} "
        f"| {r['intersection_tests_per_ray']:.2f} | {p['intersection_tests_per_ray']:.2f} "
        f"| {r['traversal_steps_per_ray']:.2f} | {p['traversal_steps_per_ray']:.2f} "
        f"| {r['render_s']:.3f} | {p['render_s']:.3f} |"
    )
print()
for label, measured, predicted in [
    ("intersection tests per ray", "intersection_tests_per_ray", "intersection_tests_per_ray"),
    ("traversal steps per ray", "traversal_steps_per_ray", "traversal_steps_per_ray"),
    ("render time", "render_s", "render_s"),
]:
    m = [r[measured] for r in rows]
    p = [r["predicted"][predicted] for r in rows]
    ratios = [b / a for a, b in zip(m, p) if a > 0]
    within = {}
    for r in rows:
        within.setdefault(r["scene"], []).append((r[measured], r["predicted"][predicted]))
    per_scene = [spearman([x for x, _ in v], [y for _, y in v]) for v in within.values() if len(v) > 2]
    print(
        f"- {label}: Spearman {spearman(m, p):.3f} over {len(rows)} settings "
        f"(within a scene: {min(per_scene):.2f} to {max(per_scene):.2f}); "
        f"predicted/measured {min(ratios):.3g} to {max(ratios):.3g}"
    )
print()
for scene in dict.fromkeys(r["scene"] for r in rows):
    mine = [r for r in rows if r["scene"] == scene]
    s = next(r for r in mine if r["suggested"])
    f = next(r for r in mine if r["fastest"])
    total = lambda r: r["build_s"] + r["render_s"]
    describe = lambda r: f"depth {r['octree_params']['max_depth']}, leaf {r['octree_params']['leaf_size']}"
    print(
        f"- {name(s)}: suggested {describe(s)} ({total(s):.3f} s measured), "
        f"fastest {describe(f)} ({total(f):.3f} s): {total(s) / total(f):.2f}x"
    )
