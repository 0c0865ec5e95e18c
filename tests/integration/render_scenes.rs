//! Every scene in `scenes/` renders, with properties checked on the images.

use crate::common;

use common::{all_scenes, diff, load, render_with};
use glint::camera::CameraSpec;
use glint::color::linear_to_srgb;
use glint::material::{Light, Material};
use glint::math::DVec3;
use glint::render::Renderer;
use glint::scene::{ImageSettings, Scene};
use glint::settings::ViewMode;
use glint::shapes::{Plane, Quadric, Shape, Sphere};

#[test]
fn every_scene_renders_finite_and_non_blank() {
    let scenes = all_scenes();
    assert!(scenes.len() >= 9, "scenes found: {scenes:?}");
    for name in scenes {
        let loaded = common::loaded(&name);
        let (scene, octree) = (&loaded.0, &loaded.1);
        let (image, counts) = render_with(scene, octree, 48, 36, |s| s.samples = 1);
        assert_eq!(
            counts.nonfinite_samples, 0,
            "{name}: NaN or infinite samples"
        );
        assert!(counts.rays.primary_hits > 0, "{name}: nothing visible");
        let first = &image[..3];
        let distinct = image.chunks_exact(3).filter(|p| *p != first).count();
        assert!(
            distinct > 48 * 36 / 20,
            "{name}: image is nearly uniform ({distinct} pixels differ from the corner)"
        );
    }
}

#[test]
fn output_is_identical_for_any_thread_count() {
    for name in [
        "scenes/glass.toml",
        "scenes/default.toml",
        "scenes/spd/teapot.nff",
    ] {
        let scene = load(name);
        let octree = std::sync::Arc::new(scene.build_octree().unwrap());
        let render = |threads: usize| {
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap();
            pool.install(|| render_with(&scene, &octree, 64, 48, |s| s.samples = 16))
        };
        let (one, c1) = render(1);
        let (three, c3) = render(3);
        assert!(one == three, "{name}: 1 and 3 threads give different bytes");
        assert_eq!(c1, c3, "{name}: counts differ between thread counts");
    }
}

/// A plane facing the camera, lit head-on by a light at the eye: the centre
/// pixel is `ambient * color + kd * color * light` exactly (N.L = 1, and the
/// highlight `ks (R.V)^n` is `ks`).
#[test]
fn head_on_plane_matches_the_analytic_colour() {
    let material = Material {
        name: "m".into(),
        color: DVec3::new(0.5, 0.25, 0.125),
        kd: 0.6,
        ks: 0.1,
        shininess: 10.0,
        ..Material::default()
    };
    let mut scene = Scene::empty(
        "analytic".into(),
        CameraSpec {
            eye: DVec3::new(0.0, 0.0, 10.0),
            lookat: DVec3::ZERO,
            up: DVec3::Y,
            fov: 30.0,
        },
        ImageSettings {
            width: 3,
            height: 3,
            samples: 1,
            max_depth: 1,
            background: DVec3::ZERO,
            ambient: DVec3::splat(0.2),
            ..ImageSettings::default()
        },
    );
    scene.materials = vec![material.clone()];
    scene.lights = vec![Light {
        position: DVec3::new(0.0, 0.0, 10.0),
        color: DVec3::splat(0.5),
    }];
    scene.push(Shape::Plane(Plane::new(DVec3::ZERO, DVec3::Z)), 0);
    let octree = std::sync::Arc::new(scene.build_octree().unwrap());
    let accel = crate::common::accelerator(&scene, &scene.render_settings(), Some(&octree));
    let renderer = Renderer::new(&scene, &accel, scene.render_settings()).unwrap();
    let (frame, _) = renderer.render(false, None);
    let centre = frame.pixels[4];
    let expected = 0.2 * material.color + (0.6 * material.color + DVec3::splat(0.1)) * 0.5;
    assert!(
        (centre - expected).length() < 1e-12,
        "{centre} vs {expected}"
    );
    let bytes = frame.to_rgb8();
    let srgb = |x: f64| (linear_to_srgb(x) * 255.0).round() as u8;
    assert_eq!(
        &bytes[12..15],
        &[srgb(expected.x), srgb(expected.y), srgb(expected.z)]
    );
}

/// The quadric `x^2 + y^2 + z^2 - r^2` and the analytic sphere render the
/// same image: at most 0.2% of pixels may differ, by at most 2/255.
#[test]
fn quadric_sphere_renders_like_the_analytic_sphere() {
    let mut scene = load("scenes/sphere.toml");
    let octree = std::sync::Arc::new(scene.build_octree().unwrap());
    let (analytic, _) = render_with(&scene, &octree, 160, 120, |s| s.samples = 16);
    let Shape::Sphere(Sphere {
        center: c,
        radius: r,
    }) = scene.shapes[0].clone()
    else {
        panic!("the first object of sphere.toml is the sphere");
    };
    std::sync::Arc::make_mut(&mut scene.shapes)[0] = Shape::Quadric(Box::new(Quadric::new(
        [
            1.0,
            0.0,
            0.0,
            -2.0 * c.x,
            1.0,
            0.0,
            -2.0 * c.y,
            1.0,
            -2.0 * c.z,
            c.length_squared() - r * r,
        ],
        None,
    )));
    let octree = std::sync::Arc::new(scene.build_octree().unwrap());
    let (quadric, _) = render_with(&scene, &octree, 160, 120, |s| s.samples = 16);
    let (over_one, largest) = diff(&analytic, &quadric, 0);
    let (over_two, _) = diff(&analytic, &quadric, 2);
    assert!(
        over_one <= 160 * 120 / 500 && over_two == 0,
        "{over_one} pixels differ, largest difference {largest}/255"
    );
}

/// Anti-aliasing changes pixels only near edges: where the 1-sample image is
/// flat over a pixel's 3x3 neighbourhood, 16 samples agree within 3/255;
/// and it does change the edges.
#[test]
fn sixteen_samples_differ_from_one_only_near_edges() {
    for name in ["scenes/sphere.toml", "scenes/quadrics.toml"] {
        let scene = load(name);
        let octree = std::sync::Arc::new(scene.build_octree().unwrap());
        let (w, h) = (120u32, 90u32);
        let (one, _) = render_with(&scene, &octree, w, h, |s| s.samples = 1);
        let (sixteen, _) = render_with(&scene, &octree, w, h, |s| s.samples = 16);
        let px = |img: &[u8], x: u32, y: u32| -> [u8; 3] {
            let i = ((y * w + x) * 3) as usize;
            [img[i], img[i + 1], img[i + 2]]
        };
        let max_diff =
            |a: [u8; 3], b: [u8; 3]| a.iter().zip(b).map(|(x, y)| x.abs_diff(y)).max().unwrap();
        let (mut flat, mut changed_edges) = (0, 0);
        for y in 1..h - 1 {
            for x in 1..w - 1 {
                let c = px(&one, x, y);
                let is_flat =
                    (0..9).all(|k| max_diff(c, px(&one, x + k % 3 - 1, y + k / 3 - 1)) <= 2);
                let d = max_diff(c, px(&sixteen, x, y));
                if is_flat {
                    flat += 1;
                    assert!(
                        d <= 3,
                        "{name}: flat pixel ({x}, {y}) changed by {d}/255 with 16 samples"
                    );
                } else if d > 3 {
                    changed_edges += 1;
                }
            }
        }
        assert!(
            flat > (w * h / 3) as usize,
            "{name}: only {flat} flat pixels"
        );
        assert!(
            changed_edges > 20,
            "{name}: anti-aliasing changed only {changed_edges} edge pixels"
        );
    }
}

#[test]
fn normals_and_depth_views_are_as_documented() {
    let scene = load("scenes/sphere.toml");
    let octree = std::sync::Arc::new(scene.build_octree().unwrap());
    let (w, h) = (81u32, 61u32);
    let (normals, _) = render_with(&scene, &octree, w, h, |s| {
        s.samples = 1;
        s.view = ViewMode::Normals;
    });
    // The camera looks at the sphere's centre: the middle pixel's normal
    // points back at the camera, (0, 0.1, 1) normalised roughly, encoded (n+1)/2.
    let mid = ((h / 2 * w + w / 2) * 3) as usize;
    let n =
        [normals[mid], normals[mid + 1], normals[mid + 2]].map(|b| b as f64 / 255.0 * 2.0 - 1.0);
    let expected = (scene.camera.eye - DVec3::new(0.0, 1.0, 0.0)).normalize();
    assert!(
        (DVec3::from(n) - expected).length() < 0.02,
        "{n:?} vs {expected}"
    );
    let (depth, _) = render_with(&scene, &octree, w, h, |s| {
        s.samples = 1;
        s.view = ViewMode::Depth;
    });
    // The grey level is near / distance (the nearest visible point white).
    // Distances from the pinhole's definition: pixel centres on the image
    // plane at distance 1, pixels 2 tan(fov/2) / h wide, in the basis
    // w = back from the view, u = up x w, v = w x u.
    let camera = scene.camera;
    let back = (camera.eye - camera.lookat).normalize();
    let right = camera.up.cross(back).normalize();
    let up = back.cross(right);
    let pixel = 2.0 * (camera.fov.to_radians() / 2.0).tan() / h as f64;
    let ray = |i: u32, j: u32| {
        let x = (i as f64 + 0.5 - w as f64 / 2.0) * pixel;
        let y = (h as f64 / 2.0 - j as f64 - 0.5) * pixel;
        (x * right + y * up - back).normalize()
    };
    // The floor (y = 0) from eye height; the middle ray runs through the
    // sphere's centre, meeting it one radius before.
    let floor = |i, j| camera.eye.y / -ray(i, j).y;
    let sphere = (camera.eye - DVec3::new(0.0, 1.0, 0.0)).length() - 1.0;
    // The nearest point is the floor at the bottom of the middle column.
    let near = floor(w / 2, h - 1);
    assert!(near < sphere);
    let grey = |i: u32, j: u32| depth[((j * w + i) * 3) as usize] as f64;
    let level = |distance: f64| 255.0 * near / distance;
    assert_eq!(grey(w / 2, h - 1), 255.0);
    assert!((grey(w / 2, h / 2) - level(sphere)).abs() <= 1.0, "sphere");
    // Floor pixels left of the sphere, near and far.
    for (i, j) in [(5, 50), (3, 40), (10, 33)] {
        let expected = level(floor(i, j));
        assert!(
            (grey(i, j) - expected).abs() <= 1.0,
            "pixel {i},{j}: {} vs {expected:.1}",
            grey(i, j)
        );
    }
}
