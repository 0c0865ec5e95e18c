"""Follow one pixel's shadow ray through the octree, cell by cell, and say
why its walk stopped.

    python python/examples/shadow_walk.py [SCENE] [X] [Y]

Without a scene it walks the repository's default scene (found from this
file, so it runs from any folder).
"""

import sys
from pathlib import Path

import glint

REPO = Path(__file__).resolve().parents[2]
scene = glint.load(sys.argv[1] if len(sys.argv) > 1 else REPO / "scenes" / "default.toml")
x, y = (int(sys.argv[2]), int(sys.argv[3])) if len(sys.argv) > 3 else (100, 110)
trace = scene.trace_pixel(x, y, width=200, height=150)

eye = trace["tree"]
if eye["hit"] is None:
    sys.exit(f"the eye ray of pixel {x},{y} leaves the scene: no shadow ray to follow")
hit = eye["hit"]
print(f"pixel {x},{y}: the eye ray hits {hit['kind']} {hit['object']} "
      f"({hit['material']}) at distance {hit['distance']:.3f}")

WHY = {
    "left-octree": "it left the octree with no cell left to visit: nothing is in the way",
    "cells-beyond-light": "the cells left all lie beyond the light: nothing is in the way",
    "blocked": "an opaque surface is in the way: the light is blocked",
    "missed-octree": "it never entered the octree",
    "hit-in-cell": "a hit nearer than its cell's exit",
    "cells-beyond-hit": "the cells left all lie beyond its hit",
}
for shadow in eye["shadows"]:
    print(f"\nlight {shadow['light']}: {shadow['verdict']}, "
          f"{shadow['transmittance']:.2f} of its light arrives")
    for n, step in enumerate(shadow.get("walk") or []):
        where = "unbounded shapes" if step["depth"] is None else (
            f"depth {step['depth']} cell, t {step['t_enter']:.3f} to {step['t_exit']:.3f}")
        tested = step.get("tested") or []
        hits = [t["object"] for t in tested if t["hit"]]
        print(f"  {n:2d} {step['kind']:9s} {where}"
              + (f", tested {len(tested)}" if tested else "")
              + (f", hit {hits}" if hits else ""))
    if shadow.get("walk_end"):
        print(f"  stopped: {WHY.get(shadow['walk_end'], shadow['walk_end'])} "
              f"({shadow['intersection_tests']} tests, {shadow['traversal_steps']} steps)")
    else:
        print("  no shadow ray: the surface faces away from this light")
