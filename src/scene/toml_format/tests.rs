//! Tests of `toml_format`.

use super::*;
use crate::scene::FileSystem;

const GOOD: &str = r#"
[camera]
eye = [0, 0, 5]
lookat = [0, 0, 0]
up = [0, 1, 0]
fov = 45

[materials.red]
color = [1, 0, 0]

[[lights]]
position = [5, 5, 5]

[[objects]]
kind = "sphere"
material = "red"
center = [0, 0, 0]
radius = 1
"#;

fn parse_str(text: &str) -> Result<Scene, SceneError> {
    parse(text, Path::new("test.toml"), &FileSystem)
}

fn error_of(text: &str) -> String {
    match parse_str(text) {
        Ok(_) => panic!("expected an error"),
        Err(e) => e.to_string(),
    }
}

#[test]
fn good_scene_parses_with_defaults() {
    let s = parse_str(GOOD).unwrap();
    assert_eq!(s.shapes.len(), 1);
    assert_eq!(s.image, ImageSettings::default());
    assert_eq!(s.lights[0].color, DVec3::ONE);
    assert_eq!(s.materials[0].kd, Material::default().kd);
}

#[test]
fn errors_name_file_line_column_and_key() {
    let cases: &[(&str, &str, &str)] = &[
        (
            "radius = 1",
            "radius = -1",
            "test.toml:18:10: `objects[0].radius`: must be positive",
        ),
        (
            "radius = 1",
            "radius = nan",
            "test.toml:18:10: `objects[0].radius`: must be a finite number",
        ),
        (
            "radius = 1",
            "radius = \"big\"",
            "test.toml:18:10: `objects[0].radius`: invalid type: string \"big\", expected a number",
        ),
        (
            "fov = 45",
            "fov = 45\neye = [0, 0, 4]",
            "test.toml:7:1: `eye`: written twice in its table",
        ),
        (
            "radius = 1",
            "radius = 1\nsize = 3",
            "test.toml:19:1: `objects[0].size`: unknown field `size`",
        ),
        (
            "material = \"red\"",
            "material = \"blue\"",
            "test.toml:16:12: `objects[0].material`: no material named `blue`",
        ),
        (
            "kind = \"sphere\"",
            "kind = \"cube\"",
            "test.toml:15:8: `objects[0].kind`: unknown kind",
        ),
        ("fov = 45", "fov = 180", "test.toml:6:7: `camera.fov`"),
        (
            "eye = [0, 0, 5]",
            "eye = [1e300, 1.5, 6]",
            "test.toml:3:7: `camera.eye`: eye and lookat are so far apart that their distance overflows",
        ),
        (
            "eye = [0, 0, 5]",
            "eye = [0, 0, 0]",
            "test.toml:3:7: `camera.eye`: eye and lookat coincide",
        ),
        (
            "up = [0, 1, 0]",
            "up = [0, 0, 2]",
            "test.toml:5:6: `camera.up`: up is parallel to the view direction",
        ),
        (
            "fov = 45",
            "fov = inf",
            "test.toml:6:7: `camera.fov`: must be a finite number",
        ),
        (
            "color = [1, 0, 0]",
            "color = [1, 0]",
            "test.toml:9:9: `materials.red.color`",
        ),
        (
            "color = [1, 0, 0]",
            "color = [1, -1, 0]",
            "test.toml:9:9: `materials.red.color`: each component must lie in [0, 1]",
        ),
        (
            "color = [1, 0, 0]",
            "color = [1e300, 0, 0]",
            "test.toml:9:9: `materials.red.color`: each component must lie in [0, 1]",
        ),
        (
            "color = [1, 0, 0]",
            "color = [1, 0, 0]\nreflectivity = 1e300",
            "test.toml:10:16: `materials.red.reflectivity`: must lie in [0, 1], got 1e300",
        ),
        (
            "radius = 1",
            "radius = 1\nnormal = [0, 1, 0]",
            "test.toml:19:10: `objects[0].normal`: `normal` does not apply to a sphere",
        ),
        (
            "center = [0, 0, 0]\n",
            "",
            "test.toml:15:8: `objects[0].center`: a sphere needs `center`",
        ),
        (
            "[camera]",
            "[camera]\nzoom = 2",
            "test.toml:3:1: `camera.zoom`",
        ),
        ("eye = [0, 0, 5]\n", "", "`camera`"),
    ];
    for (from, to, expected) in cases {
        let text = GOOD.replacen(from, to, 1);
        let message = error_of(&text);
        assert!(
            message.contains(expected),
            "for {to:?}:\n  got      {message}\n  expected {expected}"
        );
    }
}

#[test]
fn a_material_named_where_none_is_defined_says_how_to_define_it() {
    let text = GOOD.replace("[materials.red]\ncolor = [1, 0, 0]\n", "");
    let message = error_of(&text);
    assert!(
        message.contains(
            "`objects[0].material`: no material named `red` (the scene defines no materials: \
             add a `[materials.red]` table)"
        ),
        "{message}"
    );
    // With some defined, they are listed.
    assert!(
        error_of(&GOOD.replace("material = \"red\"", "material = \"blue\""))
            .contains("(defined: red)")
    );
}

#[test]
fn image_limits_are_checked() {
    let with_image = |s: &str| format!("{GOOD}\n[image]\n{s}\n");
    assert!(
        error_of(&with_image("width = 0")).contains("`image.width`: must be an integer from 1")
    );
    assert!(error_of(&with_image("samples = 4")).contains("`image.samples`: must be 1 or 16"));
    assert!(error_of(&with_image("max_depth = 1000")).contains("`image.max_depth`"));
    let s = parse_str(&with_image(
        "width = 20\nheight = 10\nsamples = 1\nbackground = [0.5, 0.5, 0.5]",
    ))
    .unwrap();
    assert_eq!(
        (s.image.width, s.image.height, s.image.samples),
        (20, 10, 1)
    );
}

#[test]
fn missing_mesh_file_names_the_path() {
    let text = GOOD.replacen(
        "kind = \"sphere\"\nmaterial = \"red\"\ncenter = [0, 0, 0]\nradius = 1",
        "kind = \"mesh\"\nmaterial = \"red\"\npath = \"nowhere.obj\"",
        1,
    );
    let message = error_of(&text);
    assert!(
        message.contains("test.toml:17:8: `objects[0].path`: mesh nowhere.obj: cannot read"),
        "{message}"
    );
}

#[test]
fn degenerate_triangles_are_dropped_and_counted() {
    let text = GOOD.replacen(
        "kind = \"sphere\"\nmaterial = \"red\"\ncenter = [0, 0, 0]\nradius = 1",
        "kind = \"triangle\"\nmaterial = \"red\"\nvertices = [[0, 0, 0], [1, 1, 1], [2, 2, 2]]",
        1,
    );
    let s = parse_str(&text).unwrap();
    assert_eq!((s.shapes.len(), s.dropped_triangles), (0, 1));
}

#[test]
fn the_leaf_size_follows_the_shapes_unless_the_file_sets_it() {
    let triangle = "\n[[objects]]\nkind = \"triangle\"\nmaterial = \"red\"\nvertices = [[0, 0, 0], [1, 0, 0], [0, 1, 0]]\n";
    // One sphere and a few triangles: not a large mesh.
    assert_eq!(parse_str(GOOD).unwrap().octree_params.leaf_size, 4);
    let small = format!("{GOOD}{}", triangle.repeat(12));
    assert_eq!(parse_str(&small).unwrap().octree_params.leaf_size, 4);
    // The sphere and 20,000 triangles: a large mesh.
    let mesh = format!("{GOOD}{}", triangle.repeat(20_000));
    assert_eq!(parse_str(&mesh).unwrap().octree_params.leaf_size, 8);
    // A leaf size the file chooses is kept, even the other default.
    let chosen = format!("{mesh}\n[octree]\nleaf_size = 4\n");
    assert_eq!(parse_str(&chosen).unwrap().octree_params.leaf_size, 4);
}

#[test]
fn camera_keyframes_make_the_scene_path() {
    let text = GOOD.replace(
        "fov = 45\n",
        "fov = 45\n\n[[camera.keyframes]]\ntime = 0\neye = [0, 0, 5]\nlookat = [0, 0, 0]\n\n\
         [[camera.keyframes]]\ntime = 2.5\neye = [5, 0, 0]\nlookat = [0, 1, 0]\nfov = 30\n",
    );
    let s = parse_str(&text).unwrap();
    let path = s.camera_path.expect("a path");
    assert_eq!(path.keys().len(), 2);
    assert_eq!(path.duration(), 2.5);
    // up and fov default to the camera's.
    assert_eq!(path.keys()[0].camera.up, DVec3::Y);
    assert_eq!(path.keys()[0].camera.fov, 45.0);
    assert_eq!(path.keys()[1].camera.fov, 30.0);
    assert!(parse_str(GOOD).unwrap().camera_path.is_none());
}

#[test]
fn bad_keyframes_name_their_line_and_key() {
    let text = GOOD.replace(
        "fov = 45\n",
        "fov = 45\n\n[[camera.keyframes]]\ntime = 1\neye = [0, 0, 5]\nlookat = [0, 0, 0]\n\n\
         [[camera.keyframes]]\ntime = 0.5\neye = [5, 0, 0]\nlookat = [0, 0, 0]\n",
    );
    let e = error_of(&text);
    assert!(e.contains("test.toml:14:8"), "{e}");
    assert!(e.contains("camera.keyframes[1].time"), "{e}");
    assert!(e.contains("increasing time"), "{e}");
    let e = error_of(&GOOD.replace(
        "fov = 45\n",
        "fov = 45\n[[camera.keyframes]]\ntime = 0\neye = [0, 0, 0]\nlookat = [0, 0, 0]\n",
    ));
    assert!(e.contains("camera.keyframes[0].eye"), "{e}");
    let e = error_of(&GOOD.replace(
        "fov = 45\n",
        "fov = 45\n[[camera.keyframes]]\ntime = 0\neye = [0, 0, 1]\nlookat = [0, 0, 0]\nspeed = 2\n",
    ));
    assert!(e.contains("speed"), "{e}");
}
