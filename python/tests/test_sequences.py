"""Sequences: cameras from turntables and paths, render_frames here and on
a Dask LocalCluster (byte for byte the same as `glint render`), a worker
lost mid-run, a scene the workers cannot load, a scheduler not there."""

import os
import signal
import time

import pytest

import glint
from conftest import scene_path

SIZE = dict(width=64, height=48)


def read(path):
    with open(path, "rb") as f:
        return f.read()


def test_turntable_cameras_keep_distance_and_start_at_the_camera():
    scene = glint.load(scene_path("default.toml"))
    cams = scene.turntable(8)
    assert len(cams) == 8
    assert cams[0].eye == tuple(scene.camera.eye)
    lookat = cams[0].lookat
    dist = [sum((e - l) ** 2 for e, l in zip(c.eye, lookat)) ** 0.5 for c in cams]
    assert max(dist) - min(dist) < 1e-9
    assert all(c.time is None for c in cams)
    with pytest.raises(ValueError, match="no camera path"):
        scene.camera_path()
    with pytest.raises(ValueError, match="from 1 to 1,000,000"):
        scene.turntable(0)


def test_frames_here_are_the_command_lines_files(tmp_path, glint_cli):
    scene = glint.load(scene_path("default.toml"))
    out = tmp_path / "py" / "t_##.png"
    got = list(glint.render_frames(scene, scene.turntable(3), out=str(out), aa="off", **SIZE))
    assert [i for i, _ in got] == [0, 1, 2]
    glint_cli("render", scene_path("default.toml"), "--turntable", "3", "--aa", "off",
              "--width", "64", "--height", "48", "-o", tmp_path / "cli" / "t_##.png")
    for k in range(3):
        assert read(tmp_path / "py" / f"t_{k:02}.png") == read(tmp_path / "cli" / f"t_{k:02}.png")


def test_camera_assignment_and_render_camera_agree():
    scene = glint.load(scene_path("sphere.toml"))
    view = scene.turntable(4)[1]
    a = scene.render(camera=view, **SIZE).srgb8()
    moved = scene.copy()
    moved.camera = view
    assert moved.camera.eye == view.eye
    assert (moved.render(**SIZE).srgb8() == a).all()
    with pytest.raises(ValueError, match="camera"):
        scene.camera = glint.Viewpoint((0, 0, 0), (0, 0, 0), (0, 1, 0), 40)


def test_client_without_dask_says_how_to_install_it(monkeypatch):
    import sys
    monkeypatch.setitem(sys.modules, "distributed", None)
    scene = glint.load(scene_path("sphere.toml"))
    with pytest.raises(ImportError, match=r'pip install "glint\[dask\]"'):
        list(glint.render_frames(scene, scene.turntable(2), client="tcp://127.0.0.1:9", **SIZE))


def test_a_sweep_times_the_scene_from_its_edited_camera():
    scene = glint.load(scene_path("sphere.toml"))
    options = dict(width=16, height=12, repeat=1)
    before = next(glint.sweep([scene], [{"max_depth": 4}], **options))[2]["rays"]
    scene.camera = scene.turntable(4)[0]._replace(fov=5)
    after = next(glint.sweep([scene], [{"max_depth": 4}], **options))[2]["rays"]
    direct = scene.bench(octree_only=True, **options)["rays"]
    assert after == direct
    assert after["primary_hits"] != before["primary_hits"], "a narrower view hits more"


def test_arguments_are_checked_when_called_not_at_the_first_frame():
    scene = glint.load(scene_path("sphere.toml"))
    with pytest.raises(ValueError, match="chunk"):
        glint.render_frames(scene, scene.turntable(2), chunk=0)
    with pytest.raises(TypeError, match="a camera is"):
        glint.render_frames(scene, [{"eye": (0, 0, 1)}])


def test_frame_files_follow_the_command_lines_names():
    assert glint.frame_file("frames/turn_####.png", 7) == "frames/turn_0007.png"
    assert glint.frame_file("out/fly.png", 12) == "out/fly_0012.png"
    assert glint.frame_file("f_#.png", 123) == "f_123.png"


dask = pytest.importorskip("distributed", reason="the dask extra is not installed")


@pytest.fixture(scope="module")
def cluster():
    """A LocalCluster of two worker processes, one thread each, started
    here and torn down after."""
    from distributed import Client, LocalCluster

    with LocalCluster(n_workers=2, threads_per_worker=1, processes=True,
                      dashboard_address=None) as c, Client(c) as client:
        yield c, client


def test_dask_frames_are_byte_identical_to_local_ones(tmp_path, cluster):
    _, client = cluster
    scene = glint.load(scene_path("default.toml"))
    cams = scene.turntable(8)
    local = dict(glint.render_frames(scene, cams, out=str(tmp_path / "local_#.png"), **SIZE))
    seen = []
    for index, frame in glint.render_frames(scene, cams, out=str(tmp_path / "dask_#.png"),
                                            client=client, **SIZE):
        seen.append(index)
        assert (frame.rgb == local[index].rgb).all()
    assert sorted(seen) == list(range(8))
    for k in range(8):
        assert read(tmp_path / f"dask_{k}.png") == read(tmp_path / f"local_{k}.png")


def test_edits_travel_to_the_workers(tmp_path, cluster):
    _, client = cluster
    scene = glint.load(scene_path("sphere.toml"))
    name = next(iter(scene.materials))
    scene.materials[name].color = (0.1, 0.9, 0.2)
    cams = scene.turntable(2)
    local = [f.srgb8() for _, f in glint.render_frames(scene, cams, **SIZE)]
    remote = dict(glint.render_frames(scene, cams, client=client, **SIZE))
    for k in range(2):
        assert (remote[k].srgb8() == local[k]).all()


def test_a_worker_killed_mid_run_still_gives_every_frame_once(tmp_path, cluster):
    _, client = cluster
    scene = glint.load(scene_path("default.toml"))
    cams = scene.turntable(8)
    pids = list(client.run(os.getpid).values())
    seen = []
    killed = False
    for index, _ in glint.render_frames(scene, cams, client=client, width=160, height=120,
                                        aa="full", out=str(tmp_path / "k_#.png")):
        seen.append(index)
        if not killed:
            os.kill(pids[0], signal.SIGKILL)
            killed = True
    assert sorted(seen) == list(range(8)), seen
    assert all((tmp_path / f"k_{k}.png").is_file() for k in range(8))
    print(f"worker {pids[0]} killed after the first frame; frames in arrival order: {seen}")
    # The nanny brings a worker back (a new process) for the tests after
    # this one: the kill did happen during the run.
    client.wait_for_workers(2, timeout=60)
    assert pids[0] not in client.run(os.getpid).values()


def test_a_scene_the_workers_cannot_load_raises_its_error_once(tmp_path, cluster):
    _, client = cluster
    folder = tmp_path / "scene"
    folder.mkdir()
    mesh = folder / "tri.obj"
    mesh.write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    text = (
        "[camera]\neye = [0, 0, 4]\nlookat = [0, 0, 0]\nup = [0, 1, 0]\nfov = 40\n\n"
        "[[lights]]\nposition = [2, 2, 2]\n\n"
        '[[objects]]\nkind = "mesh"\npath = "tri.obj"\n'
    )
    (folder / "s.toml").write_text(text)
    scene = glint.load(folder / "s.toml")
    mesh.unlink()
    start = time.monotonic()
    with pytest.raises(glint.SceneError) as caught:
        list(glint.render_frames(scene, scene.turntable(4), client=client, **SIZE))
    message = str(caught.value)
    print(f"raised in {time.monotonic() - start:.2f} s: {message}")
    assert "s.toml:" in message and "objects[0].path" in message, message


def test_a_scheduler_not_there_is_a_clear_error_within_seconds():
    scene = glint.load(scene_path("sphere.toml"))
    start = time.monotonic()
    with pytest.raises(OSError, match="cannot reach the Dask scheduler at tcp://127.0.0.1:9"):
        list(glint.render_frames(scene, scene.turntable(2), client="tcp://127.0.0.1:9",
                                 **SIZE))
    # The connection timeout is 5 s; the time is printed, not asserted.
    print(f"refused after {time.monotonic() - start:.1f} s")


def test_a_sweep_on_dask_gives_one_record_per_scene_and_setting(cluster):
    _, client = cluster
    scenes = [glint.load(scene_path("sphere.toml")), glint.load(scene_path("glass.toml"))]
    settings = [{"max_depth": 4, "leaf_size": 2}, {"max_depth": 8, "leaf_size": 8}]
    options = dict(width=32, height=24, repeat=1)
    remote = {(i, j): r for i, j, r in glint.sweep(scenes, settings, client=client, **options)}
    assert sorted(remote) == [(0, 0), (0, 1), (1, 0), (1, 1)]
    for (i, j), record in remote.items():
        params = record["octree_params"] if "octree_params" in record else record
        assert params["max_depth"] == settings[j]["max_depth"], record.keys()
