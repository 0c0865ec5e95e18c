#!/usr/bin/env python3
"""Where a render's instructions go: callgrind over the tile passes of one
`glint render`, split into shadow rays (everything under
`Renderer::transmittance`), single closest-hit queries (under
`Renderer::closest`) and the rest by source file.

    CARGO_TARGET_DIR=target/profiling cargo build --profile profiling \\
        --no-default-features --bin glint
    python3 benches/callgrind_split.py target/profiling/profiling/glint -- \\
        scenes/default.toml --samples 16 --width 200 --height 150

The profiling build keeps the release code with debug information, so
callgrind can name the source file of every instruction. Three callgrind
runs of the same render (one thread, `GLINT_SIMD=avx2`): the tile passes,
then each query alone; each query's files are taken out of the first
run's. Needs valgrind; standard library only.
"""

import collections
import os
import re
import subprocess
import sys
import tempfile


def callgrind(binary, args, toggle, out):
    env = {**os.environ, "GLINT_SIMD": "avx2"}
    with tempfile.TemporaryDirectory() as d:
        subprocess.run(["valgrind", "--tool=callgrind", f"--callgrind-out-file={out}",
                        f"--toggle-collect={toggle}", binary, "render", *args,
                        "--threads", "1", "-q", "-o", os.path.join(d, "x.png")],
                       env=env, check=True, stdout=subprocess.DEVNULL,
                       stderr=subprocess.DEVNULL)


def by_file(out):
    """Total instructions and instructions by source file name."""
    text = subprocess.run(["callgrind_annotate", "--inclusive=no", "--threshold=100", out],
                          check=True, capture_output=True, text=True).stdout
    files, total = collections.Counter(), 0
    for line in text.splitlines():
        m = re.match(r"\s*([\d,]+) \(\s*[\d.]+%\)\s+(\S+?):", line)
        if not m or "PROGRAM TOTALS" in line:
            continue
        count = int(m.group(1).replace(",", ""))
        files[os.path.basename(m.group(2))] += count
        total += count
    return total, files


def main():
    if "--" not in sys.argv[2:]:
        sys.exit(__doc__)
    binary, args = sys.argv[1], sys.argv[sys.argv.index("--") + 1:]
    parts = {}
    with tempfile.TemporaryDirectory() as d:
        for name, toggle in [("all", "*tile_pass*"),
                             ("shadow rays", "*Renderer::transmittance*"),
                             ("single closest hits", "*Renderer::closest*")]:
            out = os.path.join(d, "callgrind.out")
            callgrind(binary, args, toggle, out)
            parts[name] = by_file(out)
    total, rest = parts["all"][0], parts["all"][1].copy()
    print(f"| part | share of {total / 1e6:,.0f} M instructions | largest files |")
    print("|---|---:|---|")
    for name in ("shadow rays", "single closest hits"):
        count, files = parts[name]
        rest.subtract(files)
        top = ", ".join(f"{f} {100 * c / total:.1f} %" for f, c in files.most_common(4))
        print(f"| {name} | {100 * count / total:.1f} % | {top} |")
    rest_total = sum(rest.values())
    top = ", ".join(f"{f} {100 * c / total:.1f} %" for f, c in rest.most_common(10))
    print(f"| the rest (packets, shading) | {100 * rest_total / total:.1f} % | {top} |")


if __name__ == "__main__":
    main()
