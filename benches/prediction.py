#!/usr/bin/env python3
"""How well glint's octree cost predictions rank and size the measured
figures: reads `glint bench --sweep --format json` on stdin, prints a
markdown table (one row per scene and setting) and, for each prediction
(from the tree alone, `predicted`; from a sample of the render's rays,
`predicted_from_rays`), over all rows, the Spearman rank correlation and
the worst ratios of predicted to measured intersection tests per ray,
traversal steps per ray and render time. Then, per scene, each suggested
setting (least build + predicted render) against the sweep's fastest
(least build + measured render).

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
print("| scene | max depth | leaf size | N_IT measured | from tree | from rays | N_TS measured | from tree | from rays | render (s) | from tree | from rays |")
print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
for r in rows:
    p, q, o = r["predicted"], r["predicted_from_rays"], r["octree_params"]
    print(
        f"| {name(r)} | {o['max_depth']} | {o['leaf_size']} "
        f"| {r['intersection_tests_per_ray']:.2f} | {p['intersection_tests_per_ray']:.2f} | {q['intersection_tests_per_ray']:.2f} "
        f"| {r['traversal_steps_per_ray']:.2f} | {p['traversal_steps_per_ray']:.2f} | {q['traversal_steps_per_ray']:.2f} "
        f"| {r['render_s']:.3f} | {p['render_s']:.3f} | {q['render_s']:.3f} |"
    )
for source, field in [("From the tree alone", "predicted"), ("From a sample of the render's rays", "predicted_from_rays")]:
    print(f"\n{source} (`{field}`):\n")
    for label, key in [
        ("intersection tests per ray", "intersection_tests_per_ray"),
        ("traversal steps per ray", "traversal_steps_per_ray"),
        ("render time", "render_s"),
    ]:
        m = [r[key] for r in rows]
        p = [r[field][key] for r in rows]
        ratios = [b / a for a, b in zip(m, p) if a > 0]
        worst = max(max(x, 1 / x) for x in ratios if x > 0)
        within = {}
        for r in rows:
            within.setdefault(r["scene"], []).append((r[key], r[field][key]))
        per_scene = [spearman([x for x, _ in v], [y for _, y in v]) for v in within.values() if len(v) > 2]
        print(
            f"- {label}: Spearman {spearman(m, p):.3f} over {len(rows)} settings "
            f"(within a scene: {min(per_scene):.2f} to {max(per_scene):.2f}); "
            f"predicted/measured {min(ratios):.3g} to {max(ratios):.3g} (worst factor {worst:.2f})"
        )
print()
total = lambda r: r["build_s"] + r["render_s"]
describe = lambda r: f"depth {r['octree_params']['max_depth']}, leaf {r['octree_params']['leaf_size']}"
print("| scene | fastest (s) | suggested from rays | (s) | x fastest | side by side | suggested from the tree | (s) | x fastest |")
print("|---|---:|---|---:|---:|---:|---|---:|---:|")
for scene in dict.fromkeys(r["scene"] for r in rows):
    mine = [r for r in rows if r["scene"] == scene]
    f = next(r for r in mine if r["fastest"])
    s = next(r for r in mine if r["suggested_from_rays"])
    t = next(r for r in mine if r["suggested_from_tree"])
    # The sweep's own side-by-side timing of the two (sweeps since
    # 2026-11-30), where they differ.
    again = s.get("timed_again_s"), f.get("timed_again_s")
    side = "%.2f" % (again[0] / again[1]) if s is not f and None not in again else ("1.00" if s is f else "")
    print(
        f"| {name(f)} | {total(f):.3f} | {describe(s)} | {total(s):.3f} | {total(s) / total(f):.2f} | {side} "
        f"| {describe(t)} | {total(t):.3f} | {total(t) / total(f):.2f} |"
    )
