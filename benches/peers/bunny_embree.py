#!/usr/bin/env python3
"""Peer benchmark: glint's bunny primary rays traced by Embree 4 (PyPI `embreex`).

The rays are exactly glint's (scenes/bunny.toml, `--view normals --samples 1`):
the Stanford bunny (assets/bunny.obj, 3,674 triangles) scaled by 0.1, seen by
glint's camera at 1024x768, one ray per pixel through the pixel centre (see
common.py). Rays and vertices are computed in float64 exactly as glint does,
then rounded to float32, which Embree requires.

Robust mode: embreex's `EmbreeScene(device, robust=True)` sets
RTC_SCENE_FLAG_ROBUST with rtcSetSceneFlags (embreex/rtcore_scene.pyx;
`robust` already defaults to True). We pass robust=True explicitly, so the
scene IS in robust mode (watertight traversal/intersection, like glint's
intent of no leaks between shared edges). `--no-robust` turns it off.

Threads: embreex's `EmbreeScene.run()` is a Cython loop calling rtcIntersect1
once per ray (single-ray API, no packets/streams), and that loop sits inside a
`with nogil:` block (embreex/rtcore_scene.pyx, since the "add nogil block"
change that 4.4.0 ships; the installed rtcore_scene.pxd declares rtcIntersect1
`nogil`). One call therefore runs on ONE thread (Embree's TBB pool is used
only for the BVH build), but because it releases the GIL, several Python
threads can trace concurrently in one process sharing one scene. `--threads T`
splits the rays into T contiguous chunks traced from T Python threads; the
threads first meet at a barrier, and the timed span runs from the earliest
thread start to the latest thread end (ray generation, array allocation
outside run(), and scene build are not timed).

Scene build: embreex commits the scene lazily on the first run() call, so we
commit it with a one-ray query and report that (plus geometry creation) as
`build_s`, outside the timed runs.

Output: one JSON object on stdout:
  {"rays", "seconds" (median of K runs), "mrays_per_s", "threads", "hits", ...}
"""

import argparse
import json
import os
import statistics
import sys
import threading
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402

from embreex import rtcore as rtc  # noqa: E402
from embreex import rtcore_scene as rtcs  # noqa: E402
from embreex.mesh_construction import TriangleMesh  # noqa: E402


def build_scene(verts32, faces32, robust):
    t0 = time.perf_counter()
    device = rtc.EmbreeDevice()
    scene = rtcs.EmbreeScene(device, robust=robust)
    TriangleMesh(scene, verts32, faces32)
    # First run() commits the scene (builds the BVH): do it here, untimed.
    scene.run(np.zeros((1, 3), np.float32), np.array([[0, 0, -1]], np.float32))
    return device, scene, time.perf_counter() - t0


def trace_once(scene, chunks):
    """Trace every (origins, directions) chunk, one thread per chunk.

    Returns (wall seconds of the traced span, list of primID arrays)."""
    n = len(chunks)
    results = [None] * n
    starts = [0.0] * n
    ends = [0.0] * n
    if n == 1:
        o, d = chunks[0]
        t0 = time.perf_counter()
        results[0] = scene.run(o, d)
        return time.perf_counter() - t0, results

    barrier = threading.Barrier(n)

    def work(k):
        o, d = chunks[k]
        barrier.wait()
        starts[k] = time.perf_counter()
        results[k] = scene.run(o, d)
        ends[k] = time.perf_counter()

    threads = [threading.Thread(target=work, args=(k,)) for k in range(n)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    return max(ends) - min(starts), results


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--threads", type=int, default=1, help="Python threads tracing concurrently (default 1)")
    ap.add_argument("--runs", type=int, default=5, help="timed runs K; the median is reported (default 5)")
    ap.add_argument("--warmup", type=int, default=1, help="untimed runs first (default 1)")
    ap.add_argument("--no-robust", action="store_true", help="do not set RTC_SCENE_FLAG_ROBUST")
    ap.add_argument("--glint-stats", metavar="JSON",
                    help="glint `render --stats` output of the same view, to compare primary_hits")
    args = ap.parse_args()
    if args.threads < 1 or args.runs < 1:
        ap.error("--threads and --runs must be at least 1")

    verts, faces = common.placed_bunny()
    verts32 = np.ascontiguousarray(verts, dtype=np.float32)
    faces32 = np.ascontiguousarray(faces, dtype=np.int32)

    origins, dirs = common.primary_rays()
    origins = np.ascontiguousarray(origins, dtype=np.float32)
    dirs = np.ascontiguousarray(dirs, dtype=np.float32)
    nrays = origins.shape[0]

    _device, scene, build_s = build_scene(verts32, faces32, robust=not args.no_robust)

    bounds = np.linspace(0, nrays, args.threads + 1).astype(np.int64)
    chunks = [(origins[a:b], dirs[a:b]) for a, b in zip(bounds[:-1], bounds[1:])]

    for _ in range(args.warmup):
        trace_once(scene, chunks)
    times = []
    hits = None
    for _ in range(args.runs):
        dt, res = trace_once(scene, chunks)
        times.append(dt)
        h = int(sum(int(np.count_nonzero(r >= 0)) for r in res))
        if hits is not None and h != hits:
            raise SystemExit(f"hit count changed between runs: {hits} vs {h}")
        hits = h

    seconds = statistics.median(times)
    out = {
        "peer": "embree",
        "embree_version": repr(_device).split(":")[-1].strip(),
        "robust": not args.no_robust,
        "rays": nrays,
        "seconds": seconds,
        "mrays_per_s": nrays / seconds / 1e6,
        "threads": args.threads,
        "hits": hits,
        "triangles": int(faces32.shape[0]),
        "build_s": build_s,
        "runs_s": times,
    }
    if args.glint_stats:
        with open(args.glint_stats, encoding="utf-8") as fh:
            g = json.load(fh)
        gh = int(g["rays"]["primary_hits"])
        out["glint_primary_hits"] = gh
        out["hits_minus_glint"] = hits - gh
    print(json.dumps(out))


if __name__ == "__main__":
    main()
