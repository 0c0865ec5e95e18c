#!/usr/bin/env python3
"""Whether the octree a scene gets by default ever loses: for each scene,
build + render with the default octree against the fastest setting of a
sweep (maximum depths 6, 8, 10, leaf sizes 2 and 8, the cost-driven stop
on and off; its three fastest settings and the default timed again in
three interleaved rounds, each its median; a setting that builds the
default's tree counts as the default); whole `glint render` runs with
the default octree against brute force (octree off; interleaved rounds,
about two seconds of each and at least nine, medians); and the peak
resident memory of a render with the octree against one without (what
the tree adds) beside the memory budget.
Brute force only on scenes of up to 3,000 shapes: on more it takes
minutes. One sample per pixel, so the build weighs as much as it ever
does. Prints a markdown table.

    python3 benches/default_octree.py [SCENE ...]

Without arguments: every bundled scene at its own size and the SPD scenes
at 512x512. The SPD generator's `shells` (sizes 2-4) is not bundled;
generate it and pass the files.
"""

import glob
import json
import os
import subprocess
import sys
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
GLINT = os.path.join(ROOT, "target", "release", "glint")


def glint_json(*args):
    out = subprocess.run([GLINT, *args], cwd=ROOT, check=True, capture_output=True, text=True)
    return json.loads(out.stdout)


def peak_mib(*args):
    """Peak resident memory of `glint render ARGS` in MiB (GNU time)."""
    out = subprocess.run(["/usr/bin/time", "-f", "%M", GLINT, "render", "--quiet", *args],
                         cwd=ROOT, check=True, capture_output=True, text=True)
    return int(out.stderr.strip().splitlines()[-1]) / 1024


def render_s(*args):
    """Wall time of one whole `glint render ARGS` run."""
    start = time.perf_counter()
    subprocess.run([GLINT, "render", "--quiet", *args, "-o", os.path.join("/tmp", "default_octree.png")],
                   cwd=ROOT, check=True, capture_output=True)
    return time.perf_counter() - start


BRUTE_FORCE_MAX_SHAPES = 3000
ROUNDS = 3


def size_args(scene):
    return ["--size", "512x512"] if scene.endswith(".nff") else []


scenes = sys.argv[1:] or sorted(glob.glob(os.path.join(ROOT, "scenes", "*.toml"))) + sorted(
    glob.glob(os.path.join(ROOT, "scenes", "spd", "*.nff")))
print("| scene | shapes | default: build + render (s) | octree off: whole run (s) | sweep's fastest (s) | default / fastest | default / off, whole runs | tree's peak memory (MiB) |")
print("|---|---:|---:|---:|---:|---:|---:|---:|")
worst_fastest, worst_off = 0.0, 0.0
for scene in scenes:
    common = [scene, "--samples", "1", *size_args(scene)]

    def timed(*octree_args):
        [r] = glint_json("bench", *common, "--repeat", "3", "--octree-only", "--format", "json",
                         *octree_args)
        return r

    b = timed()
    # Brute force only where it takes seconds: on thousands of shapes it
    # takes minutes (the bunnies: 25) and loses by orders of magnitude.
    # Brute force against the default like for like: whole `glint render`
    # runs (load, build, render, PNG) with the octree off and on, in
    # interleaved rounds, medians. (`glint bench` times brute force by
    # tracing rows without keeping a frame, which on scenes of a few shapes
    # and a few milliseconds leaves out costs the octree's render has.)
    off_s = default_run_s = None
    if b["shapes"] <= BRUTE_FORCE_MAX_SHAPES:
        runs = {"on": [], "off": []}
        sides = ["--width", "512", "--height", "512"] if size_args(scene) else []
        whole_run = [scene, "--samples", "1", *sides]
        # Rounds enough for about two seconds of each (at least nine, at
        # most 151): nine rounds of a 12 ms run left its median 5 % apart
        # from one run to the next.
        first = render_s(*whole_run, "--octree", "off")
        rounds = max(ROUNDS * 3, min(151, int(2.0 / first)))
        for r in range(rounds):
            for switch in (("on", "off") if r % 2 == 0 else ("off", "on")):
                runs[switch].append(render_s(*whole_run, "--octree", switch))
        off_s = sorted(runs["off"])[len(runs["off"]) // 2]
        default_run_s = sorted(runs["on"])[len(runs["on"]) // 2]
    sweep = glint_json("bench", *common, "--repeat", "1", "--sweep", "--sweep-depths", "6,8,10",
                       "--sweep-leaf-sizes", "2,8", "--sweep-cost-driven", "on,off",
                       "--format", "json")

    def total(r):
        """Build + render of a sweep row."""
        return r["build_s"] + r["render_s"]

    def timed_total(*octree_args):
        r = timed(*octree_args)
        return r["build_s"] + r["octree_on"]["render_s"]

    # A setting that builds the default's tree (same nodes, leaves and
    # references: a scene of a few shapes is one leaf at any setting) is
    # the default, whatever its timing noise says.
    def tree(stats):
        return (stats["nodes"], stats["leaves"], stats["references"], stats["max_depth"])

    # The sweep times each setting once, so its minimum is biased low by
    # the noise of a dozen single runs: its three fastest settings and the
    # default are timed again, in interleaved rounds (medians of 3 each),
    # and each is its median over the rounds.
    candidates = [[]]
    seen = {tree(b["octree_stats"])}
    for r in sorted(sweep, key=total):
        if len(candidates) == 4:
            break
        if tree(r["octree_stats"]) in seen:
            continue
        seen.add(tree(r["octree_stats"]))
        p = r["octree_params"]
        candidates.append(["--octree-max-depth", str(p["max_depth"]),
                           "--octree-leaf-size", str(p["leaf_size"]),
                           "--octree-cost-driven", "on" if p["cost_driven"] else "off"])
    times = [[] for _ in candidates]
    for _ in range(ROUNDS):
        for k, args in enumerate(candidates):
            times[k].append(timed_total(*args))
    medians = [sorted(t)[len(t) // 2] for t in times]
    default_s, fastest = medians[0], min(medians)
    # The tree is the same at any image size: a small render keeps brute
    # force quick on the big meshes.
    out = os.path.join("/tmp", "default_octree.png")
    small = [scene, "--samples", "1", "--width", "32", "--height", "24"]
    tree_mib = peak_mib(*small, "-o", out) - peak_mib(*small, "--octree", "off", "-o", out)
    worst_fastest = max(worst_fastest, default_s / fastest)
    if off_s is not None:
        worst_off = max(worst_off, default_run_s / off_s)
    off = ("", "") if off_s is None else (f"{off_s:.3f}", f"{default_run_s / off_s:.2f}")
    print(f"| {os.path.basename(scene)} | {b['shapes']} | {default_s:.3f} | {off[0]} | {fastest:.3f} "
          f"| {default_s / fastest:.2f} | {off[1]} | {tree_mib:.0f} |", flush=True)
print(f"\nWorst: default / fastest {worst_fastest:.2f}, default / octree off {worst_off:.2f} "
      f"(brute force timed on scenes of at most {BRUTE_FORCE_MAX_SHAPES:,} shapes).")
