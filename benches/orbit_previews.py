#!/usr/bin/env python3
"""How close the previews a user sees while orbiting are to the picture
they stand for: the viewer's orbit benchmark with every shown preview
saved, each compared with the final image at its camera.

    cargo build --release
    python3 benches/orbit_previews.py scenes/default.toml --hz 60
    python3 benches/orbit_previews.py scenes/spd/balls.nff --hz 120 --keep /tmp/balls

One run:

1. `xvfb-run glint view SCENE --orbit-bench SECONDS --event-hz HZ
   --save-previews DIR` drags the camera round the scene in a real window
   and writes each preview shown, as shown (full image size), with the
   record of the final image at that preview's camera;
2. `glint render --from-png preview.png` renders that final image for
   each preview (what the preview stands for, converged);
3. the PSNR of each preview against its final image (8-bit sRGB, all
   three channels), and `glint bench SCENE --octree-only` for the time
   `glint render` takes for the same passes at the same size.

It prints the benchmark's JSON with these fields added:
`psnr_db_median`, `psnr_db_p5` (the 5th percentile: 95 % of the previews
are at least this close), `psnr_db_min`, `psnr_previews` (how many were
compared), `render_s` (glint render's time for the final passes, median
of 3) and `final_over_render` (the viewer's `final_ms` over it). With
`--per-preview` the PSNR of every preview is listed too; `--every K`
compares every K-th preview only (for scenes whose final images are slow).

Needs xvfb-run, NumPy and Pillow (`pip install numpy pillow`). A 5 s drag
at 60 Hz shows 100 to 200 previews; rendering their final images takes
one to three minutes on 2 cores for the default scene.
"""

import argparse
import json
import os
import shutil
import subprocess
import sys
import tempfile

import numpy as np
from PIL import Image

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
GLINT = os.path.join(ROOT, "target", "release", "glint")


def run(args, **kw):
    done = subprocess.run(args, cwd=ROOT, stdout=subprocess.PIPE, text=True, check=False, **kw)
    if done.returncode != 0:
        sys.exit(f"orbit_previews: `{' '.join(args)}` failed with status {done.returncode}")
    return done.stdout


def rgb(path):
    return np.asarray(Image.open(path).convert("RGB"), dtype=np.float64)


def psnr(a, b):
    mse = float(np.mean((a - b) ** 2))
    return float("inf") if mse == 0 else 10 * np.log10(255.0**2 / mse)


def percentile(values, q):
    """Nearest rank, as the orbit benchmark's own percentiles."""
    s = sorted(values)
    rank = max(1, min(len(s), int(np.ceil(q * len(s)))))
    return s[rank - 1]


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("scene")
    p.add_argument("--hz", type=float, default=60.0, help="pointer events a second (default 60)")
    p.add_argument("--seconds", type=float, default=5.0, help="length of the drag (default 5)")
    p.add_argument("--window", default="1400x860")
    p.add_argument("--keep", metavar="DIR", help="keep the previews and final images here")
    p.add_argument("--per-preview", action="store_true", help="list every preview's PSNR")
    p.add_argument("--every", type=int, default=1, metavar="K",
                   help="compare every K-th preview only (scenes whose final images are slow)")
    p.add_argument("--env", action="append", default=[], metavar="NAME=VALUE",
                   help="environment for the viewer (e.g. GLINT_PREVIEW=reduced)")
    args = p.parse_args()
    if not os.path.exists(GLINT):
        sys.exit(f"orbit_previews: build first (cargo build --release): no {GLINT}")
    work = args.keep or tempfile.mkdtemp(prefix="glint-orbit-")
    if args.keep and os.path.isdir(work):
        for name in os.listdir(work):
            if name.startswith(("preview_", "final_")) and name.endswith(".png"):
                os.remove(os.path.join(work, name))
    os.makedirs(work, exist_ok=True)
    env = dict(os.environ)
    for item in args.env:
        name, _, value = item.partition("=")
        env[name] = value
    try:
        out = run(["xvfb-run", "-a", "-s", "-screen 0 1440x900x24", "timeout", "600", GLINT, "view",
                   args.scene, "--orbit-bench", str(args.seconds), "--event-hz", str(args.hz),
                   "--window", args.window, "--save-previews", work],
                  env=env, stderr=subprocess.DEVNULL)
        report = json.loads(out.strip().splitlines()[-1])
        if "previews_save_error" in report:
            sys.exit(f"orbit_previews: the viewer could not save its previews: "
                     f"{report['previews_save_error']}")
        previews = sorted(n for n in os.listdir(work) if n.startswith("preview_"))
        previews = previews[::max(1, args.every)]
        values = []
        for k, name in enumerate(previews):
            final = os.path.join(work, name.replace("preview_", "final_"))
            run([GLINT, "render", "--from-png", os.path.join(work, name), "-o", final, "-q"])
            values.append(psnr(rgb(os.path.join(work, name)), rgb(final)))
            print(f"\r  {k + 1}/{len(previews)} final images", end="", file=sys.stderr, flush=True)
        print(file=sys.stderr)
        w, h = report["image"]
        bench = json.loads(run([GLINT, "bench", args.scene, "--size", f"{w}x{h}", "--octree-only",
                                "--repeat", "3", "--format", "json"]))
        render_s = bench[0]["octree_on"]["render_s"]
        if values:
            report["psnr_db_median"] = round(percentile(values, 0.5), 2)
            report["psnr_db_p5"] = round(percentile(values, 0.05), 2)
            report["psnr_db_min"] = round(min(values), 2)
        report["psnr_previews"] = len(values)
        report["render_s"] = round(render_s, 4)
        report["final_over_render"] = round(report["final_ms"] / 1000.0 / render_s, 2)
        if args.per_preview:
            report["psnr_db"] = [round(v, 2) for v in values]
        print(json.dumps(report))
    finally:
        if not args.keep:
            shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()
