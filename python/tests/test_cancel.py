"""A render is cancelled cleanly: by Ctrl+C (SIGINT, what a notebook's
"interrupt kernel" sends) and by a cancel hook from another thread, which
can only run while the render has released the GIL."""

import signal
import subprocess
import sys
import textwrap
import threading

import pytest

import glint
from conftest import REPO, scene_path

# A frame that would take hours on two cores (16 samples, every ray
# tested against all 3,680 shapes): a cancel that did not stop it would
# run into the tests' two-minute guards.
LONG = {"width": 640, "height": 480, "samples": 16, "octree": False}

CHILD = textwrap.dedent(f"""
    # A runner started in the background by a shell without job control
    # has SIGINT ignored, and its children inherit that; a terminal or a
    # notebook kernel has Python's own handler, which this puts back.
    import signal
    signal.signal(signal.SIGINT, signal.default_int_handler)
    import glint
    scene = glint.load({scene_path("default.toml")!r})
    print("rendering", flush=True)
    try:
        scene.render(**{LONG!r})
        print("finished")
    except KeyboardInterrupt:
        print("interrupted")
    # The scene and the module still work after the cancelled render.
    print(scene.render(8, 6).rgb.shape)
""")


def test_ctrl_c_cancels_a_render_and_the_module_goes_on():
    child = subprocess.Popen([sys.executable, "-c", CHILD], cwd=REPO,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    try:
        assert child.stdout.readline().strip() == "rendering"
        # Let the render start before interrupting it.
        threading.Event().wait(1.0)
        child.send_signal(signal.SIGINT)
        out, err = child.communicate(timeout=120)
    finally:
        child.kill()
    assert child.returncode == 0, err
    assert out.split() == ["interrupted", "(6,", "8,", "3)"], (out, err)


def cancelled_from_another_thread(work):
    """Runs work(cancel) on a thread, sets cancel from this one, and says
    how the work ended."""
    cancel = threading.Event()
    outcome = []

    def run():
        try:
            work(cancel)
            outcome.append("finished")
        except glint.Cancelled:
            outcome.append("cancelled")

    worker = threading.Thread(target=run)
    worker.start()
    # This thread runs while the other renders only if the render
    # released the GIL: were it held, set() would come after the render.
    threading.Event().wait(0.5)
    cancel.set()
    worker.join(timeout=120)
    assert not worker.is_alive(), "the cancelled work went on"
    return outcome


def test_a_cancel_hook_set_from_another_thread_stops_the_render():
    scene = glint.load(scene_path("default.toml"))
    assert cancelled_from_another_thread(
        lambda cancel: scene.render(cancel=cancel, **LONG)) == ["cancelled"]


def test_a_benchmark_is_cancelled_by_its_hook_too():
    # Its brute-force passes alone would take minutes.
    scene = glint.load(scene_path("default.toml"))
    assert cancelled_from_another_thread(
        lambda cancel: scene.bench(width=320, height=240, samples=16, repeat=5,
                                   cancel=cancel)) == ["cancelled"]


def test_a_hook_that_raises_stops_the_render_with_its_exception():
    class Broken:
        def is_set(self):
            raise RuntimeError("the hook broke")

    with pytest.raises(RuntimeError, match="the hook broke"):
        glint.load(scene_path("default.toml")).render(cancel=Broken(), **LONG)
