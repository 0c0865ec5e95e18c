"""Instructions per ray at the commits where each step of issue 37
(secondary rays at Embree's cost) landed, and now, in one run: the table
`python3 benches/readme_figures.py secondary-steps` writes.

Each commit's headless binary is built in a temporary git worktree into
target/history (kept, so a second run builds nothing; about 4 minutes the
first time on 2 cores), then every workload is counted by cachegrind for
every binary, two at a time: about 15 minutes on 2 cores. The counts do not
depend on the machine's load, so the binaries need not run interleaved.
Standard library only; needs git, cargo and valgrind.
"""

import os
import shutil
import subprocess
import sys
import tempfile
from concurrent.futures import ThreadPoolExecutor

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
HISTORY = os.path.join(ROOT, "target", "history")

# The commit each column measures: the state the issue was filed against,
# then each step as it landed (docs/notes/experiments.md tells them), in
# the order they landed.
STEPS = [
    ("before", "6aa62f4"),
    ("sRGB by table (4)", "f730ce1"),
    ("secondary packets (3)", "161052a"),
    ("wide walk (1)", "471f9a9"),
    ("single rays at AVX2 (2)", "0369bd2"),
    ("cones, sRGB buckets (4)", "04ee179"),
]

STEPS_ORDER = [commit for _, commit in STEPS]

# GLINT_PACKETS=off (every ray single, at the SIMD level) came with step 2;
# before it, the scalar level traced every ray singly.
PACKETS_OFF_SINCE = "0369bd2"

# The workloads at the sizes: name, render arguments,
# width, height, and whether every ray goes single.
WORKLOADS = [
    ("bunny primary rays, normals view, 256x192",
     ["scenes/bunny.toml", "--view", "normals", "--samples", "1"], 256, 192, False),
    ("bunny and floor, 16 spp, 128x96", ["benches/peers/bunny_floor.toml"], 128, 96, False),
    ("`scenes/default.toml`, 1 spp, 800x600",
     ["scenes/default.toml", "--samples", "1"], 800, 600, False),
    ("`scenes/default.toml`, 16 spp, 800x600",
     ["scenes/default.toml", "--samples", "16"], 800, 600, False),
    ("SPD gears, 1 spp, 256x256", ["scenes/spd/gears.nff", "--samples", "1"], 256, 256, False),
    ("SPD rings, 1 spp, 256x256", ["scenes/spd/rings.nff", "--samples", "1"], 256, 256, False),
    ("bunny primary rays, every ray single, 256x192",
     ["scenes/bunny.toml", "--view", "normals", "--samples", "1"], 256, 192, True),
]


def run(args, **kw):
    done = subprocess.run(args, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                          text=True, check=False, **kw)
    if done.returncode != 0:
        sys.exit(f"step_history: `{' '.join(args)}` failed ({done.returncode}):\n"
                 f"{done.stderr[-2000:]}")
    return done.stdout


def build(commit):
    """The headless release binary of `commit`, built once."""
    binary = os.path.join(HISTORY, f"glint-{commit}")
    if os.access(binary, os.X_OK):
        return binary
    os.makedirs(HISTORY, exist_ok=True)
    tree = tempfile.mkdtemp(prefix=f"glint-{commit}-")
    run(["git", "worktree", "add", "--detach", tree, commit])
    try:
        print(f"  building {commit} ...", file=sys.stderr, flush=True)
        done = subprocess.run(
            ["cargo", "build", "--release", "--no-default-features", "--bin", "glint"],
            cwd=tree, env={**os.environ, "CARGO_TARGET_DIR": HISTORY},
            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, check=False)
        if done.returncode != 0:
            sys.exit(f"step_history: building {commit} failed:\n{done.stderr[-2000:]}")
        shutil.copy2(os.path.join(HISTORY, "release", "glint"), binary)
    finally:
        run(["git", "worktree", "remove", "--force", tree])
    return binary


def extra_env(commit, single):
    """What `commit`'s binary needs in its environment to trace every ray
    singly (nothing for the other workloads; `None` is now)."""
    if not single:
        return {}
    if commit is None or STEPS_ORDER.index(commit) >= STEPS_ORDER.index(PACKETS_OFF_SINCE):
        return {"GLINT_PACKETS": "off"}
    return {"GLINT_SIMD": "scalar"}


def table(now, instructions):
    """The markdown table: a row per workload, a column per step and now
    (`now`: the current release binary). `instructions(args, width,
    height, env, binary)` counts a workload's instructions per ray, by the
    README's method (readme_figures.py's)."""
    columns = [(commit, build(commit)) for commit in STEPS_ORDER] + [(None, now)]
    jobs = [(args, w, h, extra_env(c, single), b)
            for _, args, w, h, single in WORKLOADS for c, b in columns]
    with ThreadPoolExecutor(2) as pool:
        counts = list(pool.map(lambda job: instructions(*job), jobs))
    head = " | ".join(f"{name} `{commit}`" for name, commit in STEPS)
    lines = [f"| workload | {head} | now |", "|---|" + "---:|" * (len(columns))]
    for i, (name, *_) in enumerate(WORKLOADS):
        row = counts[i * len(columns):(i + 1) * len(columns)]
        lines.append(f"| {name} | " + " | ".join(f"{c:,.0f}" for c in row) + " |")
    return "\n".join(lines)
