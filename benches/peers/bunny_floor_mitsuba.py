#!/usr/bin/env python3
"""Peer benchmark: the bunny on a floor, one point light, direct lighting with
hard shadows only, 1024x768 at 16 samples per pixel, rendered by Mitsuba 3.

The matching glint scene is bunny_floor.toml beside this file (max_depth = 1:
eye rays plus one shadow ray per light per hit, no reflection/refraction).

Scene (same geometry and camera as glint's):
  * bunny: assets/bunny.obj through Mitsuba's `obj` plugin, to_world = scale 0.1
    (glint: scale 0.1, no rotation, no translation); smooth vertex normals, as
    glint's `smooth = true`.
  * floor: a `rectangle` mapped by an exact matrix (no trigonometric rounding)
    to the square x, z in [-2, 2] at y = min_y of the placed bunny (min vertex
    y of the OBJ times 0.1), normal +y.
  * light: a `point` emitter at [-2, 4, 4]. Mitsuba's point light falls off
    with 1/r^2 and glint's does not; the intensity is set to pi * r^2 at the
    bunny's centre so the brightness is comparable. It does not affect timing.
  * materials: `diffuse` with reflectance kd * color = 0.8 * 0.8.
  * camera: `perspective`, fov_axis = "y", fov = 40 (glint's fov is vertical,
    edge to edge), the same eye / lookat / up; `box` reconstruction filter
    (glint averages its samples per pixel, a box).
  * integrator: `direct` with emitter_samples = 1 and bsdf_samples = 0: one
    camera ray and, where it hits, exactly one shadow ray to the point light
    per sample (BSDF sampling could never hit a point light anyway; with 0 it
    casts no extra ray).
  * sampler: `independent`, 16 spp. Mitsuba's 16 samples per pixel are
    uniformly RANDOM positions in the pixel; glint's 16 are a regular 4x4 grid
    at offsets (k + 0.5)/4. Same ray count, different positions.

Variant: `llvm_ad_rgb` (Dr.Jit's LLVM backend, vectorised and multi-threaded).
Dr.Jit loads libLLVM at run time: the file named by the environment variable
DRJIT_LIBLLVM_PATH, else a libLLVM it finds on the library path (here:
libLLVM-15.so.1 before libllvm19 was installed, libLLVM.so.19.1 after; run.sh
sets DRJIT_LIBLLVM_PATH to LLVM 19 explicitly when it is there). With
Dr.Jit 1.5 and Debian 12's libllvm15 the variant loads and tiny kernels run,
but the render kernel ABORTS the process with "LLVM ERROR: Cannot select:
... f32 = fminimum" (LLVM 15 cannot lower llvm.minimum/maximum on x86; 16
was not tried). Debian 12 ships `libllvm19` (bookworm updates,
1:19.1.7-3~deb12u1), which works; run.sh installs it when needed. Because the
failure is an abort, the variant is first tried by rendering a 32x24 image in
a child process; if that fails the script falls back to `scalar_rgb` and says
so in the JSON ("variant" and "fallback_reason") and on stderr.

Threads: Dr.Jit's nanothread pool runs the LLVM kernels (and Mitsuba's
scalar render blocks); `--threads T` calls drjit.set_thread_count(T) (the
calling thread counts as one of the T). Default: Dr.Jit's default, one per
core.

Timing: one warm-up render (includes JIT compilation of the kernel, or
loading it from Dr.Jit's on-disk kernel cache ~/.drjit after the first
process that compiled it; the seed does not change the kernel), then
the median of `--runs` (default 3) timed renders; each timed span is
mi.render(...) plus drjit.eval/sync of the image, so the kernel has really
finished. Scene loading is reported separately as `load_s`.
"""

import argparse
import json
import math
import os
import statistics
import subprocess
import sys
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import common  # noqa: E402

import drjit as dr  # noqa: E402
import mitsuba as mi  # noqa: E402


def probe_variant(variant):
    """Render a tiny version of the scene with `variant` in a child process.

    An LLVM that is too old for Dr.Jit's kernels does not raise: it aborts
    the process ("LLVM ERROR: Cannot select: ... fminimum" with LLVM 15, which
    lacks x86 lowering of llvm.minimum/maximum), so the test must run in a
    separate process. Returns None if it worked, else the reason."""
    try:
        res = subprocess.run(
            [sys.executable, os.path.abspath(__file__), "--probe", "--variant", variant],
            capture_output=True, text=True, timeout=600,
        )
    except subprocess.TimeoutExpired:
        return "probe render timed out"
    if res.returncode == 0:
        return None
    lines = [ln for ln in (res.stderr + res.stdout).splitlines() if ln.strip()]
    first = next((ln for ln in lines if "ERROR" in ln or "Error" in ln), lines[0] if lines else "")
    return f"probe exited with code {res.returncode}: {first.strip()}"


def choose_variant(wanted, probe=True):
    """Set `wanted` if a probe render with it works, else scalar_rgb.
    Returns (variant, reason for falling back or None)."""
    reason = probe_variant(wanted) if (probe and wanted != "scalar_rgb") else None
    if reason is None:
        try:
            mi.set_variant(wanted)
            return wanted, None
        except Exception as exc:  # noqa: BLE001 - any failure means: fall back
            reason = f"{type(exc).__name__}: {exc}"
    mi.set_variant("scalar_rgb")
    return "scalar_rgb", reason


def scene_dict(width, height, spp, framing="fill"):
    eye, lookat = common.FRAMINGS[framing]
    verts, _faces = common.load_obj(common.BUNNY_OBJ)
    min_y = float(verts[:, 1].min()) * common.BUNNY_SCALE
    centre = (verts.min(axis=0) + verts.max(axis=0)) * 0.5 * common.BUNNY_SCALE
    r2 = sum((common.LIGHT[k] - centre[k]) ** 2 for k in range(3))
    albedo = 0.8 * 0.8  # kd * color of glint's default material colour
    T = mi.ScalarTransform4f
    floor_to_world = T([
        [2.0, 0.0, 0.0, 0.0],
        [0.0, 0.0, 2.0, min_y],
        [0.0, -2.0, 0.0, 0.0],
        [0.0, 0.0, 0.0, 1.0],
    ])  # rectangle (x, y) in [-1, 1]^2, z = 0  ->  (2x, min_y, -2y), normal +y
    return {
        "type": "scene",
        "integrator": {"type": "direct", "emitter_samples": 1, "bsdf_samples": 0},
        "sensor": {
            "type": "perspective",
            "fov_axis": "y",
            "fov": common.FOV_DEG,
            "to_world": T().look_at(origin=list(eye), target=list(lookat), up=list(common.UP)),
            "sampler": {"type": "independent", "sample_count": spp},
            "film": {
                "type": "hdrfilm",
                "width": width,
                "height": height,
                "rfilter": {"type": "box"},
                "pixel_format": "rgb",
            },
        },
        "light": {
            "type": "point",
            "position": list(common.LIGHT),
            "intensity": {"type": "rgb", "value": [math.pi * r2] * 3},
        },
        "bunny": {
            "type": "obj",
            "filename": common.BUNNY_OBJ,
            "to_world": T().scale(common.BUNNY_SCALE),
            "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [albedo] * 3}},
        },
        "floor": {
            "type": "rectangle",
            "to_world": floor_to_world,
            "bsdf": {"type": "diffuse", "reflectance": {"type": "rgb", "value": [albedo] * 3}},
        },
    }, min_y


def render_once(scene, spp, seed):
    t0 = time.perf_counter()
    img = mi.render(scene, spp=spp, seed=seed)
    dr.eval(img)
    dr.sync_thread()
    return time.perf_counter() - t0, img


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--threads", type=int, default=0, help="Dr.Jit threads (default: one per core)")
    ap.add_argument("--runs", type=int, default=3, help="timed renders; the median is reported (default 3)")
    ap.add_argument("--spp", type=int, default=16)
    ap.add_argument("--width", type=int, default=common.WIDTH)
    ap.add_argument("--height", type=int, default=common.HEIGHT)
    ap.add_argument("--variant", default="llvm_ad_rgb")
    ap.add_argument("--framing", choices=sorted(common.FRAMINGS), default="fill",
                    help="camera: fill (bunny_floor.toml) or small (bunny_floor_small.toml)")
    ap.add_argument("--out", help="write the last image here (.exr, or .png tonemapped by Mitsuba)")
    ap.add_argument("--no-probe", action="store_true",
                    help="skip the child-process test render of the variant")
    ap.add_argument("--probe", action="store_true", help=argparse.SUPPRESS)
    args = ap.parse_args()

    if args.probe:
        # Child of probe_variant(): a 32x24, 1 spp render of the same scene.
        mi.set_variant(args.variant)
        d, _ = scene_dict(32, 24, 1)
        render_once(mi.load_dict(d), 1, seed=0)
        print("ok")
        return

    variant, fallback_reason = choose_variant(args.variant, probe=not args.no_probe)
    if args.threads > 0:
        dr.set_thread_count(args.threads)

    t0 = time.perf_counter()
    d, min_y = scene_dict(args.width, args.height, args.spp, args.framing)
    scene = mi.load_dict(d)
    load_s = time.perf_counter() - t0

    warmup_s, img = render_once(scene, args.spp, seed=0)
    times = []
    for k in range(args.runs):
        dt, img = render_once(scene, args.spp, seed=k + 1)
        times.append(dt)

    if args.out:
        mi.util.write_bitmap(args.out, img)

    out = {
        "peer": "mitsuba",
        "mitsuba_version": mi.__version__,
        "drjit_version": dr.__version__,
        "variant": variant,
        "seconds": statistics.median(times),
        "spp": args.spp,
        "width": args.width,
        "height": args.height,
        "threads": dr.thread_count(),
        "llvm_version": ".".join(map(str, dr.detail.llvm_version())) if variant.startswith("llvm") else None,
        "warmup_s": warmup_s,
        "load_s": load_s,
        "runs_s": times,
        "floor_y": min_y,
        "sampler": "independent (random sample positions; glint uses a regular 4x4 grid)",
    }
    if fallback_reason is not None:
        out["fallback_reason"] = f"{args.variant} unavailable, fell back to scalar_rgb: {fallback_reason}"
        print(f"WARNING: {out['fallback_reason']}", file=sys.stderr)
    print(json.dumps(out))


if __name__ == "__main__":
    main()
