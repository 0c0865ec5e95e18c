"""The module gives what `glint render` and `glint bench` give for the same
scene and settings: the same PNG bytes, pixels, statistics and ray trees.
Timings differ between any two runs; everything else must be equal."""

import json

import numpy as np
import pytest

import glint
from conftest import cli_json, read_png, scene_path

# Fields that hold seconds, or rates and ratios made from them.
TIMINGS = {"load_s", "build_s", "render_s", "mrays_per_s", "counting_overhead", "speedup"}

SETTINGS = [
    # (render kwargs, the same as glint render flags)
    ({"aa": "off"}, ["--aa", "off"]),
    ({"aa": "adaptive"}, ["--aa", "adaptive"]),
    ({"samples": 16, "max_depth": 3}, ["--samples", "16", "--max-depth", "3"]),
    ({"view": "cost", "aa": "off"}, ["--view", "cost", "--aa", "off"]),
    ({"view": "depth", "max_depth": 2}, ["--view", "depth", "--max-depth", "2"]),
    ({"view": "aa-need"}, ["--view", "aa-need"]),
]


def without_timings(value):
    if isinstance(value, dict):
        return {k: without_timings(v) for k, v in value.items() if k not in TIMINGS}
    if isinstance(value, list):
        return [without_timings(v) for v in value]
    return value


@pytest.mark.parametrize("kwargs,flags", SETTINGS, ids=lambda s: str(s))
def test_saved_png_is_the_cli_png_byte_for_byte(tmp_path, glint_cli, kwargs, flags):
    scene = glint.load(scene_path("default.toml"))
    frame = scene.render(64, 48, **kwargs)
    ours, theirs = tmp_path / "python.png", tmp_path / "cli.png"
    frame.save(ours)
    glint_cli("render", scene_path("default.toml"), "--width", 64, "--height", 48,
              *flags, "-o", theirs, "-q")
    # The record (scene path, text, settings, version) included.
    assert ours.read_bytes() == theirs.read_bytes()
    pixels = read_png(theirs)
    assert np.array_equal(frame.srgb8(legend=True), pixels)
    # The image without the legend strip is the top of the PNG.
    assert np.array_equal(frame.srgb8(), pixels[:48])


def test_nff_obj_and_octree_off_match_too(tmp_path, glint_cli):
    for name, octree in [("spd/teapot.nff", None), ("../assets/bunny.obj", None),
                         ("glass.toml", False)]:
        path = scene_path(name)
        frame = glint.load(path).render(48, 40, octree=octree)
        flags = ["--octree", "off"] if octree is False else []
        glint_cli("render", path, "--width", 48, "--height", 40, *flags,
                  "-o", tmp_path / "cli.png", "-q")
        frame.save(tmp_path / "python.png")
        assert (tmp_path / "python.png").read_bytes() == (tmp_path / "cli.png").read_bytes(), name


@pytest.mark.parametrize("accel", ["octree", "bvh", "none"])
def test_each_accelerator_renders_the_cli_png_and_counts_the_cli_work(tmp_path, glint_cli, accel):
    path = scene_path("spd/teapot.nff")
    scene = glint.load(path)
    frame = scene.render(40, 32, accel=accel, stats=True)
    glint_cli("render", path, "--width", 40, "--height", 32, "--accel", accel,
              "--stats", "-q", "-o", tmp_path / "cli.png")
    frame.save(tmp_path / "python.png")
    assert (tmp_path / "python.png").read_bytes() == (tmp_path / "cli.png").read_bytes()
    assert frame.stats["accel"] == accel
    # Every accelerator answers alike: the pixels are the octree's.
    assert np.array_equal(frame.srgb8(), scene.render(40, 32).srgb8())
    assert ("bvh_stats" in frame.stats) == (accel == "bvh")


def test_octree_and_accel_that_disagree_or_an_unknown_accel_are_refused():
    scene = glint.load(scene_path("sphere.toml"))
    with pytest.raises(ValueError, match="disagree"):
        scene.render(8, 8, octree=True, accel="bvh")
    with pytest.raises(ValueError, match="expected octree, bvh or none"):
        scene.render(8, 8, accel="kd-tree")
    # Agreeing is allowed.
    assert scene.render(8, 8, octree=False, accel="none").stats is None


@pytest.mark.parametrize("kwargs,flags", SETTINGS[:4], ids=lambda s: str(s))
def test_stats_are_the_cli_stats(tmp_path, glint_cli, kwargs, flags):
    scene = glint.load(scene_path("default.toml"))
    stats = scene.render(64, 48, stats=True, **kwargs).stats
    cli = cli_json(glint_cli("render", scene_path("default.toml"), "--width", 64, "--height", 48,
                             *flags, "--stats", "-q", "-o", tmp_path / "cli.png"))
    assert set(stats) == set(cli)
    assert without_timings(stats) == without_timings(cli)
    # Counted work, not zeros: the comparison compares something.
    assert stats["rays"]["total"] > 0 and stats["intersection_tests_per_ray"] > 0


def test_a_render_without_stats_has_none():
    assert glint.load(scene_path("sphere.toml")).render(8, 8).stats is None


@pytest.mark.parametrize("pixel", [(32, 24), (5, 40), (63, 0)])
def test_the_ray_tree_is_the_cli_ray_tree(glint_cli, pixel):
    x, y = pixel
    tree = glint.load(scene_path("default.toml")).trace_pixel(x, y, width=64, height=48)
    cli = cli_json(glint_cli("render", scene_path("default.toml"), "--width", 64, "--height", 48,
                             "--trace-pixel", f"{x},{y}"))
    assert tree == cli
    assert tree["tree"]["kind"] == "eye"


def test_the_ray_tree_with_the_octree_off_is_the_cli_ray_tree(glint_cli):
    tree = glint.load(scene_path("glass.toml")).trace_pixel(20, 20, width=40, height=40,
                                                            octree=False, max_depth=3)
    cli = cli_json(glint_cli("render", scene_path("glass.toml"), "--width", 40, "--height", 40,
                             "--octree", "off", "--max-depth", 3, "--trace-pixel", "20,20"))
    assert tree == cli


def test_bench_is_the_cli_bench_less_its_timings(glint_cli):
    ours = glint.load(scene_path("spd/tetra.nff")).bench(width=48, height=48, repeat=1)
    cli = cli_json(glint_cli("bench", scene_path("spd/tetra.nff"), "--size", "48x48",
                             "--repeat", 1, "--format", "json"))
    assert len(cli) == 1
    cli = cli[0]
    assert set(ours) == set(cli)
    # Unit costs and predicted times are measured; the rest is counted.
    for record in (ours, cli):
        del record["unit_costs"]
        del record["predicted"]["render_s"]
    assert without_timings(ours) == without_timings(cli)
    assert ours["rays_total"] > 0 and ours["octree_stats"]["nodes"] > 1


def test_octree_statistics_are_the_ones_bench_reports():
    scene = glint.load(scene_path("spd/tetra.nff"))
    built = scene.octree()
    bench = scene.bench(width=16, height=16, repeat=1, octree_only=True)
    assert built["octree_stats"] == bench["octree_stats"]
    assert built["octree_params"] == bench["octree_params"]
    for key in ("traversal_steps_per_ray", "intersection_tests_per_ray"):
        assert built["predicted"][key] == bench["predicted"][key]
    assert json.dumps(built)  # plain data, as JSON


def test_textures_on_and_off_are_the_cli_pngs(tmp_path, glint_cli):
    """``textures=False`` is ``--textures off``: the same PNG bytes, and
    pixels that differ from the textured render's (the garden's floor,
    fence and leaves lose their images and cut-outs)."""
    path = scene_path("garden.toml")
    scene = glint.load(path)
    frames = {}
    for textures, flag in [(True, "on"), (False, "off")]:
        frame = scene.render(64, 48, aa="off", textures=textures)
        frame.save(tmp_path / "python.png")
        glint_cli("render", path, "--width", 64, "--height", 48, "--aa", "off",
                  "--textures", flag, "-o", tmp_path / "cli.png", "-q")
        assert (tmp_path / "python.png").read_bytes() == (tmp_path / "cli.png").read_bytes()
        frames[textures] = frame.srgb8()
    differing = np.any(frames[True] != frames[False], axis=2).mean()
    assert differing > 0.3, differing
