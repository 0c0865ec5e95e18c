//! What the renderer's queries walk, its shadow hints and light buffer
//! against brute force.

use super::*;
use crate::accel::sphere_grid;
use crate::math::{DVec3, Ray};
use crate::scene::ImageSettings;
use crate::stats::WorkCounts;

/// A deterministic stream of numbers in `[0, 1)` (an LCG) from `seed`.
fn uniform_from(mut state: u64) -> impl FnMut() -> f64 {
    move || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1);
        (state >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn scene_of(shapes: Vec<crate::shapes::Shape>) -> Scene {
    let camera = CameraSpec {
        eye: DVec3::new(0.0, 0.0, 10.0),
        lookat: DVec3::ZERO,
        up: DVec3::Y,
        fov: 30.0,
    };
    let mut scene = Scene::empty("routes".into(), camera, ImageSettings::default());
    scene.materials = vec![Material::default()];
    for shape in shapes {
        scene.push(shape, 0);
    }
    scene
}

/// Whether counted and uncounted queries (eye-ray packets among them)
/// walk the octree.
fn walks_octree(renderer: &Renderer) -> (bool, bool) {
    (
        renderer.walked_octree::<WorkCounts>().is_some(),
        renderer.walked_octree::<NoCounts>().is_some(),
    )
}

/// The accelerator `settings` ask for over `scene`, with a light buffer
/// built where it would be asked, or given (`Some`).
fn built(
    scene: &Scene,
    settings: RenderSettings,
    octree: Option<&std::sync::Arc<Octree>>,
    light_buffer: Option<crate::render::LightBufferSource>,
) -> Accelerator {
    let reuse = crate::render::Reuse {
        octree: octree.cloned(),
        bvh: None,
        light_buffer: light_buffer.unwrap_or_default(),
    };
    Accelerator::build(scene, &settings, reuse).unwrap()
}

/// Shadow rays in runs that share an origin and nearly a direction,
/// some ending before what blocks their neighbours, through a grid of
/// opaque and glass spheres: with the hints carried from ray to ray,
/// each lets through exactly what brute force finds.
#[test]
fn shadow_hints_change_no_answer() {
    let mut scene = scene_of(sphere_grid(3, 0.45));
    let glass = Material {
        transparency: 0.5,
        ..Material::default()
    };
    scene.materials.push(glass);
    let materials: Vec<u32> = (0..27).map(|i| (i % 5 == 0) as u32).collect();
    scene.shape_materials = std::sync::Arc::new(materials);
    let accel = crate::render::Accelerator::of_octree(&scene, scene.build_octree().unwrap());
    let renderer = Renderer::new(&scene, &accel, scene.render_settings()).unwrap();
    assert!(renderer.shadow_hints);
    let mut uniform = uniform_from(0x2545_f491_4f6c_dd1d);
    let mut scratch = Scratch::default();
    let (mut blocked, mut answered_by_hint) = (0, 0);
    for run in 0..60 {
        let origin = DVec3::new(uniform(), uniform(), uniform()) * 8.0 - 3.0;
        let aim = DVec3::new(uniform(), uniform(), uniform()) * 2.0;
        let light = run % 3;
        for _ in 0..40 {
            let jitter = DVec3::new(uniform(), uniform(), uniform()) - 0.5;
            let dir = (aim + 0.2 * jitter - origin).normalize();
            let distance = 0.5 + 9.0 * uniform();
            let ray = PreparedRay::new(Ray::new(origin, dir));
            let before = scratch.hints[light];
            let mut query = Query {
                counter: &mut NoCounts,
                scratch: &mut scratch,
            };
            let pass = renderer.transmittance(
                &ray,
                distance,
                light,
                crate::accel::ShapeRange::EMPTY,
                &mut query,
            );
            let mut crossings = ShadowCrossings::default();
            occlusion_brute_force(
                &renderer.primitives(),
                &ray,
                distance,
                &mut crossings,
                &mut NoCounts,
            );
            let expected = renderer.pass_through(&ray.ray, &crossings);
            assert_eq!(
                pass.to_bits(),
                expected.to_bits(),
                "run {run}: {ray:?} to {distance}"
            );
            blocked += (pass == 0.0) as u32;
            let hint = scratch.hints[light];
            answered_by_hint +=
                (pass == 0.0 && before.score >= 0 && hint.score > before.score) as u32;
        }
    }
    // The hints answered some rays, and not every blocked one.
    assert!(
        answered_by_hint > 100 && answered_by_hint < blocked,
        "{answered_by_hint} of {blocked}"
    );
}

/// Shadow rays from random points to each light of a grid of opaque
/// and glass spheres with lights among them let through the same with
/// the light buffer as without; the buffer is ignored where it would
/// hide the octree's work or answer for moved lights.
#[test]
fn the_light_buffer_changes_no_answer() {
    let mut scene = scene_of(sphere_grid(4, 0.3));
    scene.materials.push(Material {
        transparency: 0.5,
        ..Material::default()
    });
    let materials: Vec<u32> = (0..64).map(|i| (i % 3 == 0) as u32).collect();
    scene.shape_materials = std::sync::Arc::new(materials);
    let at = |x, y, z| crate::material::Light {
        position: DVec3::new(x, y, z),
        color: DVec3::ONE,
    };
    scene.lights = vec![at(1.5, 1.5, 1.5), at(-2.0, 5.0, 0.5), at(3.0, 0.5, 0.5)];
    let accel = crate::render::Accelerator::of_octree(&scene, scene.build_octree().unwrap());
    let octree = accel.octree();
    let with_buffer = built(&scene, scene.render_settings(), octree, None);
    let plain = Renderer::new(&scene, &accel, scene.render_settings()).unwrap();
    let buffered = Renderer::new(&scene, &with_buffer, scene.render_settings()).unwrap();
    assert!(buffered.has_light_buffer() && !plain.has_light_buffer());
    let mut uniform = uniform_from(0x853c_49e6_748f_ea9b);
    let (mut scratch, mut plain_scratch) = (Scratch::default(), Scratch::default());
    let (mut blocked, mut lit) = (0, 0);
    for n in 0..3_000 {
        let light = n % 3;
        let origin = DVec3::new(uniform(), uniform(), uniform()) * 6.0 - 1.5;
        let to_light = scene.lights[light].position - origin;
        let ray = PreparedRay::new(Ray::new(origin, to_light.normalize()));
        let pass = |renderer: &Renderer, scratch: &mut Scratch| {
            let mut query = Query {
                counter: &mut NoCounts,
                scratch,
            };
            renderer.transmittance(
                &ray,
                to_light.length(),
                light,
                crate::accel::ShapeRange::EMPTY,
                &mut query,
            )
        };
        let expected = pass(&plain, &mut plain_scratch);
        assert_eq!(
            pass(&buffered, &mut scratch).to_bits(),
            expected.to_bits(),
            "ray {n}: {ray:?}"
        );
        blocked += (expected == 0.0) as u32;
        lit += (expected == 1.0) as u32;
    }
    assert!(blocked > 300 && lit > 300, "{blocked} blocked, {lit} lit");
    // Brute force stays brute force; a moved light finds no buffer.
    let buffer = with_buffer.shared_light_buffer().cloned();
    let given = || Some(crate::render::LightBufferSource::Given(buffer.clone()));
    let mut off = scene.render_settings();
    off.accel = Accel::BruteForce;
    assert!(built(&scene, off, None, given()).light_buffer().is_none());
    let mut moved = scene.clone();
    moved.lights[2].position.x += 1e-9;
    let moved_accel = built(&moved, moved.render_settings(), octree, given());
    assert!(moved_accel.light_buffer().is_none());
    assert!(
        built(&scene, scene.render_settings(), octree, given())
            .light_buffer()
            .is_some()
    );
}

#[test]
fn a_one_leaf_tree_sends_only_counted_queries_through_the_octree() {
    let few = scene_of(sphere_grid(1, 0.5));
    let many = scene_of(sphere_grid(4, 0.3));
    for (scene, one_leaf) in [(&few, true), (&many, false)] {
        let mut settings = scene.render_settings();
        let accel = built(scene, settings, None, None);
        assert_eq!(accel.octree().unwrap().is_one_leaf(), one_leaf);
        let renderer = Renderer::new(scene, &accel, settings).unwrap();
        assert_eq!(walks_octree(&renderer), (true, !one_leaf));
        // A BVH takes every query, counted or not, and no packets; brute
        // force walks nothing.
        for other in [Accel::Bvh, Accel::BruteForce] {
            settings.accel = other;
            let accel = built(scene, settings, None, None);
            let renderer = Renderer::new(scene, &accel, settings).unwrap();
            assert_eq!(walks_octree(&renderer), (false, false));
            assert_eq!(renderer.accelerator().bvh().is_some(), other == Accel::Bvh);
            // Settings that ask for another accelerator than the one
            // given are refused, not quietly rendered through it.
            let octree_settings = RenderSettings {
                accel: Accel::Octree,
                ..settings
            };
            assert!(matches!(
                Renderer::new(scene, &accel, octree_settings),
                Err(RenderError::AccelMismatch { .. })
            ));
        }
    }
}

/// Stacked 60-gons cut into slivers, glass and opaque, over a floor of
/// slivers, lit from grazing angles, near the origin and a million away:
/// shadow rays that skip the shapes in the plane they leave give the
/// pictures brute force gives, byte for byte.
#[test]
fn shadow_rays_skipping_their_plane_change_no_picture() {
    for far in [0.0, 1e6] {
        let at = DVec3::splat(far);
        let fan = |center: DVec3, normal: DVec3, radius: f64| {
            let (u, w) = crate::math::orthonormal_basis(normal.normalize());
            let vertex = |k: usize| {
                let angle = std::f64::consts::TAU * k as f64 / 60.0;
                at + center + radius * (angle.cos() * u + angle.sin() * w)
            };
            (1..59)
                .filter_map(|k| crate::shapes::Triangle::new([vertex(0), vertex(k), vertex(k + 1)]))
                .map(crate::shapes::Shape::Triangle)
                .collect::<Vec<_>>()
        };
        let mut shapes = fan(DVec3::new(0.0, -1.0, 0.0), DVec3::Y, 4.0);
        for k in 0..6 {
            let tilt = DVec3::new(0.02 * k as f64, 1.0, -0.01 * k as f64);
            shapes.extend(fan(
                DVec3::new(0.1 * k as f64, 0.3 * k as f64, 0.0),
                tilt,
                1.5,
            ));
        }
        let count = shapes.len();
        let mut scene = scene_of(shapes);
        scene.camera.eye = at + DVec3::new(0.0, 4.0, 9.0);
        scene.camera.lookat = at;
        scene.materials.push(Material {
            transparency: 0.7,
            ior: 1.3,
            ..Material::default()
        });
        // Every other disc glass, the floor opaque.
        let materials: Vec<u32> = (0..count).map(|i| ((i / 58) % 2 == 1) as u32).collect();
        scene.shape_materials = std::sync::Arc::new(materials);
        let light = |x, y, z| crate::material::Light {
            position: at + DVec3::new(x, y, z),
            color: DVec3::splat(0.5),
        };
        scene.lights = vec![
            light(6.0, 0.05, 1.0),
            light(-3.0, 5.0, 2.0),
            light(0.5, 1.62, -4.0),
        ];
        let accel = crate::render::Accelerator::of_octree(&scene, scene.build_octree().unwrap());
        let mut settings = scene.render_settings();
        (settings.width, settings.height, settings.samples) = (96, 72, 1);
        let with_buffer = built(&scene, settings, accel.octree(), None);
        let skipping = Renderer::new(&scene, &with_buffer, settings).unwrap();
        let walking = Renderer::new(&scene, &accel, settings).unwrap();
        assert!(skipping.skips_planes && walking.skips_planes);
        assert!(skipping.has_light_buffer());
        let brute_settings = RenderSettings {
            accel: Accel::BruteForce,
            ..settings
        };
        let brute_accel = built(&scene, brute_settings, None, None);
        let brute = Renderer::new(&scene, &brute_accel, brute_settings).unwrap();
        assert!(!brute.skips_planes);
        let picture = |r: &Renderer| r.render(false, None).0.to_rgb8();
        let expected = picture(&brute);
        assert!(
            picture(&skipping) == expected,
            "far {far}: through the light buffer"
        );
        assert!(
            picture(&walking) == expected,
            "far {far}: through the octree"
        );
    }
}
