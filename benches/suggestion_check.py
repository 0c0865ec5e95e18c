#!/usr/bin/env python3
"""Whether a sweep's suggested octree setting is within a bound of the
sweep's fastest, with the timing noise taken out of the verdict.

A sweep times each setting once (median of --repeat runs); its fastest row
is the least of many noisy figures, so it is biased low, and a suggestion
a few percent slower can look 20 % slower by chance. Where the two
differ, `glint bench --sweep` times them again side by side
(`timed_again_s`); this script runs the sweep on each scene and prints
both comparisons, the sweep's and the side-by-side one.

    python3 benches/suggestion_check.py [--binary target/release/glint]
        [--size 256x256] [--depths 6,8,10] [--leaf-sizes 2,4,8]
        [--cost-driven on,off] [--bound 1.10] scene.nff ...

Prints a markdown table, one row per scene; exits 1 if any scene's
side-by-side ratio is above the bound.
"""

import argparse
import json
import subprocess
import sys


def describe(params):
    return "depth %d, leaf %d%s" % (params["max_depth"], params["leaf_size"],
                                     "" if params["cost_driven"] else ", cost-driven off")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--binary", default="target/release/glint")
    ap.add_argument("--size", default="256x256")
    ap.add_argument("--depths", default="6,8,10")
    ap.add_argument("--leaf-sizes", default="2,4,8")
    ap.add_argument("--cost-driven", default="on,off")
    ap.add_argument("--repeat", type=int, default=3, help="the sweep's --repeat")
    ap.add_argument("--bound", type=float, default=1.10)
    ap.add_argument("scenes", nargs="+")
    args = ap.parse_args()

    print("| scene | settings | suggested | fastest in the sweep | sweep: suggested / fastest "
          "| side by side (s) | side by side: suggested / fastest |")
    print("|---|---:|---|---|---:|---|---:|")
    worst = (0.0, "")
    for scene in args.scenes:
        out = subprocess.run(
            [args.binary, "bench", scene, "--size", args.size, "--samples", "1",
             "--octree-only", "--repeat", str(args.repeat), "--format", "json",
             "--sweep", "--sweep-depths", args.depths, "--sweep-leaf-sizes", args.leaf_sizes,
             "--sweep-cost-driven", args.cost_driven],
            capture_output=True, text=True, check=True).stdout
        rows = json.loads(out)
        suggested = next(r for r in rows if r["suggested"])
        fastest = next(r for r in rows if r["fastest"])
        total = lambda r: r["build_s"] + r["render_s"]
        sweep_ratio = total(suggested) / total(fastest)
        if suggested is fastest:
            again, ratio = "the same setting", 1.0
        else:
            s, f = suggested["timed_again_s"], fastest["timed_again_s"]
            again, ratio = "%.4f / %.4f" % (s, f), s / f
        name = scene.split("/")[-1]
        worst = max(worst, (ratio, name))
        print("| %s | %d | %s | %s | %.2f | %s | %.2f |" % (
            name, len(rows), describe(suggested["octree_params"]),
            describe(fastest["octree_params"]), sweep_ratio, again, ratio))
        sys.stdout.flush()
    print()
    print("Worst side by side: %.2fx the fastest (%s; bound %.2fx)." % (worst[0], worst[1], args.bound))
    return 0 if worst[0] <= args.bound else 1


if __name__ == "__main__":
    sys.exit(main())
