#!/usr/bin/env python3
"""The octree against a BVH on the same scenes, in one run: for each
accelerator the build time, its memory, the traversal steps and
intersection tests per ray (one `glint render --stats`: single rays
counted), and the render time (median of 3 renders without counting).
The octree's render traces coherent rays in packets; the BVH traces every
ray singly, so the table also times the octree with every ray single
(`GLINT_PACKETS=off`), the like-for-like comparison of the two walks.
One sample per pixel, 2 threads. Prints a markdown table.

    python3 benches/accelerators.py [SCENE ...]

Without arguments: the SPD scenes at 512x512, the bunny and the default
scene at 400x300.
"""

import glob
import json
import os
import re
import statistics
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
GLINT = os.path.join(ROOT, "target", "release", "glint")


def size_args(scene):
    w, h = (512, 512) if scene.endswith(".nff") else (400, 300)
    return ["--width", str(w), "--height", str(h), "--samples", "1", "--threads", "2"]


def render(scene, accel, *extra, env=None):
    with tempfile.TemporaryDirectory() as d:
        out = subprocess.run(
            [GLINT, "render", scene, *size_args(scene), "--accel", accel, *extra,
             "-o", os.path.join(d, "x.png")],
            cwd=ROOT, check=True, capture_output=True, text=True,
            env={**os.environ, **(env or {})})
    return out


def timed(scene, accel, env=None):
    """Median render seconds of 3 renders (from glint's line on stderr)."""
    return statistics.median(
        float(re.search(r"render ([\d.]+) s", render(scene, accel, env=env).stderr).group(1))
        for _ in range(3))


def main():
    scenes = sys.argv[1:] or sorted(glob.glob("scenes/spd/*.nff")) + [
        "scenes/bunny.toml", "scenes/default.toml"]
    print("| scene | shapes | octree build s | BVH build s | octree MiB | BVH MiB "
          "| octree steps/ray | BVH steps/ray | octree tests/ray | BVH tests/ray "
          "| octree render s | octree single rays s | BVH render s |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
    for scene in scenes:
        counted = {a: json.loads(render(scene, a, "--stats", "-q").stdout)
                   for a in ("octree", "bvh")}
        octree_s = timed(scene, "octree")
        single_s = timed(scene, "octree", env={"GLINT_PACKETS": "off"})
        bvh_s = timed(scene, "bvh")
        o, b = counted["octree"], counted["bvh"]
        octree_build, bvh_build = o["build_s"], b["build_s"]
        mib = lambda n: n / (1 << 20)
        print(f"| {os.path.basename(scene)} | {sum(o['shapes'].values()):,} "
              f"| {octree_build:.3f} | {bvh_build:.3f} "
              f"| {mib(o['octree_stats']['memory_bytes']):.1f} | {mib(b['bvh_stats']['memory_bytes']):.1f} "
              f"| {o['traversal_steps_per_ray']:.1f} | {b['traversal_steps_per_ray']:.1f} "
              f"| {o['intersection_tests_per_ray']:.1f} | {b['intersection_tests_per_ray']:.1f} "
              f"| {octree_s:.3f} | {single_s:.3f} | {bvh_s:.3f} |", flush=True)


if __name__ == "__main__":
    main()
