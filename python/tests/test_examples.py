"""The examples run as a notebook user would run them, and say what they
promise."""

import subprocess
import sys

from conftest import REPO

EXAMPLES = REPO / "python" / "examples"


def run(script, *args, cwd=REPO):
    done = subprocess.run([sys.executable, str(EXAMPLES / script), *map(str, args)],
                          cwd=cwd, capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return done.stdout


def test_examples_without_arguments_run_from_any_folder_and_write_nothing_there(tmp_path):
    # From a folder that is not the checkout: the scenes are found from
    # the script, and cost.png goes to the temporary folder.
    out = run("cost_view.py", cwd=tmp_path)
    assert "intersection tests per ray" in out
    assert "the eye ray hits plane 0 (floor)" in run("shadow_walk.py", cwd=tmp_path)
    assert list(tmp_path.iterdir()) == []


def test_cost_view_reports_the_cost_and_writes_a_picture(tmp_path):
    out = run("cost_view.py", "scenes/spd/teapot.nff", tmp_path)
    assert "intersection tests per ray" in out and "per pixel: min" in out
    # A figure with matplotlib, glint's own cost PNG without it.
    assert (tmp_path / "cost.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_shadow_walk_follows_a_blocked_shadow_ray_to_its_blocker():
    out = run("shadow_walk.py", "scenes/default.toml", 100, 110)
    assert "the eye ray hits plane 0 (floor)" in out
    blocked = out[out.index("light 2: blocked"):]
    assert "hit [" in blocked
    assert "stopped: an opaque surface is in the way" in blocked
    # The lit lights' walks end by leaving the octree.
    assert out.count("stopped: it left the octree") == 2
