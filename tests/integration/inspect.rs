//! Seeing inside the render: a pixel's ray tree, per-pixel cost, the
//! aa-need view and reproducible PNG exports.

use crate::common;
use glint::settings::Accel;

use std::process::Command;

use glint::image::frame::Frame;
use glint::image::metrics::image_error;
use glint::math::DVec3;
use glint::render::Renderer;
use glint::render::ray_tree::{RayKind, RayNode};
use glint::scene::Scene;
use glint::settings::{RenderSettings, ViewMode};

/// A mirror sphere and a glass sphere over a floor, two lights.
const MIRROR_AND_GLASS: &str = r#"
[camera]
eye = [0, 1.5, 6]
lookat = [0, 1, 0]
up = [0, 1, 0]
fov = 40

[image]
width = 64
height = 48
samples = 1
max_depth = 4
background = [0.5, 0.6, 0.8]
ambient = [0.1, 0.1, 0.1]

[materials.mirror]
color = [0.9, 0.9, 0.9]
kd = 0.2
reflectivity = 0.7

[materials.glass]
color = [1, 1, 1]
kd = 0.05
ks = 0.5
shininess = 200
reflectivity = 0.1
transparency = 0.85
ior = 1.5

[materials.floor]
color = [0.8, 0.7, 0.6]

[[lights]]
position = [-3, 6, 4]
color = [0.8, 0.8, 0.8]

[[lights]]
position = [4, 5, 2]
color = [0.4, 0.4, 0.4]

[[objects]]
kind = "plane"
material = "floor"
point = [0, 0, 0]
normal = [0, 1, 0]

[[objects]]
kind = "sphere"
material = "glass"
center = [0.9, 1, 0]
radius = 0.8

[[objects]]
kind = "sphere"
material = "mirror"
center = [-1.1, 1, -0.5]
radius = 0.8
"#;

fn settings(scene: &Scene, view: ViewMode, use_octree: bool) -> RenderSettings {
    RenderSettings {
        view,
        accel: Accel::from_octree_switch(use_octree),
        ..scene.render_settings()
    }
}

/// Pixel whose centre eye ray hits shape `object` (scanning row-major).
fn pixel_hitting(renderer: &Renderer, w: u32, h: u32, object: u32) -> (u32, u32) {
    for j in 0..h {
        for i in 0..w {
            let t = renderer.ray_tree(i, j);
            if t.hit.as_ref().is_some_and(|hit| hit.object == object) {
                return (i, j);
            }
        }
    }
    panic!("no pixel sees object {object}");
}

fn check_sums(node: &RayNode, scene: &Scene) {
    let (max_depth, lights) = (scene.image.max_depth, scene.lights.len());
    assert!(
        node.depth <= max_depth,
        "depth {} > {max_depth}",
        node.depth
    );
    if node.hit.is_some() {
        assert_eq!(node.shadows.len(), lights, "one verdict per light");
    } else {
        assert!(node.shadows.is_empty() && node.children.is_empty());
    }
    if node.depth == max_depth {
        assert!(
            node.children.is_empty(),
            "a ray at max depth spawns nothing"
        );
    }
    // Colour = local term + weighted children, channel by channel.
    let mut sum = DVec3::from_array(node.local_color);
    for c in &node.children {
        assert_eq!(c.depth, node.depth + 1);
        sum += DVec3::from_array(c.contribution);
        check_sums(c, scene);
    }
    let color = DVec3::from_array(node.color);
    assert!(
        (sum - color).abs().max_element() < 1e-12,
        "local + children = {sum} but the ray's colour is {color}"
    );
    // The local term is ambient plus the lights' shares, as the model says.
    match &node.hit {
        Some(hit) => {
            let m = scene
                .materials
                .iter()
                .find(|m| m.name == hit.material)
                .unwrap();
            let direct: DVec3 = node
                .shadows
                .iter()
                .map(|s| DVec3::from_array(s.color))
                .sum();
            let expected = m.ka * scene.image.ambient * m.color + direct;
            let local = DVec3::from_array(node.local_color);
            assert!(
                (expected - local).abs().max_element() < 1e-12,
                "local {local} != ambient + direct {expected}"
            );
        }
        None => assert_eq!(DVec3::from_array(node.local_color), scene.image.background),
    }
}

#[test]
fn ray_tree_of_a_glass_pixel_has_reflection_and_refraction_and_sums_to_the_pixel() {
    let scene = common::scene_from(MIRROR_AND_GLASS, "test.toml");
    let octree = std::sync::Arc::new(scene.build_octree().unwrap());
    let s = settings(&scene, ViewMode::Shaded, true);
    let accel = crate::common::accelerator(&scene, &s, Some(&octree));
    let renderer = Renderer::new(&scene, &accel, s).unwrap();
    let (frame, _) = renderer.render(false, None);
    let rgb = frame.to_rgb8();
    for (object, kinds) in [
        (1u32, vec![RayKind::Refraction, RayKind::Reflection]),
        (2, vec![RayKind::Reflection]),
    ] {
        let (i, j) = pixel_hitting(&renderer, s.width, s.height, object);
        let tree = renderer.ray_tree(i, j);
        assert_eq!(tree.kind, RayKind::Eye);
        assert_eq!(tree.depth, 1);
        let children: Vec<RayKind> = tree.children.iter().map(|c| c.kind).collect();
        assert_eq!(children, kinds, "children of the eye ray at {i},{j}");
        check_sums(&tree, &scene);
        // The root colour is the 1-sample pixel: the same bytes once encoded.
        let p = ((j * s.width + i) * 3) as usize;
        let root = DVec3::from_array(tree.color);
        let enc = [root.x, root.y, root.z]
            .map(|c| (glint::color::linear_to_srgb(c) * 255.0).round() as u8);
        assert_eq!(
            enc,
            [rgb[p], rgb[p + 1], rgb[p + 2]],
            "pixel {i},{j}: tree against image"
        );
        if object == 1 {
            // The refracted ray crosses the glass and leaves it again.
            let deepest = tree.rays().iter().map(|n| n.depth).max().unwrap();
            assert!(deepest >= 3, "glass rays recurse (deepest {deepest})");
        }
    }
}

#[test]
fn cost_counts_one_test_per_primitive_without_the_octree_and_none_outside_it() {
    // Spheres only: every primitive is bounded, so a ray that misses the
    // octree's root box tests nothing at all.
    let text = MIRROR_AND_GLASS.replace(
        "[[objects]]\nkind = \"plane\"\nmaterial = \"floor\"\npoint = [0, 0, 0]\nnormal = [0, 1, 0]\n",
        "",
    );
    let scene = common::scene_from(&text, "test.toml");
    assert_eq!(scene.shapes.len(), 2);
    let octree = std::sync::Arc::new(scene.build_octree().unwrap());
    let corner = |use_octree| {
        let s = settings(&scene, ViewMode::Cost, use_octree);
        let accel = crate::common::accelerator(&scene, &s, Some(&octree));
        let (frame, _) = Renderer::new(&scene, &accel, s)
            .unwrap()
            .render(false, None);
        (frame.pixels[0], frame)
    };
    let (off, frame_off) = corner(false);
    assert_eq!(
        off.x,
        scene.shapes.len() as f64,
        "octree off: the missing eye ray tests every primitive once"
    );
    assert_eq!(off.y, 0.0, "no traversal without the octree");
    let (on, frame_on) = corner(true);
    assert_eq!(
        on.x, 0.0,
        "octree on: a ray missing the root box tests nothing"
    );
    // Summed over the frame, the cost view counts what --stats counts.
    let s = settings(&scene, ViewMode::Shaded, true);
    let accel = crate::common::accelerator(&scene, &s, Some(&octree));
    let (_, counts) = Renderer::new(&scene, &accel, s).unwrap().render(true, None);
    let total_tests: f64 = frame_on.pixels.iter().map(|p| p.x).sum();
    assert_eq!(total_tests, counts.work.intersection_tests as f64);
    let summary = frame_off.cost_summary().unwrap();
    assert!(summary.min >= 2.0 && summary.max >= summary.mean);
}

#[test]
fn aa_need_view_agrees_with_the_study_measure() {
    let scene = common::load("scenes/default.toml");
    let octree = std::sync::Arc::new(scene.build_octree().unwrap());
    let mut s = settings(&scene, ViewMode::AaNeed, true);
    s.width = 96;
    s.height = 72;
    let accel = crate::common::accelerator(&scene, &s, Some(&octree));
    let (need, _) = Renderer::new(&scene, &accel, s)
        .unwrap()
        .render(false, None);
    let shaded = |samples| {
        let st = RenderSettings {
            samples,
            view: ViewMode::Shaded,
            ..s
        };
        let accel = crate::common::accelerator(&scene, &st, Some(&octree));
        Renderer::new(&scene, &accel, st)
            .unwrap()
            .render(false, None)
            .0
    };
    let (one, sixteen) = (shaded(1), shaded(16));
    let study = image_error(&one.pixels, &sixteen.pixels, sixteen.colors).visible_fraction;
    let view = need
        .pixels
        .iter()
        .filter(|p| p.max_element() > 1.0 / 255.0)
        .count() as f64
        / need.pixels.len() as f64;
    assert_eq!(view, study, "aa-need fraction {view} vs study {study}");
    assert!(
        view > 0.0 && view < 0.5,
        "some edges need anti-aliasing: {view}"
    );
    assert_eq!(
        Frame::aa_need(&one, &one)
            .pixels
            .iter()
            .filter(|p| p.max_element() > 0.0)
            .count(),
        0
    );
    let legend = need.legend().unwrap();
    assert!(
        legend.caption.contains(&format!("{:.1}%", 100.0 * study)),
        "legend states the fraction: {}",
        legend.caption
    );
}

fn glint() -> Command {
    Command::new(env!("CARGO_BIN_EXE_glint"))
}

#[test]
fn exports_record_how_they_were_made_and_render_again_identically() {
    let tmp = common::temp_dir();
    let dir = tmp.path();
    let first = dir.join("first.png");
    let again = dir.join("again.png");
    let scene = common::repo_path("scenes/glass.toml");
    for view in ["shaded", "cost"] {
        let out = glint()
            .args(["render", scene.to_str().unwrap(), "-o"])
            .arg(&first)
            .args(["--width", "40", "--height", "30", "--samples", "16"])
            .args([
                "--max-depth",
                "3",
                "--octree-leaf-size",
                "4",
                "--view",
                view,
            ])
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let record = glint::export::read_record(&first).unwrap();
        assert_eq!(record.settings.render.samples, 16);
        assert_eq!(record.settings.render.max_depth, 3);
        assert_eq!(record.settings.octree_params.leaf_size, 4);
        assert_eq!(record.settings.render.view.name(), view);
        let text = std::fs::read_to_string(&scene).unwrap();
        assert_eq!(record.scene_text, text);
        assert_eq!(
            record.scene_sha256,
            glint::export::sha256_hex(text.as_bytes())
        );

        let (n, largest) = common::rerender_from_png(&first, &again);
        assert_eq!(n, 0, "{view}: {n} pixels differ (largest {largest})");
    }

    // `glint info` prints the record; a PNG without one is a clear error.
    let out = glint().arg("info").arg(&first).output().unwrap();
    let info = String::from_utf8_lossy(&out.stdout);
    assert!(
        out.status.success() && info.contains("samples       16"),
        "{info}"
    );
    // A viewer export's partial mark, overlay and edits are printed too,
    // not only with --json.
    let mut record = glint::export::read_record(&first).unwrap();
    record.settings.partial = true;
    record.settings.overlay_depth = Some(3);
    let scene = glint::scene::load(&scene).unwrap();
    let mut lights = scene.lights.clone();
    lights[0].color = glint::math::DVec3::new(0.25, 0.5, 0.75);
    record.settings.edits = Some(glint::export::SceneEdits {
        lights,
        materials: scene.materials.clone(),
    });
    let edited = dir.join("edited.png");
    glint::export::save_rgb_png(&edited, 1, 1, &[9, 9, 9], Some(&record)).unwrap();
    let out = glint().arg("info").arg(&edited).output().unwrap();
    let info = String::from_utf8_lossy(&out.stdout);
    for line in [
        "partial       yes",
        "overlay       octree cells to depth 3",
        &format!(
            "edits         {} lights and {} materials",
            scene.lights.len(),
            scene.materials.len()
        ),
        "  light 1     position",
        "colour 0.25 0.5 0.75",
        &format!("  material `{}`: colour", scene.materials[0].name),
    ] {
        assert!(info.contains(line), "missing {line:?} in\n{info}");
    }
    // Lights and materials as the file has them are no edits, and an
    // adaptive render says so.
    record.settings.edits = Some(glint::export::SceneEdits {
        lights: scene.lights.clone(),
        materials: scene.materials.clone(),
    });
    record.settings.render.adaptive = true;
    glint::export::save_rgb_png(&edited, 1, 1, &[9, 9, 9], Some(&record)).unwrap();
    let out = glint().arg("info").arg(&edited).output().unwrap();
    let info = String::from_utf8_lossy(&out.stdout);
    for line in [
        "edits         none (the scene file's lights and materials)",
        "samples       16 (adaptive",
    ] {
        assert!(info.contains(line), "missing {line:?} in\n{info}");
    }
    // --legend off: the cost view (and the overlay) at exactly the render's
    // size, recorded, so --from-png makes the same file again.
    for overlay in [&[][..], &["--overlay", "octree"][..]] {
        let out = glint()
            .args([
                "render",
                common::repo_path("scenes/glass.toml").to_str().unwrap(),
                "-o",
            ])
            .arg(&first)
            .args([
                "--width", "40", "--height", "30", "--view", "cost", "--legend", "off",
            ])
            .args(overlay)
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        assert_eq!(
            image::image_dimensions(&first).unwrap(),
            (40, 30),
            "{overlay:?}"
        );
        assert!(String::from_utf8_lossy(&out.stderr).contains("(40x30,"));
        assert!(!glint::export::read_record(&first).unwrap().settings.legend);
        let (n, _) = common::rerender_from_png(&first, &again);
        assert_eq!(n, 0);
        assert_eq!(image::image_dimensions(&again).unwrap(), (40, 30));
    }
    let plain = dir.join("plain.png");
    image::RgbImage::new(4, 4).save(&plain).unwrap();
    for args in [vec!["info"], vec!["render", "-o", "x.png", "--from-png"]] {
        let out = glint().args(&args).arg(&plain).output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success());
        assert!(
            err.contains("plain.png") && err.contains("no glint metadata"),
            "{args:?}: {err}"
        );
    }
}

#[test]
fn trace_pixel_prints_the_tree_as_json() {
    let out = glint()
        .args(["render"])
        .arg(common::repo_path("scenes/glass.toml"))
        .args(["--width", "48", "--height", "36", "--trace-pixel", "24,20"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["pixel"], serde_json::json!([24, 20]));
    assert_eq!(v["tree"]["kind"], "eye");
    assert_eq!(v["tree"]["depth"], 1);
    assert!(v["tree"]["hit"]["material"].is_string(), "{v}");
    let out = glint()
        .args(["render"])
        .arg(common::repo_path("scenes/glass.toml"))
        .args(["--width", "48", "--height", "36", "--trace-pixel", "48,0"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("outside the 48x36 image"));
}

#[test]
fn records_outside_the_limits_are_refused() {
    let scene = common::load("scenes/sphere.toml");
    let settings = scene.render_settings();
    let tmp = common::temp_dir();
    let dir = tmp.path();
    let path = dir.join("bad.png");
    let base =
        glint::export::RenderRecord::new(&scene, "scenes/sphere.toml", &scene.camera, settings);
    type Spoil = Box<dyn Fn(&mut glint::export::RenderRecord)>;
    let cases: [(&str, Spoil); 4] = [
        (
            "leaf_size",
            Box::new(|r| r.settings.octree_params.leaf_size = 0),
        ),
        (
            "octree max_depth",
            Box::new(|r| r.settings.octree_params.max_depth = 1_000_000),
        ),
        (
            "max_depth",
            Box::new(|r| r.settings.render.max_depth = 100_000),
        ),
        ("image size", Box::new(|r| r.settings.render.width = 0)),
    ];
    for (what, spoil) in cases {
        let mut record = base.clone();
        spoil(&mut record);
        glint::export::save_rgb_png(&path, 1, 1, &[0, 0, 0], Some(&record)).unwrap();
        let err = glint::export::read_record(&path).unwrap_err().to_string();
        assert!(
            err.contains("glint:settings") && err.contains("bad.png"),
            "{what}: {err}"
        );
    }
    // An untouched record reads back equal.
    glint::export::save_rgb_png(&path, 1, 1, &[0, 0, 0], Some(&base)).unwrap();
    assert_eq!(glint::export::read_record(&path).unwrap(), base);
}

/// The depth view, which `--legend` lists, has a strip saying what the grey
/// means: its white end is the nearest visible distance (a sphere of radius
/// 1 seen from 5 away: 4), and the CLI's PNG carries it unless
/// `--legend off`.
#[test]
fn the_depth_view_has_a_legend() {
    let scene = common::scene_from(
        r#"
        [camera]
        eye = [0, 0, 5]
        lookat = [0, 0, 0]
        up = [0, 1, 0]
        fov = 40
        [materials.m]
        color = [1, 1, 1]
        [[objects]]
        kind = "sphere"
        center = [0, 0, 0]
        radius = 1
        material = "m"
        "#,
        "depth.toml",
    );
    let octree = std::sync::Arc::new(scene.build_octree().unwrap());
    let mut settings = scene.render_settings();
    (settings.width, settings.height) = (41, 41);
    settings.view = glint::settings::ViewMode::Depth;
    let accel = crate::common::accelerator(&scene, &settings, Some(&octree));
    let (frame, _) = glint::render::Renderer::new(&scene, &accel, settings)
        .unwrap()
        .render(false, None);
    let legend = frame.legend().expect("the depth view has a legend");
    let near: f64 = legend.high.parse().unwrap();
    assert!((near - 4.0).abs() < 0.01, "nearest distance {near}");
    assert!(legend.caption.contains("8.0"), "{}", legend.caption);
    let tmp = common::temp_dir();
    let png = tmp.path().join("depth.png");
    for (switch, taller) in [("on", true), ("off", false)] {
        let out = glint()
            .args([
                "render",
                common::repo_path("scenes/glass.toml").to_str().unwrap(),
                "-o",
            ])
            .arg(&png)
            .args([
                "--width", "40", "--height", "30", "--view", "depth", "--legend", switch,
            ])
            .output()
            .unwrap();
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        let (w, h) = image::image_dimensions(&png).unwrap();
        assert_eq!((w, h > 30), (40, taller), "--legend {switch}: {w}x{h}");
    }
}
