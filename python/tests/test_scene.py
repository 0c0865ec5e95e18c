"""Loading, errors with their locations, and edits: what a notebook user
does to a scene before rendering it."""

import numpy as np
import pytest

import glint
from conftest import read_png, scene_path

BROKEN_TOML = """[camera]
eye = [0, 1, 5]
lookat = [0, 0, 0]
up = [0, 1, 0]
fov = 40

[materials.red]
color = [0.9, 0.1, 0.1]
kd = 1.5
"""


def cli_message(done):
    """The CLI's error message, without its `error: ` prefix."""
    text = done.stderr.decode().strip()
    assert text.startswith("error: "), text
    return text[len("error: "):]


def test_a_scene_loads_and_renders_to_numpy():
    frame = glint.load(scene_path("default.toml")).render(20, 15)
    assert frame.rgb.shape == (15, 20, 3) and frame.rgb.dtype == np.float32
    assert frame.srgb8().shape == (15, 20, 3) and frame.srgb8().dtype == np.uint8
    # Linear light, not bytes: values within [0, 1] for this scene, not all equal.
    assert 0.0 <= frame.rgb.min() and frame.rgb.max() <= 1.0
    assert len(np.unique(frame.srgb8().reshape(-1, 3), axis=0)) > 20
    assert frame._repr_png_()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_scene_error_names_file_line_column_and_key_like_the_cli(tmp_path, glint_cli):
    path = tmp_path / "broken.toml"
    path.write_text(BROKEN_TOML)
    with pytest.raises(glint.SceneError) as caught:
        glint.load(path)
    e = caught.value
    assert (e.path, e.line, e.column, e.key) == (str(path), 9, 6, "materials.red.kd")
    assert e.message == "must lie in [0, 1], got 1.5"
    assert isinstance(e, ValueError)
    done = glint_cli("render", path, "-o", tmp_path / "x.png", check=False)
    assert done.returncode == 1
    assert str(e) == cli_message(done)


def test_text_scenes_name_themselves_in_errors():
    with pytest.raises(glint.SceneError) as caught:
        glint.Scene.from_toml(BROKEN_TOML)
    assert (caught.value.path, caught.value.line) == ("<string>.toml", 9)
    scene = glint.Scene.from_toml(BROKEN_TOML.replace("kd = 1.5", "kd = 0.5"))
    assert scene.materials["red"].kd == 0.5


def test_an_unreadable_file_is_a_scene_error_with_its_path(tmp_path, glint_cli):
    missing = tmp_path / "missing.toml"
    with pytest.raises(glint.SceneError) as caught:
        glint.load(missing)
    assert caught.value.path == str(missing) and caught.value.line is None
    done = glint_cli("render", missing, "-o", tmp_path / "x.png", check=False)
    assert str(caught.value) == cli_message(done)


def test_edits_change_the_picture_and_a_saved_png_renders_again_with_them(tmp_path, glint_cli):
    scene = glint.load(scene_path("default.toml"))
    before = scene.render(48, 36, aa="off").srgb8()
    scene.materials["floor"].color = (0.1, 0.6, 0.2)
    scene.lights[0].color = (2.0, 2.0, 2.0)
    scene.camera.fov = 30
    frame = scene.render(48, 36, aa="off")
    assert not np.array_equal(before, frame.srgb8())
    # The record holds the edits: the CLI renders the same image from it.
    frame.save(tmp_path / "edited.png")
    glint_cli("render", "--from-png", tmp_path / "edited.png", "-o", tmp_path / "again.png", "-q")
    assert np.array_equal(read_png(tmp_path / "again.png"), frame.srgb8())
    # Edits stay on the scene object, not on the file or other scenes.
    assert scene.camera.fov == 30
    assert glint.load(scene_path("default.toml")).camera.fov == 40


def test_a_refused_edit_says_why_in_the_scene_files_words_and_changes_nothing(tmp_path):
    scene = glint.load(scene_path("default.toml"))
    with pytest.raises(glint.SceneError) as caught:
        scene.lights[1].color = (1.0, 5000.0, 1.0)
    assert caught.value.key == "lights[1].color"
    assert scene.lights[1].color == (0.35, 0.4, 0.55)
    # The same value in a scene file is refused with the same message.
    text = (tmp_path / "s.toml")
    source = open(scene_path("default.toml")).read()
    text.write_text(source.replace("color = [0.35, 0.4, 0.55]", "color = [1.0, 5000.0, 1.0]"))
    with pytest.raises(glint.SceneError) as from_file:
        glint.load(text)
    assert (from_file.value.key, from_file.value.message) == (
        caught.value.key, caught.value.message)
    with pytest.raises(glint.SceneError, match="camera.up"):
        scene.camera.up = (0.0, 0.0, 0.0)
    with pytest.raises(glint.SceneError, match="must be an integer from 1 to 8"):
        scene.octree_params.max_duplication = 9
    with pytest.raises(AttributeError, match="has no attribute 'ka'"):
        scene.materials["glass"].ka = 0.5
    with pytest.raises(KeyError):
        scene.materials["nothing"]
    with pytest.raises(IndexError):
        scene.lights[3]


def test_views_read_what_the_keys_hold():
    scene = glint.load(scene_path("default.toml"))
    assert len(scene.lights) == 3 and scene.lights[-1].position == scene.get("lights[2].position")
    assert sorted(scene.materials) == ["clay", "floor", "glass", "gold", "mirror", "teal", "violet"]
    assert scene.materials["glass"].as_dict()["ior"] == scene.get("materials.glass.ior")
    assert scene.octree_params.as_dict() == {
        "enabled": True, "max_depth": 10, "leaf_size": 4, "cost_driven": True,
        "max_duplication": 8, "memory_budget_mib": 128}
    assert "materials.glass.ior" in scene.keys()
    copy = scene.copy()
    copy.camera.fov = 20
    assert scene.camera.fov == 40


def test_octree_parameters_change_the_tree_not_the_picture():
    scene = glint.load(scene_path("default.toml"))
    shallow, deep = scene.octree(max_depth=2), scene.octree(max_depth=8)
    assert shallow["octree_stats"]["max_depth"] <= 2 < deep["octree_stats"]["max_depth"]
    # A deeper tree predicts fewer tests per ray and more steps.
    assert deep["predicted"]["intersection_tests_per_ray"] < \
        shallow["predicted"]["intersection_tests_per_ray"]
    assert scene.octree_params.max_depth == 10, "octree() leaves the scene's own"
    before = scene.render(32, 24, aa="off").srgb8()
    scene.octree_params.max_depth = 2
    assert np.array_equal(before, scene.render(32, 24, aa="off").srgb8())
    with pytest.raises(glint.SceneError, match="from 0 to 21"):
        scene.octree(max_depth=22)


def test_settings_outside_the_limits_are_refused():
    scene = glint.load(scene_path("sphere.toml"))
    for kwargs, words in [
        ({"samples": 4}, "samples must be 1 or 16"),
        ({"samples": 1, "aa": "full"}, "not both"),
        ({"view": "x-ray"}, "unknown view"),
        ({"max_depth": 65}, "max depth 65"),
        ({"width": 40000}, "outside the limits"),
        ({"threads": 10**6}, "per core"),
        ({"protocol": "spd", "max_depth": 3}, "fixes the ray depth"),
    ]:
        with pytest.raises(ValueError, match=words):
            scene.render(**kwargs)
    with pytest.raises(ValueError, match="outside the 8x8 image"):
        scene.trace_pixel(8, 0, width=8, height=8)
    with pytest.raises(OSError, match="name the file .png") as e:
        scene.render(4, 4).save("picture.jpg")
    assert "standard output" not in str(e.value)
    # Negative sizes are refused as values, as the command line refuses them.
    for kwargs in [{"width": -1, "height": 10}, {"samples": -1}, {"max_depth": -3}]:
        with pytest.raises(ValueError, match="at least 0, got -"):
            scene.render(**kwargs)
    with pytest.raises(ValueError, match="width must be"):
        scene.trace_pixel(0, 0, width=-8, height=8)
