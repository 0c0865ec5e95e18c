"""Render a scene, then where its rays cost the most: the cost view counts
the intersection tests of every ray a pixel spawned.

    python python/examples/cost_view.py [SCENE] [OUTPUT_FOLDER]

Without arguments it renders the repository's SPD teapot (found from this
file, so it runs from any folder) and writes cost.png into the temporary
folder, never into the working one (often the checkout).
"""

import sys
import tempfile
from pathlib import Path

import glint

REPO = Path(__file__).resolve().parents[2]
scene = glint.load(sys.argv[1] if len(sys.argv) > 1 else REPO / "scenes" / "spd" / "teapot.nff")
out = Path(sys.argv[2] if len(sys.argv) > 2 else tempfile.gettempdir())

picture = scene.render(320, 240)
cost = scene.render(320, 240, view="cost", stats=True)
tests = cost.rgb[..., 0]  # intersection tests per pixel
print(f"{scene.name}: {cost.stats['rays']['total']:,} rays, "
      f"{cost.stats['intersection_tests_per_ray']:.2f} intersection tests per ray")
print(f"per pixel: min {tests.min():.0f}, mean {tests.mean():.1f}, max {tests.max():.0f}")

try:
    import matplotlib
    matplotlib.use("Agg")  # no display needed; a notebook shows the figure inline
    import matplotlib.pyplot as plt
except ImportError:
    cost.save(out / "cost.png")  # glint's own colour map and legend
    print(f"matplotlib is not installed: wrote {out / 'cost.png'}")
else:
    fig, (left, right) = plt.subplots(1, 2, figsize=(10, 3.8))
    left.imshow(picture.srgb8())
    left.set_title("shaded")
    shown = right.imshow(tests, cmap="viridis")
    right.set_title("intersection tests per pixel")
    fig.colorbar(shown, ax=right)
    fig.savefig(out / "cost.png", dpi=80)
    print(f"wrote {out / 'cost.png'}")
