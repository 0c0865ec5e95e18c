#!/usr/bin/env python3
"""Measures every figure the README and the user guide quote and writes it
into the file that holds it.

    cargo build --release
    python3 benches/readme_figures.py              # every section (about an hour on 2 cores)
    python3 benches/readme_figures.py spd-table    # one or more sections
    python3 benches/readme_figures.py --list       # the sections, their files and what they measure
    python3 benches/readme_figures.py --reuse-sweep prediction
                                                   # format the committed sweep again

Each section runs glint's own commands (target/release/glint, never built
here) and replaces the text between `<!-- figures:NAME -->` and
`<!-- /figures:NAME -->`, so no quoted figure is typed by hand. A block
lives in exactly one of README.md and docs/**/*.md, each marker on a line
of its own; the script finds it there (a block in none of them, or in more
than one place, is an error, reported before anything is measured) and
rewrites that file through a temporary file renamed into place. Figures
outside the blocks are history (what a change measured when it was made)
and say so; docs/notes/experiments.md keeps most of them. Needs Python 3
(standard library only); the `kernels` section needs valgrind, `peers` what
benches/peers/run.sh installs.
"""

import glob
import json
import os
import platform
import re
import statistics
import struct
import subprocess
import sys
import tempfile
import time
import zlib

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
GLINT = os.path.join(ROOT, "target", "release", "glint")
README = os.path.join(ROOT, "README.md")
DOCS = os.path.join(ROOT, "docs")
SPD = ["balls", "gears", "mount", "rings", "teapot", "tetra", "tree"]
SPD_FILES = [f"scenes/spd/{s}.nff" for s in SPD]


def run(args, **kw):
    """Runs a command from the repository root; its stdout as text."""
    shown = " ".join(args)
    print(f"  $ {shown}", file=sys.stderr, flush=True)
    done = subprocess.run(args, cwd=ROOT, stdout=subprocess.PIPE, text=True, check=False, **kw)
    if done.returncode != 0:
        sys.exit(f"readme_figures: `{shown}` failed with status {done.returncode}")
    return done.stdout


def glint(*args):
    return run([GLINT, *args])


def bench_json(*args):
    return json.loads(glint("bench", *args, "--format", "json"))


def cores():
    return os.cpu_count() or 1


def cpu_model():
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or "unknown CPU"


def stamp(section):
    day = time.strftime("%Y-%m-%d", time.gmtime())
    return (
        f"*Measured {day} on {cores()} cores ({cpu_model()}) by "
        f"`python3 benches/readme_figures.py {section}`.*"
    )


def table_rows(markdown):
    """The cells of a markdown table's body rows."""
    rows = []
    for line in markdown.splitlines():
        if line.startswith("|") and not line.startswith("|---"):
            rows.append([c.strip() for c in line.strip().strip("|").split("|")])
    return rows[1:]


def seconds(cell):
    """`25.95 (est., rows 1/6)` -> 25.95."""
    return float(cell.split()[0])


def fmt(x, digits=2):
    return f"{x:,.{digits}f}"


# --- sections -----------------------------------------------------------


def spd_table():
    """SPD scenes at 512x512, octree on and off: the Benchmark table."""
    out = glint(
        "bench", *SPD_FILES, "--size", "512x512", "--samples", "1", "--repeat", "3",
        "--brute-force-budget", "2e9",
    )
    table = "\n".join(l for l in out.splitlines() if l.startswith("|"))
    rows = table_rows(table)
    on = {r[0]: seconds(r[5]) for r in rows}
    speedups = [float(r[7].rstrip("x")) for r in rows]
    tests = {r[0]: (float(r[9]), float(r[12])) for r in rows}
    slowest = max(on, key=on.get)
    build = {r[0]: float(r[4]) for r in rows}[slowest]
    worst = max(tests, key=lambda s: tests[s][0] / tests[s][1])
    ratio = tests[worst][0] / tests[worst][1]
    return (
        f"{table}\n\n"
        f"With the octree every SPD scene renders in {min(on.values()):.2f} to "
        f"{max(on.values()):.2f} s ({slowest.removesuffix('.nff')} the slowest; its "
        f"{build:.2f} s build is timed apart), {min(speedups):.0f}x to "
        f"{max(speedups):.0f}x faster than brute force, with at most {ratio:.2f}x the "
        f"intersection tests per ray of the best of Havran's octrees "
        f"({worst.removesuffix('.nff')}: {tests[worst][0]:.2f} against "
        f"{tests[worst][1]:.2f}).\n\n{stamp('spd-table')}"
    )


def spd_protocol():
    """SPD scenes under --protocol spd, octree only."""
    rows = bench_json(*SPD_FILES, "--protocol", "spd", "--octree-only", "--repeat", "3")
    times = ", ".join(
        f"{os.path.basename(r['scene']).removesuffix('.nff')} {r['octree_on']['render_s']:.2f} s"
        for r in rows
    )
    return f"Under `--protocol spd`: {times}.\n\n{stamp('spd-protocol')}"


def scaling():
    """The SPD size series: time against shape count."""
    files = (
        [f"scenes/spd/sizes/balls_s{k}.nff" for k in (1, 2, 3)]
        + ["scenes/spd/balls.nff", "scenes/spd/sizes/balls_s5.nff", "scenes/spd/sizes/tetra_s4.nff",
           "scenes/spd/tetra.nff", "scenes/spd/sizes/tetra_s8.nff"]
    )
    rows = bench_json(*files, "--size", "512x512", "--samples", "1", "--repeat", "1",
                      "--brute-force-budget", "5e8")
    lines = [
        "| scene | shapes | build (s) | memory (KiB) | octree on (s) | octree off (s) | speedup | N_IT | N_TS |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---:|",
    ]
    for r in rows:
        off = r["octree_off"]
        off_s = f"{off['render_s']:.2f}"
        if off.get("estimated"):
            off_s += f" (est., rows 1/{r['compared_rows_every']})"
        name = os.path.basename(r["scene"]).removesuffix(".nff")
        lines.append(
            f"| {name} | {r['shapes']} | {r['build_s']:.3f} | "
            f"{r['octree_stats']['memory_bytes'] // 1024} | {r['octree_on']['render_s']:.3f} | "
            f"{off_s} | {r['speedup']:.0f}x | {r['octree_on']['intersection_tests_per_ray']:.2f} | "
            f"{r['octree_on']['traversal_steps_per_ray']:.2f} |"
        )
    return "\n".join(lines) + f"\n\n{stamp('scaling')}"


def peers():
    """glint against Embree 4 and Mitsuba 3 (benches/peers/run.sh)."""
    out = run(["bash", "benches/peers/run.sh", "2"])
    table = "\n".join(l for l in out.splitlines() if l.startswith("|"))
    return f"{table}\n\n{stamp('peers')}"


def instructions(args, width, height, env=None, binary=GLINT):
    """Instructions per ray: cachegrind at the working size minus the same
    at 1x1 (loading and the octree build), over the render's rays. `env`
    adds environment variables (GLINT_PACKETS=off: every ray single);
    `binary` is the glint that renders (another commit's, for the step
    table)."""
    env = {**os.environ, "GLINT_SIMD": "avx2", **(env or {})}

    def count(w, h):
        with tempfile.TemporaryDirectory() as d:
            out = os.path.join(d, "cg.out")
            run(["valgrind", "--tool=cachegrind", "--cache-sim=no", f"--cachegrind-out-file={out}",
                 binary, "render", *args, "-o", os.path.join(d, "x.png"), "--width", str(w),
                 "--height", str(h), "--threads", "1", "-q"],
                env=env, stderr=subprocess.DEVNULL)
            with open(out) as f:
                for line in f:
                    if line.startswith("summary:"):
                        return int(line.split()[1])
        sys.exit("readme_figures: no cachegrind summary")
    with tempfile.TemporaryDirectory() as d:
        stats = json.loads(run([binary, "render", *args, "-o", os.path.join(d, "x.png"),
                                "--width", str(width), "--height", str(height),
                                "--threads", "1", "--stats", "-q"], env=env))
    return (count(width, height) - count(1, 1)) / stats["rays"]["total"]


# Instructions per ray before each step of issue 20, measured when each
# step was made (history: the code they measured is gone).
KERNEL_HISTORY = {
    "bunny primary rays, normals view, 256x192": (2655, 1953, 1066, 779),
    "bunny on floor, 16 spp, 128x96": (3552, 3203, 1326, 1294),
    "`scenes/default.toml`, 1 spp, 200x150": (2056, 1812, 1573, 1521),
}


def kernels():
    """Instructions per ray (valgrind cachegrind) on three workloads."""
    workloads = [
        ("bunny primary rays, normals view, 256x192",
         ["scenes/bunny.toml", "--view", "normals", "--samples", "1"], 256, 192),
        ("bunny on floor, 16 spp, 128x96", ["benches/peers/bunny_floor.toml"], 128, 96),
        ("`scenes/default.toml`, 1 spp, 200x150", ["scenes/default.toml", "--samples", "1"], 200, 150),
    ]
    lines = [
        "| workload | before (issue 20) | lean single-ray walk | packets | kept scratch | now |",
        "|---|---:|---:|---:|---:|---:|",
    ]
    for name, args, w, h in workloads:
        now = instructions(args, w, h)
        before = KERNEL_HISTORY[name]
        lines.append(f"| {name} | {before[0]:,} | {before[1]:,} | {before[2]:,} | {before[3]:,} | {now:,.0f} |")
    lines += [
        "",
        "| single and secondary rays (issue 37) | before the wide walk | now |",
        "|---|---:|---:|",
    ]
    for name, args, w, h, env in SINGLE_RAY_WORKLOADS:
        now = instructions(args, w, h, env)
        lines.append(f"| {name} | {SINGLE_RAY_HISTORY[name]:,} | {now:,.0f} |")
    return "\n".join(lines) + f"\n\n{stamp('kernels')}"


def secondary_steps():
    """Instructions per ray at each step of issue 37, built from git
    (benches/step_history.py; about 20 minutes)."""
    import step_history

    return f"{step_history.table(GLINT, instructions)}\n\n{stamp('secondary-steps')}"


# Workloads that live on single rays (shadow rays, glass and mirrors), with
# instructions per ray measured before issue 37's wide walk (history).
SINGLE_RAY_WORKLOADS = [
    ("bunny primary rays, every ray single (`GLINT_PACKETS=off`), 256x192",
     ["scenes/bunny.toml", "--view", "normals", "--samples", "1"], 256, 192,
     {"GLINT_PACKETS": "off"}),
    ("SPD gears, 1 spp, 128x128", ["scenes/spd/gears.nff", "--samples", "1"], 128, 128, None),
    ("SPD rings, 1 spp, 128x128", ["scenes/spd/rings.nff", "--samples", "1"], 128, 128, None),
]
SINGLE_RAY_HISTORY = {
    "bunny primary rays, every ray single (`GLINT_PACKETS=off`), 256x192": 1799,
    "SPD gears, 1 spp, 128x128": 4054,
    "SPD rings, 1 spp, 128x128": 4444,
}


def png_rgb(path):
    """The RGB bytes of an 8-bit RGB or RGBA, non-interlaced PNG (what glint
    writes)."""
    with open(path, "rb") as f:
        data = f.read()
    pos, idat, width = 8, b"", 0
    while pos < len(data):
        length, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + length]
        if kind == b"IHDR":
            width, height, depth, color = struct.unpack(">IIBB", body[:10])
            if depth != 8 or color not in (2, 6) or body[12] != 0:
                sys.exit(f"readme_figures: {path} is not 8-bit RGB(A), non-interlaced")
            channels = 3 if color == 2 else 4
        elif kind == b"IDAT":
            idat += body
        pos += 12 + length
    raw = zlib.decompress(idat)
    stride = width * channels
    out, prev, i = bytearray(), bytearray(stride), 0
    for _ in range(height):
        kind, line = raw[i], bytearray(raw[i + 1:i + 1 + stride])
        i += 1 + stride
        for x in range(stride):
            a = line[x - channels] if x >= channels else 0
            b = prev[x]
            c = prev[x - channels] if x >= channels else 0
            if kind == 1:
                line[x] = (line[x] + a) & 255
            elif kind == 2:
                line[x] = (line[x] + b) & 255
            elif kind == 3:
                line[x] = (line[x] + (a + b) // 2) & 255
            elif kind == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                pred = a if pa <= pb and pa <= pc else (b if pb <= pc else c)
                line[x] = (line[x] + pred) & 255
        prev = line
        for x in range(0, stride, channels):
            out += line[x:x + 3]
    return bytes(out)


def psnr(a, b):
    mse = sum((x - y) ** 2 for x, y in zip(a, b)) / len(a)
    return float("inf") if mse == 0 else 10 * __import__("math").log10(255 ** 2 / mse)


def adaptive():
    """scenes/default.toml at 800x600: AA off, adaptive, full."""
    scene = "scenes/default.toml"
    times = {
        aa: bench_json(scene, "--aa", aa, "--octree-only", "--repeat", "5")[0]["octree_on"]["render_s"]
        for aa in ("off", "adaptive", "full")
    }
    with tempfile.TemporaryDirectory() as d:
        images, refined = {}, None
        for aa in ("off", "adaptive", "full"):
            png = os.path.join(d, f"{aa}.png")
            stats = json.loads(glint("render", scene, "--aa", aa, "-o", png, "--stats", "-q"))
            if aa == "adaptive":
                refined = stats["refined_fraction"]
            images[aa] = png_rgb(png)
    return (
        f"On `{scene}` at its 800x600 (`glint bench {scene} --aa off|adaptive|full "
        f"--octree-only --repeat 5`): {times['off']:.3f} s, {times['adaptive']:.3f} s and "
        f"{times['full']:.3f} s: adaptive costs {100 * times['adaptive'] / times['full']:.0f}% of "
        f"the full grid, refines {100 * refined:.1f}% of the pixels and is "
        f"{psnr(images['adaptive'], images['full']):.1f} dB from it (1 sample alone: "
        f"{psnr(images['off'], images['full']):.1f} dB; PSNR of the 8-bit PNGs).\n\n{stamp('adaptive')}"
    )


def cost_view():
    """Cost view figures on the teapot, and the view's overhead."""
    scene = "scenes/spd/teapot.nff"
    with tempfile.TemporaryDirectory() as d:
        cost = {}
        for octree in ("off", "on"):
            stats = json.loads(glint("render", scene, "--width", "512", "--height", "512",
                                     "--view", "cost", "--octree", octree, "-o",
                                     os.path.join(d, "c.png"), "--stats", "-q"))
            cost[octree] = stats["cost_per_pixel"]

        def whole_command(*view):
            runs = []
            for _ in range(5):
                start = time.perf_counter()
                glint("render", "scenes/spd/balls.nff", "--width", "512", "--height", "512",
                      *view, "-o", os.path.join(d, "b.png"), "-q")
                runs.append(time.perf_counter() - start)
            return statistics.median(runs)
        shaded = whole_command()
        with_cost = whole_command("--view", "cost")
    span = lambda c: f"{c['min']:,.0f} to {c['max']:,.0f} tests per pixel, mean {c['mean']:,.1f}"
    return (
        f"On the teapot at 512x512: {span(cost['off'])} without the octree, against "
        f"{span(cost['on'])} with it (`glint render {scene} --width 512 --height 512 --view cost "
        f"--octree off -o off.png --stats`, and `--octree on`: `cost_per_pixel`). With the view "
        f"on, `glint render scenes/spd/balls.nff --width 512 --height 512 --view cost` takes "
        f"{with_cost:.3f} s against {shaded:.3f} s shaded (median of 5, whole command).\n\n"
        f"{stamp('cost-view')}"
    )


def study():
    """glint study: the speed-against-accuracy summary."""
    glint("study", "scenes/default.toml", "scenes/spd/balls.nff", "scenes/spd/tetra.nff",
          "scenes/spd/teapot.nff", "--out", "benches/study", "--size", "320x240", "--repeat", "3")
    with open(os.path.join(ROOT, "benches", "study", "study.md")) as f:
        text = f.read()
    summary = text.split("## Summary", 1)[1]
    table = []
    for line in summary.strip().splitlines():
        if not line.startswith("|"):
            break
        table.append(line)
    return "\n".join(table) + f"\n\n{stamp('study')}"


REUSE_SWEEP = False


def prediction():
    """The octree cost prediction against the measured sweep."""
    raw = os.path.join(ROOT, "benches", "prediction-sweep.json")
    if REUSE_SWEEP:
        # The committed sweep, formatted again (the sweep takes about 9 minutes).
        with open(raw) as f:
            sweep = f.read()
        when = run(["git", "log", "-1", "--format=%cs", "--", "benches/prediction-sweep.json"]).strip()
        made = (f"*Sweep measured {when} (benches/prediction-sweep.json), formatted by "
                f"`python3 benches/readme_figures.py --reuse-sweep prediction`.*")
    else:
        sweep = glint("bench", *SPD_FILES, "--size", "512x512", "--samples", "1", "--repeat", "3",
                      "--sweep", "--sweep-depths", "6,8,10", "--sweep-leaf-sizes", "2,4,8",
                      "--format", "json")
        with open(raw, "w") as f:
            f.write(sweep)
        made = stamp("prediction")
    out = run([sys.executable, "benches/prediction.py"], input=sweep)
    with open(os.path.join(ROOT, "benches", "prediction.md"), "w") as f:
        f.write(out)
    # The guide quotes the summary tables; every row is in benches/prediction.md.
    tables = out.split("\n\n", 1)[1].strip()
    return f"{tables}\n\n{made}"


SIMD_WORKLOADS = [
    ("bunny primary rays, normals view, 1024x768",
     ["scenes/bunny.toml", "--view", "normals", "--samples", "1", "--size", "1024x768"]),
    ("bunny on floor, 16 spp, 512x384", ["benches/peers/bunny_floor.toml", "--size", "512x384"]),
    ("`scenes/default.toml`, 1 spp, 800x600", ["scenes/default.toml", "--samples", "1"]),
    ("`scenes/default.toml`, adaptive 16 spp, 800x600", ["scenes/default.toml", "--aa", "adaptive"]),
    ("viewer preview \"1/2, no reflections\": default at 400x300, depth 1",
     ["scenes/default.toml", "--samples", "1", "--size", "400x300", "--max-depth", "1"]),
    ("SPD gears, 1 spp, 512x512", ["scenes/spd/gears.nff", "--size", "512x512", "--samples", "1"]),
    ("SPD rings, 1 spp, 512x512", ["scenes/spd/rings.nff", "--size", "512x512", "--samples", "1"]),
]


def simd():
    """Scalar, AVX2 and AVX-512 on the guide's workloads, interleaved."""
    levels = [l for l in ("scalar", "avx2", "avx512")
              if json.loads(glint("info", "--simd", "--json"))["available"].count(l)]
    default = json.loads(glint("info", "--simd", "--json"))["level"]
    rounds = 3
    lines = [
        "| workload (2 threads, medians) | " + " | ".join(levels) + " | "
        + " | ".join(f"{l} / avx2" for l in levels if l != "avx2") + " |",
        "|---|" + "---:|" * (2 * len(levels) - 1),
    ]
    slower = []
    for name, args in SIMD_WORKLOADS:
        times = {l: [] for l in levels}
        # Levels interleaved round by round, so a change in the machine's
        # load falls on all of them alike.
        for _ in range(rounds):
            for level in levels:
                out = run([GLINT, "bench", *args, "--octree-only", "--repeat", "3", "--format", "json"],
                          env={**os.environ, "GLINT_SIMD": level})
                times[level].append(json.loads(out)[0]["octree_on"]["render_s"])
        med = {l: statistics.median(t) for l, t in times.items()}
        cells = [f"{1000 * med[l]:,.1f} ms" + (" **(default)**" if l == default else "") for l in levels]
        ratios = [f"{med[l] / med['avx2']:.2f}" for l in levels if l != "avx2"]
        lines.append(f"| {name} | " + " | ".join(cells + ratios) + " |")
        if "avx512" in med:
            slower.append(med["avx512"] / med["avx2"])
    note = ""
    if slower:
        note = (f"\n\nAVX-512 takes {min(slower):.2f} to {max(slower):.2f} times AVX2's time "
                f"on these workloads ({rounds} rounds, levels interleaved; each cell the median "
                f"of the rounds' medians of 3).")
    return "\n".join(lines) + note + f"\n\n{stamp('simd')}"


def orbit_run(scene, hz, seconds=5, env=None):
    """One `glint view --orbit-bench` under Xvfb: its JSON report."""
    out = run(["xvfb-run", "-a", "-s", "-screen 0 1440x900x24", "timeout", "300", GLINT, "view", scene,
               "--orbit-bench", str(seconds), "--event-hz", str(hz), "--window", "1400x860"],
              env={**os.environ, **(env or {})}, stderr=subprocess.DEVNULL)
    return json.loads(out.strip().splitlines()[-1])


def orbit():
    """The viewer orbiting scenes/default.toml under Xvfb at 60 and 120 Hz."""
    scene = "scenes/default.toml"
    lines = [
        "| pointer events | previews shown | shown per s | started | cancelled | latency p50 | latency p95 "
        "| final pass | previews chosen (count, median) |",
        "|---|---:|---:|---:|---:|---:|---:|---:|---|",
    ]
    for hz in (60, 120):
        r = orbit_run(scene, hz)
        choices = "; ".join(f"{c['preview']} ({c['count']}, {c['median_ms']} ms)"
                            for c in sorted(r["choices"], key=lambda c: -c["count"]))
        lines.append(
            f"| {r['events']} at {hz} Hz | {r['previews_shown']} | {r['shown_per_s']} | "
            f"{r['previews_started']} | {r['previews_cancelled']} | {r['latency_ms_p50']} ms | "
            f"{r['latency_ms_p95']} ms | {r['final_ms']:,.0f} ms ({r['final_pass']}) | {choices} |"
        )
    return (
        "\n".join(lines)
        + f"\n\n`xvfb-run glint view {scene} --orbit-bench 5 --event-hz HZ --window 1400x860` "
        f"(5 s of dragging, {r['threads']} render threads, SIMD {r['simd']}, image {r['image'][0]}x{r['image'][1]})."
        + f"\n\n{stamp('orbit')}"
    )


PYTHON_RUN = """
import json, sys, time
import glint
scene_file, width, height, png = sys.argv[1], int(sys.argv[2]), int(sys.argv[3]), sys.argv[4]
start = time.perf_counter()
scene = glint.load(scene_file)
render_start = time.perf_counter()
frame = scene.render(width, height)
render_end = time.perf_counter()
frame.save(png)
end = time.perf_counter()
print(json.dumps({"total_s": end - start, "render_call_s": render_end - render_start}))
"""


def python_module():
    """The Python module against `glint render` for the same frames, in one
    run: each repeat times the command (a process: load, octree, render,
    PNG) and then the module in a fresh interpreter (the same steps, timed
    from `glint.load` to `frame.save`, import excluded)."""
    scene, repeats = "scenes/default.toml", 9
    lines = []
    with tempfile.TemporaryDirectory() as d:
        for (width, height), aa in (((800, 600), "adaptive"), ((800, 600), "off")):
            flags = ["--width", str(width), "--height", str(height), "--aa", aa]
            cli, module, call = [], [], []
            for _ in range(repeats):
                start = time.perf_counter()
                glint("render", scene, *flags, "-o", os.path.join(d, "cli.png"), "-q")
                cli.append(time.perf_counter() - start)
                # The scene's own anti-aliasing, set here as on the command line.
                code = PYTHON_RUN.replace("scene.render(width, height)",
                                          f"scene.render(width, height, aa={aa!r})")
                out = run([sys.executable, "-c", code, scene, str(width), str(height),
                           os.path.join(d, "py.png")])
                figures = json.loads(out)
                module.append(figures["total_s"])
                call.append(figures["render_call_s"])
            c, m = statistics.median(cli), statistics.median(module)
            lines.append(
                f"- `{scene}` at {width}x{height}, `aa={aa!r}`: `glint render` {c:.3f} s, "
                f"the module {m:.3f} s ({100 * (m / c - 1):+.1f}%; `render()` alone "
                f"{statistics.median(call):.3f} s); medians of {repeats}, interleaved"
            )
    return "\n".join(lines) + f"\n\n{stamp('python')}"


SECTIONS = {
    "spd-table": spd_table,
    "spd-protocol": spd_protocol,
    "scaling": scaling,
    "peers": peers,
    "kernels": kernels,
    "secondary-steps": secondary_steps,
    "adaptive": adaptive,
    "cost-view": cost_view,
    "study": study,
    "prediction": prediction,
    "simd": simd,
    "orbit": orbit,
    "python": python_module,
}


def doc_files():
    """The files a block may live in: README.md, then docs/**/*.md."""
    docs = sorted(glob.glob(os.path.join(DOCS, "**", "*.md"), recursive=True))
    return [README, *docs]


def block_pattern(name):
    """A whole block: its opening marker, any text, its closing marker, each
    marker on a line of its own."""
    return re.compile(
        rf"(^<!-- figures:{re.escape(name)} -->\n)(?:.*?\n)?(^<!-- /figures:{re.escape(name)} -->$)",
        re.S | re.M,
    )


def find_block(name):
    """The one file that holds section NAME's block; exits if no file or
    more than one place holds it."""
    opening = re.compile(rf"^<!-- figures:{re.escape(name)} -->$", re.M)
    found = []
    for path in doc_files():
        with open(path) as f:
            text = f.read()
        count = len(opening.findall(text))
        if count and not block_pattern(name).search(text):
            sys.exit(f"readme_figures: {os.path.relpath(path, ROOT)} opens block "
                     f"`<!-- figures:{name} -->` but never closes it")
        found += [path] * count
    if not found:
        sys.exit(f"readme_figures: no block `<!-- figures:{name} -->` in README.md or docs/**/*.md")
    if len(found) > 1:
        places = ", ".join(os.path.relpath(p, ROOT) for p in found)
        sys.exit(f"readme_figures: block `<!-- figures:{name} -->` is in more than one "
                 f"place ({places}); keep exactly one")
    return found[0]


def replace_block(text, name, body):
    pattern = block_pattern(name)
    if not pattern.search(text):
        sys.exit(f"readme_figures: no block `<!-- figures:{name} -->`")
    return pattern.sub(lambda m: m.group(1) + body + "\n" + m.group(2), text, count=1)


def write_block(name, body):
    """Writes BODY into section NAME's block, in whichever file holds it,
    through a temporary file renamed into place."""
    path = find_block(name)
    with open(path) as f:
        text = f.read()
    text = replace_block(text, name, body)
    # Written through a temporary file, so an interrupted run leaves the
    # file whole; each finished section is kept.
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, path)
    return path


def main():
    global REUSE_SWEEP
    args = sys.argv[1:]
    if "--reuse-sweep" in args:
        REUSE_SWEEP = True
        args.remove("--reuse-sweep")
    if args == ["--list"]:
        for name, f in SECTIONS.items():
            where = os.path.relpath(find_block(name), ROOT)
            print(f"{name} ({where}): {f.__doc__ or ''}".rstrip())
        return
    unknown = [a for a in args if a not in SECTIONS]
    if unknown:
        sys.exit(f"readme_figures: unknown section(s) {', '.join(unknown)}; "
                 f"the sections: {', '.join(SECTIONS)}")
    names = args or list(SECTIONS)
    # Every block is found before anything is measured: a missing or
    # doubled block fails at once, not after an hour of measuring.
    for name in names:
        find_block(name)
    if not os.access(GLINT, os.X_OK):
        sys.exit(f"readme_figures: {GLINT} not found: run `cargo build --release` first")
    for name in names:
        start = time.time()
        print(f"{name} ...", file=sys.stderr, flush=True)
        body = SECTIONS[name]()
        path = write_block(name, body)
        print(f"{name}: done in {time.time() - start:.0f} s, written to "
              f"{os.path.relpath(path, ROOT)}", file=sys.stderr, flush=True)


if __name__ == "__main__":
    main()
