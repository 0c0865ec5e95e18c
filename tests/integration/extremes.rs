//! Numerical robustness at the extremes. Every case asserts a property and
//! reports what it measured when it fails.

use crate::common;
use glint::settings::Accel;

use common::{diff, load, render_with, scene_from};
use glint::accel::Octree;
use glint::camera::{Camera, CameraSpec};
use glint::math::{DVec3, Ray};
use glint::render::Renderer;
use glint::scene::Scene;
use glint::shapes::{PreparedRay, Quadric, Shape, Sphere, Triangle};
use proptest::prelude::*;

/// The scene mapped by `p -> s p + t`: geometry, camera and lights.
fn transformed(scene: &Scene, s: f64, t: DVec3) -> Scene {
    let map = |p: DVec3| s * p + t;
    let mut out = scene.clone();
    out.camera.eye = map(scene.camera.eye);
    out.camera.lookat = map(scene.camera.lookat);
    for l in &mut out.lights {
        l.position = map(l.position);
    }
    for shape in std::sync::Arc::make_mut(&mut out.shapes).iter_mut() {
        *shape = match shape.clone() {
            Shape::Sphere(sp) => Shape::Sphere(Sphere::new(map(sp.center), s * sp.radius)),
            Shape::Plane(p) => Shape::Plane(glint::shapes::Plane::new(map(p.point), p.normal)),
            Shape::Triangle(tr) => {
                let mut new = Triangle::new(tr.vertices.map(map)).expect("still a triangle");
                new.vertex_normals = tr.vertex_normals;
                Shape::Triangle(new)
            }
            Shape::Quadric(q) => Shape::Quadric(Box::new(transform_quadric(&q, s, t))),
            Shape::Cone(c) => Shape::Cone(Box::new(
                glint::shapes::Cone::new(
                    map(c.base),
                    s * c.base_radius,
                    map(c.apex),
                    s * c.apex_radius,
                )
                .unwrap(),
            )),
        };
    }
    out
}

/// `F'(p) = s^2 F((p - t) / s)`, expanded back into the ten coefficients.
fn transform_quadric(q: &Quadric, s: f64, t: DVec3) -> Quadric {
    let [a, b, c, d, e, f, g, h, i, j] = q.coefficients;
    // F(p) = p.Q p + l.p + J with Q symmetric.
    let qm = glam::DMat3::from_cols(
        DVec3::new(a, b / 2.0, c / 2.0),
        DVec3::new(b / 2.0, e, f / 2.0),
        DVec3::new(c / 2.0, f / 2.0, h),
    );
    let l = DVec3::new(d, g, i);
    let l2 = -2.0 * (qm * t) + s * l;
    let j2 = t.dot(qm * t) - s * l.dot(t) + s * s * j;
    let clip = q
        .clip
        .map(|b| glint::math::Aabb::new(s * b.min + t, s * b.max + t));
    Quadric::new([a, b, c, l2.x, e, f, l2.y, h, l2.z, j2], clip)
}

fn render_scene(scene: &Scene, w: u32, h: u32) -> (Vec<u8>, u64) {
    let octree = std::sync::Arc::new(scene.build_octree().unwrap());
    let (img, counts) = render_with(scene, &octree, w, h, |s| s.samples = 1);
    (img, counts.nonfinite_samples)
}

/// Scaled by 1e-4 and 1e4 and moved 1e5 and 1e6 from the origin, scenes
/// render like the unit-scale original: at most 0.25% of pixels may differ
/// by more than 2/255 (silhouette pixels whose centre ray lands within
/// rounding of an edge), and none may be NaN.
#[test]
fn scenes_render_alike_at_any_scale_and_distance_from_the_origin() {
    for name in [
        "scenes/glass.toml",
        "scenes/quadrics.toml",
        "scenes/triangle.toml",
        "scenes/default.toml",
    ] {
        let scene = load(name);
        let (w, h) = (96, 72);
        let (base, nonfinite) = render_scene(&scene, w, h);
        assert_eq!(nonfinite, 0);
        for (s, t) in [
            (1e-4, DVec3::ZERO),
            (1e4, DVec3::ZERO),
            (1.0, DVec3::new(1e5, -1e5, 1e5)),
            (1.0, DVec3::new(1e6, 1e6, -1e6)),
        ] {
            let (img, nonfinite) = render_scene(&transformed(&scene, s, t), w, h);
            let (differing, largest) = diff(&base, &img, 2);
            let limit = (w * h) as usize / 400;
            eprintln!(
                "{name} scaled {s:e}, moved {t}: {differing} of {} pixels differ by > 2/255 (largest {largest})",
                w * h
            );
            assert_eq!(nonfinite, 0, "{name} scaled {s} moved {t}: NaN samples");
            assert!(
                differing <= limit,
                "{name} scaled {s}, moved {t}: {differing} of {} pixels differ by more than 2/255 (largest {largest}), limit {limit}",
                w * h
            );
        }
    }
}

#[test]
fn closed_mesh_is_watertight_from_inside() {
    // An octahedron: rays from its centre through every vertex, every edge
    // midpoint and points along the edges must hit one of its faces.
    let v = [
        DVec3::X,
        -DVec3::X,
        DVec3::Y,
        -DVec3::Y,
        DVec3::Z,
        -DVec3::Z,
    ]
    .map(|p| p * 0.7 + DVec3::splat(0.1));
    let faces = [
        [0, 2, 4],
        [2, 1, 4],
        [1, 3, 4],
        [3, 0, 4],
        [2, 0, 5],
        [1, 2, 5],
        [3, 1, 5],
        [0, 3, 5],
    ];
    let shapes: Vec<Shape> = faces
        .iter()
        .map(|f| Shape::Triangle(Triangle::new([v[f[0]], v[f[1]], v[f[2]]]).unwrap()))
        .collect();
    let centre = DVec3::splat(0.1);
    let mut targets: Vec<DVec3> = v.to_vec();
    for f in faces {
        for k in 0..3 {
            let (a, b) = (v[f[k]], v[f[(k + 1) % 3]]);
            for step in 1..20 {
                targets.push(a.lerp(b, step as f64 / 20.0));
            }
        }
    }
    let octree = std::sync::Arc::new(Octree::build(&shapes, Default::default()).unwrap());
    let mut misses = 0;
    for target in &targets {
        let ray = PreparedRay::new(Ray::new(centre, (*target - centre).normalize()));
        let brute = glint::accel::closest_brute_force(
            &glint::accel::Primitives::opaque(&shapes),
            &ray,
            f64::INFINITY,
            &mut glint::stats::NoCounts,
        );
        let tree = octree.closest(
            &glint::accel::Primitives::opaque(&shapes),
            &ray,
            f64::INFINITY,
            &mut glint::accel::WalkStack::default(),
            &mut glint::stats::NoCounts,
        );
        assert_eq!(brute, tree);
        if brute.is_none() {
            misses += 1;
        }
    }
    assert_eq!(
        misses,
        0,
        "{misses} of {} rays through edges and vertices escaped",
        targets.len()
    );
}

#[test]
fn tiny_and_huge_triangles_hit_where_expected() {
    for size in [1e-4, 1.0, 1e4] {
        let tri = Triangle::new([DVec3::ZERO, DVec3::X * size, DVec3::Y * size]).unwrap();
        let ray = PreparedRay::new(Ray::new(
            DVec3::new(0.25 * size, 0.25 * size, size),
            -DVec3::Z,
        ));
        let hit = tri.intersect(&ray, f64::INFINITY).expect("hit");
        assert!(
            (hit.t - size).abs() <= 1e-12 * size,
            "size {size}: t = {}",
            hit.t
        );
    }
}

#[test]
fn quadric_extremes() {
    // Tiny sphere seen from far away, in quadric form.
    let r = 1e-3;
    let c = DVec3::new(0.0, 0.0, -1e4);
    let q = Quadric::new(
        [
            1.0,
            0.0,
            0.0,
            0.0,
            1.0,
            0.0,
            0.0,
            1.0,
            -2.0 * c.z,
            c.z * c.z - r * r,
        ],
        None,
    );
    let ray = Ray::new(DVec3::ZERO, -DVec3::Z);
    let hit = q
        .intersect(&ray, f64::INFINITY)
        .expect("hits the tiny sphere");
    assert!((hit.t - (1e4 - r)).abs() < 1e-6, "t = {}", hit.t);
    // Origin on the surface (Cq = 0): leaving the surface outward finds nothing,
    // going inward finds the far side.
    let unit = Quadric::new([1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, -1.0], None);
    let on = DVec3::X;
    assert!(
        unit.intersect(&Ray::new(on, DVec3::X), f64::INFINITY)
            .is_none()
    );
    let inward = unit
        .intersect(&Ray::new(on, -DVec3::X), f64::INFINITY)
        .expect("far side");
    assert!((inward.t - 2.0).abs() < 1e-12);
    // Rays grazing the unit sphere at height y: a chord of half-length
    // sqrt(1 - y^2) centred at x = 0, entered at t = 5 - sqrt(1 - y^2)
    // with the normal (-sqrt(1 - y^2), y, 0). Just inside, exactly at and
    // just outside the silhouette.
    for y in [1.0 - 1e-6, 1.0 - 1e-12, 1.0] {
        let ray = Ray::new(DVec3::new(-5.0, y, 0.0), DVec3::X);
        let half_chord = (1.0 - y * y).sqrt();
        let hit = unit
            .intersect(&ray, f64::INFINITY)
            .unwrap_or_else(|| panic!("y = {y}: the grazing ray hits"));
        assert!(
            (hit.t - (5.0 - half_chord)).abs() < 1e-9,
            "y = {y}: t = {}",
            hit.t
        );
        let normal = unit.surface(&ray, &hit).geometric_normal.normalize();
        let expected = DVec3::new(-half_chord, y, 0.0);
        assert!((normal - expected).length() < 1e-6, "y = {y}: {normal}");
    }
    let outside = Ray::new(DVec3::new(-5.0, 1.0 + 1e-12, 0.0), DVec3::X);
    assert!(unit.intersect(&outside, f64::INFINITY).is_none());
}

#[test]
fn total_internal_reflection_at_great_depth_stays_finite() {
    let mut scene = load("scenes/glass.toml");
    scene.image.max_depth = 64;
    let octree = std::sync::Arc::new(scene.build_octree().unwrap());
    let (_, counts) = render_with(&scene, &octree, 48, 36, |s| s.samples = 1);
    assert_eq!(counts.nonfinite_samples, 0);
    assert!(counts.rays.refraction > 0 && counts.rays.reflection > 0);
}

/// A lone unit sphere at the origin seen from `distance` along +z.
fn lone_sphere(distance: f64, fov: f64) -> Scene {
    let mut scene = Scene::empty(
        "lone sphere".into(),
        CameraSpec {
            eye: DVec3::new(0.0, 0.0, distance),
            lookat: DVec3::ZERO,
            up: DVec3::Y,
            fov,
        },
        glint::scene::ImageSettings::default(),
    );
    scene.materials = vec![glint::material::Material::default()];
    scene.lights = vec![glint::material::Light {
        position: DVec3::new(1.0, 2.0, distance),
        color: DVec3::ONE,
    }];
    scene.push(Shape::Sphere(Sphere::new(DVec3::ZERO, 1.0)), 0);
    scene
}

/// Which pixel centres of a `w` x `h` image see [`lone_sphere`], from the
/// pinhole's definition (fov the vertical angle edge to edge, square
/// pixels) rather than glint's camera: (surely inside, within 1e-9 of the
/// silhouette either way).
fn sphere_pixels(w: u32, h: u32, fov: f64, distance: f64) -> (u64, u64) {
    let radius = (1.0 / distance).asin().tan();
    let pixel = 2.0 * (fov.to_radians() / 2.0).tan() / h as f64;
    let (mut inside, mut border) = (0, 0);
    for j in 0..h {
        for i in 0..w {
            let x = (i as f64 + 0.5 - w as f64 / 2.0) * pixel;
            let y = (h as f64 / 2.0 - j as f64 - 0.5) * pixel;
            let r = x.hypot(y);
            if r < radius * (1.0 - 1e-9) {
                inside += 1;
            } else if r <= radius * (1.0 + 1e-9) {
                border += 1;
            }
        }
    }
    (inside, border)
}

#[test]
fn extreme_cameras_and_image_shapes_see_what_the_pinhole_predicts() {
    let distance = 2.5;
    // fov 0.01: all pixels on the sphere; 179: only the centre one; 1x1:
    // the centre; a column 10000 tall at fov 60: the rows within the
    // sphere's angular radius, tan(asin(0.4)) / tan(30°) = 75.6% of them;
    // a row 10000 wide: pixels 0.73 wide, the two beside the centre.
    for (fov, w, h, expected) in [
        (0.01, 8, 8, 64),
        (179.0, 33, 25, 1),
        (40.0, 1, 1, 1),
        (60.0, 1, 10_000, 7_560),
        (40.0, 10_000, 1, 2),
    ] {
        let scene = lone_sphere(distance, fov);
        let octree = std::sync::Arc::new(scene.build_octree().unwrap());
        let (inside, border) = sphere_pixels(w, h, fov, distance);
        assert_eq!((inside, border), (expected, 0), "the prediction itself");
        let (_, one) = render_with(&scene, &octree, w, h, |r| r.samples = 1);
        assert_eq!(one.rays.primary_hits, expected, "fov {fov}, {w}x{h}");
        let (_, sixteen) = render_with(&scene, &octree, w, h, |r| r.samples = 16);
        assert_eq!(sixteen.nonfinite_samples, 0, "fov {fov}, {w}x{h}");
        assert_eq!(sixteen.rays.primary, 16 * w as u64 * h as u64);
    }
    let scene = load("scenes/sphere.toml");
    let octree = std::sync::Arc::new(scene.build_octree().unwrap());
    // Up almost parallel to the view direction still forms a valid basis...
    let mut tilted = scene.clone();
    let view = (scene.camera.lookat - scene.camera.eye).normalize();
    tilted.camera.up = (view + DVec3::new(1e-6, 0.0, 0.0)).normalize();
    assert!(Camera::new(&tilted.camera, 16, 16).is_ok());
    // ...exactly parallel is a clear error.
    tilted.camera.up = view;
    let accel = crate::common::accelerator(&tilted, &tilted.render_settings(), Some(&octree));
    let err = Renderer::new(&tilted, &accel, tilted.render_settings())
        .err()
        .expect("an error");
    assert!(err.to_string().contains("parallel"), "{err}");
    let zero = Camera::new(
        &CameraSpec {
            fov: 40.0,
            ..scene.camera
        },
        0,
        10,
    );
    assert!(zero.is_err());
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 300, ..ProptestConfig::default() })]

    /// Arbitrary text never panics either parser.
    #[test]
    fn parsers_never_panic_on_arbitrary_text(text in ".{0,400}") {
        for ext in ["toml", "nff"] {
            let path = std::path::PathBuf::from(format!("fuzz.{ext}"));
            let _ = glint::scene::load_str(&text, &path, &glint::scene::FileSystem);
        }
    }

    /// Mutations of real scene files (a byte range replaced by tokens the
    /// parsers find hard) give a scene or an error, never a panic.
    #[test]
    fn parsers_never_panic_on_mutated_scenes(
        which in 0usize..2,
        start in 0usize..4000,
        len in 0usize..40,
        insert in prop::sample::select(vec!["", "nan", "inf", "-1", "1e308", "99999999999999999999", "[", "]", "{", "=", "\"", "p 4000000000", "s", "v\n", "0 0 0", "\n[[objects]]\n", "#", "\u{0}", "é"]),
    ) {
        let (name, ext) = [("scenes/glass.toml", "toml"), ("scenes/spd/tetra.nff", "nff")][which];
        let original = std::fs::read_to_string(common::repo_path(name)).unwrap();
        let original = &original[..original.len().min(6000)];
        let start = original.floor_char_boundary(start.min(original.len()));
        let end = original.floor_char_boundary((start + len).min(original.len()));
        let mutated = format!("{}{}{}", &original[..start], insert, &original[end..]);
        let path = common::repo_path(name).with_extension(ext);
        let _ = glint::scene::load_str(&mutated, &path, &glint::scene::FileSystem);
    }
}

#[test]
fn malformed_inputs_are_clear_errors() {
    let tmp = common::temp_dir();
    let dir = tmp.path();
    let cases: &[(&str, &[u8], &str)] = &[
        ("missing.toml", b"", "cannot read scene file"),
        ("binary.toml", b"\xff\xfe\x00camera", "is not UTF-8"),
        // A render passed where its scene was meant.
        ("render.png", b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR", "is a PNG image, not a scene; to render the scene a PNG of glint's was made from, use `glint render --from-png"),
        ("huge.nff", b"v\nfrom 0 0 1\nat 0 0 0\nup 0 1 0\nangle 40\nhither 1\nresolution 99999999 10\n", "resolution must be a whole number"),
        ("neg.nff", b"v\nfrom 0 0 1\nat 0 0 0\nup 0 1 0\nangle 40\nhither 1\nresolution 10 10\nf 1 1 1 1 0 0 0 1\ns 0 0 0 -0\n", "radius must not be zero"),
        ("needle.nff", b"v\nfrom 0 0 1\nat 0 0 0\nup 0 1 0\nangle 40\nhither 1\nresolution 10 10\nf 1 1 1 1 0 0 0 1\nc 0 3 0 0 5 6 0 -0\n", "needle.nff:9:1: `c`: cone radii must not both be zero"),
        ("empty.toml", b"", "missing field `camera`"),
        ("scene.txt", b"", "unknown scene format"),
    ];
    for (file, bytes, expected) in cases {
        let path = dir.join(file);
        if *file != "missing.toml" {
            std::fs::write(&path, bytes).unwrap();
        }
        let err = glint::scene::load(&path)
            .err()
            .unwrap_or_else(|| panic!("{file} should fail"))
            .to_string();
        assert!(err.contains(expected), "{file}: {err}");
        assert!(
            err.contains(file),
            "{file}: the message names the file: {err}"
        );
    }
}

/// A scene with every key glint's TOML has (a mesh too), for the
/// extreme-value test below.
const EVERY_KEY: &str = r#"
[camera]
eye = [0.5, 1.5, 6]
lookat = [0, 1, 0]
up = [0, 1, 0]
fov = 40

[image]
width = 16
height = 12
samples = 1
max_depth = 6
background = [0.2, 0.3, 0.4]
ambient = [0.1, 0.1, 0.1]

[octree]
enabled = true
max_depth = 8
leaf_size = 4

[materials.glass]
color = [0.9, 0.95, 1]
kd = 0.1
ks = 0.5
shininess = 200
reflectivity = 0.1
transparency = 0.8
ior = 1.5

[materials.red]
color = [0.8, 0.2, 0.1]
kd = 0.7
ks = 0.3
shininess = 40
reflectivity = 0.3
transparency = 0
ior = 1.3

[[lights]]
position = [-3, 5, 4]
color = [0.8, 0.8, 0.8]

[[lights]]
position = [4, 3, 2]
color = [0.3, 0.3, 0.4]

[[objects]]
kind = "plane"
material = "red"
point = [0, 0, 0]
normal = [0, 1, 0]

[[objects]]
kind = "sphere"
material = "glass"
center = [0, 1, 0]
radius = 1

[[objects]]
kind = "triangle"
material = "red"
vertices = [[-2, 0, -2], [2, 0, -2], [0, 3, -2]]

[[objects]]
kind = "quadric"
material = "glass"
coefficients = [1, 0, 0, 0, 1, 0, 0, 1, 0, -0.25]
clip = { min = [-0.5, -0.5, -0.5], max = [0.5, 0.5, 0.5] }

[[objects]]
kind = "mesh"
material = "red"
path = "quad.obj"
scale = 0.5
rotate = [0, 30, 0]
translate = [1.5, 0.5, 0]
smooth = true
"#;

/// Byte ranges of the numbers in a TOML or NFF text (outside comments and
/// strings), to replace one at a time.
fn number_spans(text: &str) -> Vec<std::ops::Range<usize>> {
    let bytes = text.as_bytes();
    let mut spans = Vec::new();
    let mut i = 0;
    let mut in_string = false;
    while i < bytes.len() {
        let c = bytes[i];
        if c == b'"' {
            in_string = !in_string;
        }
        let starts = !in_string
            && (c.is_ascii_digit() || c == b'-')
            && (i == 0 || matches!(bytes[i - 1], b' ' | b'[' | b'\n' | b'='));
        if starts {
            let end = (i + 1..bytes.len())
                .find(|&k| !matches!(bytes[k], b'0'..=b'9' | b'.' | b'e' | b'E' | b'-' | b'+'))
                .unwrap_or(bytes.len());
            if text[i..end].parse::<f64>().is_ok() {
                spans.push(i..end);
            }
            i = end;
            continue;
        }
        i += 1;
    }
    spans
}

/// What every value of a scene may be replaced by: zeros of both signs,
/// the smallest and largest floats, overflowing and non-finite values,
/// integers beyond 32 and 64 bits.
const EXTREMES: [&str; 14] = [
    "0",
    "-0.0",
    "-1",
    "1e-300",
    "-1e-300",
    "1e300",
    "-1e300",
    "3.4e38",
    "1.7976931348623157e308",
    "nan",
    "inf",
    "-inf",
    "4294967297",
    "-9223372036854775808",
];

/// Loads `text` (named `name`); a load error must name the file, line and
/// column; a scene that loads must render at 16x12 with no non-finite
/// sample and no panic (or be refused by the renderer with an error).
/// What became of a scene text.
#[derive(Debug, PartialEq)]
enum Outcome {
    /// Loaded and rendered, every sample finite.
    Rendered,
    /// Refused by the loader, with its place in the file.
    Refused,
    /// Loaded, but the octree or the renderer refused it (with an error,
    /// not a panic): not counted as rendered.
    NotRendered,
}

fn loads_cleanly_or_renders_finite(text: &str, name: &std::path::Path, what: &str) -> Outcome {
    let scene = match glint::scene::load_str(text, name, &glint::scene::FileSystem) {
        Ok(scene) => scene,
        Err(e) => {
            let message = e.to_string();
            let place = format!("{}:", name.display());
            assert!(
                message.starts_with(&place) && message[place.len()..].contains(':'),
                "{what}: error without a place: {message}"
            );
            return Outcome::Refused;
        }
    };
    let Ok(octree) = scene.build_octree().map(std::sync::Arc::new) else {
        return Outcome::NotRendered;
    };
    let mut settings = scene.render_settings();
    (settings.width, settings.height, settings.samples) = (16, 12, 1);
    let accel = crate::common::accelerator(&scene, &settings, Some(&octree));
    let Ok(renderer) = Renderer::new(&scene, &accel, settings) else {
        return Outcome::NotRendered;
    };
    let (_, counts) = renderer.render(false, None);
    assert_eq!(counts.nonfinite_samples, 0, "{what}: non-finite samples");
    Outcome::Rendered
}

/// Every number of a scene using every key, replaced in turn by every
/// extreme value: never a panic, never a non-finite sample, and every
/// refusal names its place in the file.
#[test]
fn extreme_values_in_every_key_are_refused_or_render_finite() {
    let tmp = common::temp_dir();
    let dir = tmp.path();
    std::fs::write(
        dir.join("quad.obj"),
        "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\n",
    )
    .unwrap();
    let toml_path = dir.join("every-key.toml");
    assert_eq!(
        loads_cleanly_or_renders_finite(EVERY_KEY, &toml_path, "original"),
        Outcome::Rendered
    );
    let nff = std::fs::read_to_string(common::repo_path("scenes/spd/sizes/balls_s1.nff")).unwrap();
    let nff = format!(
        "{nff}f 0.5 0.6 0.7 0.4 0.3 50 0.6 1.4\nc 0 0 0 0.2 0 0 1 0.1\npp 3\n0 0 1 0 0 1\n1 0 1 0 0 1\n0 1 1 0 0 1\n"
    );
    let nff_path = dir.join("every-entity.nff");
    assert_eq!(
        loads_cleanly_or_renders_finite(&nff, &nff_path, "original"),
        Outcome::Rendered
    );
    let (mut rendered, mut refused, mut not_rendered) = (0, 0, 0);
    for (text, path) in [(EVERY_KEY.to_string(), &toml_path), (nff, &nff_path)] {
        let spans = number_spans(&text);
        assert!(spans.len() > 40, "{} numbers found", spans.len());
        for span in spans {
            for value in EXTREMES {
                let mutated = format!("{}{value}{}", &text[..span.start], &text[span.end..]);
                let what = format!(
                    "{} with `{}` -> `{value}`",
                    path.display(),
                    &text[span.clone()]
                );
                match loads_cleanly_or_renders_finite(&mutated, path, &what) {
                    Outcome::Rendered => rendered += 1,
                    Outcome::Refused => refused += 1,
                    Outcome::NotRendered => not_rendered += 1,
                }
            }
        }
    }
    eprintln!(
        "extreme values: {rendered} scenes rendered finite, {refused} refused with a place, \
         {not_rendered} loaded but refused by the octree or the renderer"
    );
    // Most mutations are ordinary values for their key: a run where few
    // render has stopped testing the renderer.
    assert!(
        rendered > refused,
        "{rendered} rendered, {refused} refused, {not_rendered} not rendered"
    );
}

/// A light on a surface (a lamp set into a ceiling) neither lights nor
/// shadows a point through that surface as rounding falls: a floor seen
/// from below the ceiling renders the same bytes with the ceiling's
/// triangle around the light as without it. The camera looks down, so no
/// eye ray meets the triangle.
#[test]
fn a_light_inside_a_surface_casts_no_speckled_shadow() {
    let scene = |with_ceiling: bool| {
        let ceiling = if with_ceiling {
            "[[objects]]\nkind = \"triangle\"\nmaterial = \"white\"\n\
             vertices = [[-3, -2, 0.3], [4, -1, 0.3], [-1, 5, 0.3]]\n"
        } else {
            ""
        };
        let text = format!(
            "[camera]\neye = [0.3, -0.2, -0.6]\nlookat = [0.1, 0.2, -2]\nup = [0, 1, 0]\nfov = 70\n\
             [image]\nwidth = 96\nheight = 72\nsamples = 1\n\
             [materials.white]\ncolor = [0.9, 0.9, 0.9]\nkd = 0.9\n\
             [[lights]]\nposition = [0.25, 0.5, 0.3]\ncolor = [1, 1, 1]\n\
             [[objects]]\nkind = \"plane\"\nmaterial = \"white\"\npoint = [0, 0, -2]\nnormal = [0, 0, 1]\n\
             {ceiling}"
        );
        scene_from(&text, "ceiling.toml")
    };
    let (open, lit) = (scene(false), scene(true));
    for use_octree in [true, false] {
        let render = |s: &glint::scene::Scene| {
            let octree = std::sync::Arc::new(s.build_octree().unwrap());
            render_with(s, &octree, 96, 72, |st| {
                st.accel = Accel::from_octree_switch(use_octree)
            })
            .0
        };
        let (a, b) = (render(&open), render(&lit));
        let differing = a.chunks(3).zip(b.chunks(3)).filter(|(x, y)| x != y).count();
        assert_eq!(
            differing, 0,
            "octree {use_octree}: {differing} pixels speckled"
        );
    }
}
