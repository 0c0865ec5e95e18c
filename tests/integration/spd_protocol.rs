//! The SPD test protocol (`--protocol spd`) and the colour conventions:
//! corner rays, the protocol's spawning rules on single rays, the
//! published ray counts, and display-value shading.

use crate::common;

use common::{repo_path, scene_from};
use glint::color::ColorConvention;
use glint::math::DVec3;
use glint::render::Renderer;
use glint::render::ray_tree::{RayKind, RayNode};
use glint::scene::Scene;
use glint::settings::{Protocol, RenderSettings, ViewMode};

fn spd(scene: &Scene) -> RenderSettings {
    scene.render_settings().with_protocol(Protocol::Spd)
}

/// A tilted plane seen head-on from z = 10: every corner ray hits it.
const TILTED_PLANE: &str = r#"
[camera]
eye = [0, 0, 10]
lookat = [0, 0, 0]
up = [0, 1, 0]
fov = 40

[image]
width = 8
height = 6

[materials.m]

[[objects]]
kind = "plane"
material = "m"
point = [0, 0, 0]
normal = [0, 0.6, 0.8]
"#;

/// The corner rays of a `w x h` image, computed here from the camera's
/// definition (eye, lookat, up, vertical fov edge to edge), not glint's code.
fn corner_distance(ci: u32, cj: u32, w: u32, h: u32) -> f64 {
    let (eye, normal) = (DVec3::new(0.0, 0.0, 10.0), DVec3::new(0.0, 0.6, 0.8));
    let half_height = 20f64.to_radians().tan();
    let pixel = 2.0 * half_height / h as f64;
    let x = -pixel * w as f64 / 2.0 + ci as f64 * pixel;
    let y = half_height - cj as f64 * pixel;
    let dir = DVec3::new(x, y, -1.0).normalize();
    // Plane through the origin: n . (eye + t dir) = 0.
    -normal.dot(eye) / normal.dot(dir)
}

#[test]
fn corner_rays_make_each_pixel_the_mean_of_its_four_corners() {
    let scene = scene_from(TILTED_PLANE, "tilted.toml");
    let octree = std::sync::Arc::new(scene.build_octree().unwrap());
    let mut settings = spd(&scene);
    settings.view = ViewMode::Depth;
    // Three bands of corner rows, the last one partial.
    (settings.width, settings.height) = (8, 37);
    let (w, h) = (settings.width, settings.height);
    let accel = crate::common::accelerator(&scene, &settings, Some(&octree));
    let renderer = Renderer::new(&scene, &accel, settings).unwrap();
    let (frame, counts) = renderer.render(false, None);
    assert_eq!(counts.rays.primary, ((w + 1) * (h + 1)) as u64);
    assert_eq!(counts.rays.primary_hits, counts.rays.primary);
    for j in 0..h {
        for i in 0..w {
            let expected = (corner_distance(i, j, w, h)
                + corner_distance(i + 1, j, w, h)
                + corner_distance(i, j + 1, w, h)
                + corner_distance(i + 1, j + 1, w, h))
                / 4.0;
            let got = frame.pixels[(j * w + i) as usize];
            assert!(
                (got.x - expected).abs() < 1e-12 * expected,
                "pixel {i},{j}: {} vs {expected}",
                got.x
            );
            assert_eq!(got.y, 1.0, "every corner hits");
        }
    }
    // Shown progressively (as the viewer does), band by band: the bands
    // cover the image once and each shows exactly the finished pixels.
    let shown = BandCollector::default();
    let rendered = renderer
        .render_frame(
            glint::render::PassOptions {
                count_work: false,
                progressive: true,
            },
            &shown,
        )
        .unwrap();
    assert_eq!(rendered.frame, frame);
    assert_eq!(rendered.counts.rays, counts.rays);
    let bands = shown.bands.into_inner().unwrap();
    let mut covered = vec![0u32; (w * h) as usize];
    for (tile, values) in bands {
        for (k, (i, j)) in tile.coordinates().enumerate() {
            let at = (j * w + i) as usize;
            covered[at] += 1;
            assert_eq!(values[k], frame.pixels[at], "pixel {i},{j} as shown");
        }
    }
    assert!(covered.iter().all(|&n| n == 1), "every pixel shown once");
}

/// Keeps every tile the engine shows, with its pixels.
#[derive(Default)]
struct BandCollector {
    bands: std::sync::Mutex<Vec<(glint::render::tiles::Tile, Vec<DVec3>)>>,
}

impl glint::render::PassWatch for BandCollector {
    fn shows_tiles(&self) -> bool {
        true
    }
    fn tile_done(&self, _pass: &glint::render::PassInfo, done: &glint::render::FinishedTile) {
        let values = done.values().expect("pixels were asked for").to_vec();
        self.bands.lock().unwrap().push((done.tile, values));
    }
}

#[test]
fn a_512_square_image_casts_513_squared_eye_rays_in_any_row_subset() {
    let scene = scene_from(TILTED_PLANE, "tilted.toml");
    let octree = std::sync::Arc::new(scene.build_octree().unwrap());
    let mut settings = spd(&scene);
    (settings.width, settings.height) = (512, 512);
    settings.view = ViewMode::Depth;
    let accel = crate::common::accelerator(&scene, &settings, Some(&octree));
    let renderer = Renderer::new(&scene, &accel, settings).unwrap();
    let (_, counts) = renderer.render(false, None);
    assert_eq!(counts.rays.primary, 513 * 513);
    // Every 4th row (as `glint bench` samples brute force): the top edge
    // corners of each of those rows.
    assert_eq!(renderer.trace_rows(4, false).rays.primary, 128 * 513);
}

/// NFF text: a camera at z = 6 looking at the origin, one light, and `body`.
fn nff(light: &str, body: &str) -> String {
    format!(
        "v\nfrom 0 0 6\nat 0 0 0\nup 0 1 0\nangle 30\nhither 1\nresolution 5 5\n\
         l {light}\n{body}"
    )
}

fn tree_at(scene: &Scene, settings: RenderSettings, i: u32, j: u32) -> RayNode {
    let octree = std::sync::Arc::new(scene.build_octree().unwrap());
    let accel = crate::common::accelerator(scene, &settings, Some(&octree));
    Renderer::new(scene, &accel, settings)
        .unwrap()
        .ray_tree(i, j)
}

fn kinds(node: &RayNode) -> Vec<RayKind> {
    node.children.iter().map(|c| c.kind).collect()
}

#[test]
fn a_transmitter_without_ks_spawns_a_reflection_ray_under_the_protocol() {
    // Glass with Ks = 0: glint's rules cast no mirror ray (it has no
    // weight); the SPD's cast one from every transmitting surface.
    let scene = scene_from(
        &nff("0 5 6", "f 1 1 1 0.1 0 1 0.9 1.5\ns 0 0 0 1.5\n"),
        "glass.nff",
    );
    let glint = tree_at(&scene, scene.render_settings(), 2, 2);
    assert_eq!(kinds(&glint), vec![RayKind::Refraction]);
    let protocol = tree_at(&scene, spd(&scene), 2, 2);
    assert!(protocol.hit.is_some(), "the corner ray hits the sphere");
    assert_eq!(
        kinds(&protocol),
        vec![RayKind::Refraction, RayKind::Reflection]
    );
    let reflection = &protocol.children[1];
    assert_eq!(
        reflection.weight, 0.0,
        "Ks = 0: it adds nothing to the colour"
    );
}

#[test]
fn a_light_behind_the_surface_gets_no_shadow_ray() {
    // A wall facing the camera, the light behind it.
    let wall = "f 1 1 1 0.8 0 1 0 0\np 4\n-9 -9 0\n9 -9 0\n9 9 0\n-9 9 0\n";
    let scene = scene_from(&nff("0 0 -5", wall), "wall.nff");
    let octree = std::sync::Arc::new(scene.build_octree().unwrap());
    for settings in [scene.render_settings(), spd(&scene)] {
        let accel = crate::common::accelerator(&scene, &settings, Some(&octree));
        let renderer = Renderer::new(&scene, &accel, settings).unwrap();
        let (_, counts) = renderer.render(false, None);
        assert_eq!(counts.rays.primary_hits, counts.rays.primary);
        assert_eq!(counts.rays.shadow, 0, "{:?}", settings.protocol);
        let tree = renderer.ray_tree(2, 2);
        assert_eq!(tree.shadows[0].verdict.name(), "faces-away");
    }
    // With the light in front, every hit casts one.
    let lit = scene_from(&nff("0 0 5", wall), "wall.nff");
    let octree = std::sync::Arc::new(lit.build_octree().unwrap());
    let accel = crate::common::accelerator(&lit, &spd(&lit), Some(&octree));
    let (_, counts) = Renderer::new(&lit, &accel, spd(&lit))
        .unwrap()
        .render(false, None);
    assert_eq!(counts.rays.shadow, 36);
}

#[test]
fn depth_five_is_the_last_level() {
    // Two facing mirrors: the eye ray (depth 1) bounces between them; the
    // ray at depth 5 spawns nothing.
    let mirrors = "f 1 1 1 0.5 0.9 10 0 0\n\
                   p 4\n-9 -9 -2\n9 -9 -2\n9 9 -2\n-9 9 -2\n\
                   p 4\n-9 -9 8\n-9 9 8\n9 9 8\n9 -9 8\n";
    let mut text = nff("0 0 5", mirrors);
    // The eye between the mirrors, looking at the far one.
    text = text.replace("from 0 0 6", "from 0.1 0.1 6");
    let scene = scene_from(&text, "mirrors.nff");
    let tree = tree_at(&scene, spd(&scene), 2, 2);
    let nodes = tree.rays();
    let deepest = nodes.iter().map(|n| n.depth).max().unwrap();
    assert_eq!(deepest, 5);
    assert_eq!(nodes.len(), 5, "one reflection per level");
    for n in nodes {
        assert!(n.hit.is_some(), "depth {} hits a mirror", n.depth);
        assert_eq!(n.children.is_empty(), n.depth == 5);
    }
}

#[test]
fn total_internal_reflection_casts_no_refraction_ray_and_is_counted() {
    // The eye inside a glass sphere, looking along it: the ray meets the
    // surface from inside at 64 degrees, past the critical angle (41.8).
    let text = "v\nfrom 0.9 -0.2 0\nat 0.9 1 0\nup 0 0 1\nangle 1\nhither 1\nresolution 1 1\n\
                l 0 0 9\nf 1 1 1 0.1 0 1 0.9 1.5\ns 0 0 0 1\n";
    let scene = scene_from(text, "inside.nff");
    let octree = std::sync::Arc::new(scene.build_octree().unwrap());
    let mut settings = scene.render_settings().with_protocol(Protocol::Spd);
    settings.max_depth = 2;
    let accel = crate::common::accelerator(&scene, &settings, Some(&octree));
    let renderer = Renderer::new(&scene, &accel, settings).unwrap();
    let (_, counts) = renderer.render(false, None);
    // Four corner rays, each totally reflected: four reflection rays.
    assert_eq!(counts.rays.primary, 4);
    assert_eq!(counts.rays.total_internal_reflections, 4);
    assert_eq!(counts.rays.refraction, 0);
    assert_eq!(counts.rays.reflection, 4);
}

/// The SPD Readme's ray counts for the seven default scenes (513 x 513 eye
/// rays): eye rays that hit, reflection, refraction and shadow rays.
const PUBLISHED: [(&str, [u64; 4]); 7] = [
    ("balls", [263_169, 175_095, 0, 954_368]),
    ("gears", [245_086, 304_643, 207_564, 2_246_955]),
    ("mount", [173_125, 354_769, 354_769, 412_922]),
    ("rings", [263_169, 315_236, 0, 1_085_002]),
    ("teapot", [161_120, 225_248, 0, 407_656]),
    ("tetra", [49_788, 0, 0, 46_112]),
    ("tree", [169_836, 0, 0, 1_097_419]),
];

#[test]
fn published_ray_counts_are_reproduced_within_ten_percent() {
    for (name, published) in PUBLISHED {
        let scene = glint::scene::load(&repo_path(&format!("scenes/spd/{name}.nff"))).unwrap();
        let octree = std::sync::Arc::new(scene.build_octree().unwrap());
        let accel = crate::common::accelerator(&scene, &spd(&scene), Some(&octree));
        let renderer = Renderer::new(&scene, &accel, spd(&scene)).unwrap();
        let (_, counts) = renderer.render(false, None);
        let r = counts.rays;
        assert_eq!(r.primary, 513 * 513);
        // Gears' published refraction count includes its total internal
        // reflections (docs/benchmarks.md, "The SPD protocol"): both are checked.
        let ours = [r.primary_hits, r.reflection, r.refraction, r.shadow];
        for (k, (&a, &b)) in ours.iter().zip(&published).enumerate() {
            let close = if b == 0 {
                a == 0
            } else {
                (a as f64 - b as f64).abs() <= 0.1 * b as f64
            };
            assert!(close, "{name} count {k}: {a} against the published {b}");
        }
        let with_tir = r.refraction + r.total_internal_reflections;
        assert!(
            (with_tir as f64 - published[2] as f64).abs() <= 0.001 * published[2].max(1) as f64,
            "{name}: refraction + TIR {with_tir} against {}",
            published[2]
        );
        eprintln!(
            "{name}: {ours:?} (published {published:?}), TIR {}",
            r.total_internal_reflections
        );
    }
}

/// The head-on plane of `render_scenes.rs`, shaded as display values: the
/// pixel is exactly `ambient * color + (kd * color + ks) * light`, written
/// with no transfer function.
#[test]
fn display_values_are_shaded_and_written_unchanged() {
    let text = "v\nfrom 0 0 10\nat 0 0 0\nup 0 1 0\nangle 30\nhither 1\nresolution 3 3\n\
                l 0 0 10 0.5 0.5 0.5\nf 0.5 0.25 0.125 0.6 0.1 10 0 0\n\
                p 4\n-9 -9 0\n9 -9 0\n9 9 0\n-9 9 0\n";
    let scene = scene_from(text, "plane.nff");
    assert_eq!(scene.image.colors, ColorConvention::Display);
    let octree = std::sync::Arc::new(scene.build_octree().unwrap());
    let color = DVec3::new(0.5, 0.25, 0.125);
    // One light: the ambient is sqrt(1) / 2; NFF weights it by Kd.
    let ambient = 0.5 * 0.6;
    let expected = ambient * color + (0.6 * color + DVec3::splat(0.1)) * 0.5;
    let mut settings = scene.render_settings();
    settings.max_depth = 1;
    let accel = crate::common::accelerator(&scene, &settings, Some(&octree));
    let (frame, _) = Renderer::new(&scene, &accel, settings)
        .unwrap()
        .render(false, None);
    let centre = frame.pixels[4];
    assert!(
        (centre - expected).length() < 1e-12,
        "{centre} vs {expected}"
    );
    let bytes = frame.to_rgb8();
    let written = [expected.x, expected.y, expected.z].map(|c| (c * 255.0).round() as u8);
    assert_eq!(&bytes[12..15], &written, "no transfer function");
    // The same file in linear light: the colour is decoded from sRGB first,
    // the result encoded again.
    settings.colors = ColorConvention::Linear;
    let accel = crate::common::accelerator(&scene, &settings, Some(&octree));
    let (linear, _) = Renderer::new(&scene, &accel, settings)
        .unwrap()
        .render(false, None);
    let decoded = DVec3::new(0.5, 0.25, 0.125).map(glint::color::srgb_to_linear);
    let expected = ambient * decoded + (0.6 * decoded + DVec3::splat(0.1)) * 0.5;
    assert!((linear.pixels[4] - expected).length() < 1e-12);
    let encoded = [expected.x, expected.y, expected.z]
        .map(|c| (glint::color::linear_to_srgb(c) * 255.0).round() as u8);
    assert_eq!(&linear.to_rgb8()[12..15], &encoded);
}
