"""The sequence benchmark (issue 62): a 24-frame turntable of
scenes/default.toml at 400x300 with adaptive anti-aliasing, made four ways:

  (a) one `glint render --turntable 24` process;
  (b) glint.render_frames without a client (this process);
  (c) a Dask LocalCluster of 2 worker processes x 1 thread, glint at
      1 thread in each task;
  (d) a LocalCluster of 1 worker process x 2 threads, glint at 1 thread in
      each task (two tasks at once in one process).

It prints frames per second for each, the Dask scheduler's overhead per
task (a round trip of 200 empty tasks), the bytes each task sends and
returns, and checks that every way wrote the same files, byte for byte.

    python3 benches/sequence.py [--frames 24] [--size 400x300] [--json OUT]

Needs the glint binary (target/release/glint) and the module with its
dask extra (pip install "./python[dask]"). A benchmark, not a test: its
figures go into docs/benchmarks.md.
"""

import argparse
import json
import os
import pickle
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import glint
from glint import _sequences

REPO = Path(__file__).resolve().parents[1]


def cpu_children():
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def cpu_self():
    r = resource.getrusage(resource.RUSAGE_SELF)
    return r.ru_utime + r.ru_stime


def files(folder):
    return {p.name: p.read_bytes() for p in sorted(Path(folder).glob("*.png"))}


def noop(x):
    return x


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--frames", type=int, default=24)
    ap.add_argument("--size", default="400x300")
    ap.add_argument("--scene", default=str(REPO / "scenes" / "default.toml"))
    ap.add_argument("--json", help="also write the figures here")
    args = ap.parse_args()
    width, height = map(int, args.size.split("x"))
    binary = os.environ.get("GLINT_BIN", str(REPO / "target" / "release" / "glint"))
    flags = dict(width=width, height=height, aa="adaptive")
    scene = glint.load(args.scene)
    cams = scene.turntable(args.frames)
    rows = {}
    tmp = Path(tempfile.mkdtemp(prefix="glint-seq-"))

    # (a) the command line.
    cpu0 = cpu_children()
    start = time.perf_counter()
    subprocess.run([binary, "render", args.scene, "--turntable", str(args.frames),
                    "--width", str(width), "--height", str(height), "--aa", "adaptive",
                    "-q", "-o", str(tmp / "a" / "f_####.png")], check=True)
    wall = time.perf_counter() - start
    rows["a"] = dict(way="glint render --turntable (one process, 2 threads)", wall_s=wall,
                     cpu_s=cpu_children() - cpu0)

    # (b) render_frames here.
    cpu0 = cpu_self()
    start = time.perf_counter()
    for _ in glint.render_frames(scene, cams, out=str(tmp / "b" / "f_####.png"), **flags):
        pass
    wall = time.perf_counter() - start
    rows["b"] = dict(way="render_frames, no client (this process, 2 threads)", wall_s=wall,
                     cpu_s=cpu_self() - cpu0)

    from distributed import Client, LocalCluster

    source = _sequences._source(scene)
    task_bytes = len(pickle.dumps(([(0, args.frames, cams[0])], dict(flags, threads=1))))
    result_bytes = None
    for key, workers, threads, label in [
        ("c", 2, 1, "Dask LocalCluster 2 processes x 1 thread, glint 1 thread a task"),
        ("d", 1, 2, "Dask LocalCluster 1 process x 2 threads, glint 1 thread a task"),
    ]:
        with LocalCluster(n_workers=workers, threads_per_worker=threads, processes=True,
                          dashboard_address=None) as cluster, Client(cluster) as client:
            # Warm: the workers import glint and load the scene once.
            list(glint.render_frames(scene, cams[:workers * threads], client=client,
                                     threads=1, width=16, height=12))
            start = time.perf_counter()
            for _ in glint.render_frames(scene, cams, client=client, threads=1,
                                         out=str(tmp / key / "f_####.png"), **flags):
                pass
            wall = time.perf_counter() - start
            # The scheduler's own cost: 200 empty tasks, submitted and gathered.
            start = time.perf_counter()
            client.gather([client.submit(noop, k, pure=False) for k in range(200)])
            overhead_ms = (time.perf_counter() - start) / 200 * 1000
            if result_bytes is None:
                fut = client.submit(_sequences._render_chunk, client.scatter([source], broadcast=True, hash=False)[0],
                                    [(0, args.frames, cams[0])], dict(flags, threads=1),
                                    pure=False)
                result_bytes = len(pickle.dumps(fut.result()))
        rows[key] = dict(way=label, wall_s=wall, cpu_s=None, task_overhead_ms=overhead_ms)

    reference = files(tmp / "a")
    for key in "bcd":
        same = files(tmp / key) == reference
        rows[key]["same_bytes_as_a"] = same
        if not same:
            print(f"({key}) wrote other bytes than the command line", file=sys.stderr)
    for r in rows.values():
        r["frames_per_s"] = args.frames / r["wall_s"]

    print(f"{args.frames}-frame turntable of {Path(args.scene).name} at {width}x{height}, "
          f"adaptive AA, {os.cpu_count()} cores")
    print("| way | wall (s) | CPU (s) | frames/s | Dask overhead per task | same bytes |")
    print("|---|---:|---:|---:|---:|---|")
    for key, r in rows.items():
        cpu = f"{r['cpu_s']:.2f}" if r["cpu_s"] is not None else "-"
        over = f"{r['task_overhead_ms']:.1f} ms" if "task_overhead_ms" in r else "-"
        same = "reference" if key == "a" else ("yes" if r["same_bytes_as_a"] else "NO")
        print(f"| ({key}) {r['way']} | {r['wall_s']:.2f} | {cpu} | {r['frames_per_s']:.1f} "
              f"| {over} | {same} |")
    sent = len(pickle.dumps(source))
    print(f"bytes sent: the scene once per worker {sent:,} (scattered); per task "
          f"{task_bytes:,} (cameras, flags); returned per frame {result_bytes:,} "
          f"(the frame's values, 64-bit floats)")
    if args.json:
        Path(args.json).write_text(json.dumps(dict(rows=rows, scene_bytes=sent,
                                                   task_bytes=task_bytes,
                                                   result_bytes=result_bytes), indent=2))


if __name__ == "__main__":
    main()
