//! Packets give the bytes single rays give: every SIMD level this machine
//! runs renders every scene, view and setting byte-identically to the
//! scalar path, and casts the same rays.

use crate::common;
use glint::settings::Accel;

use common::{all_scenes, load, scene_from};
use glint::accel::Octree;
use glint::render::Renderer;
use glint::scene::Scene;
use glint::settings::{RenderSettings, ViewMode};
use glint::simd::SimdLevel;
use proptest::prelude::*;

/// The levels above scalar this machine runs. On a machine without AVX2
/// there is nothing to compare scalar with: the tests below say so and
/// render nothing.
fn packet_levels() -> Vec<SimdLevel> {
    let levels: Vec<_> = SimdLevel::ALL[1..]
        .iter()
        .copied()
        .filter(|l| l.is_available())
        .collect();
    if levels.is_empty() {
        eprintln!("this machine has no AVX2: only the scalar path is tested");
    }
    levels
}

/// Renders at every level and asserts each equals the scalar render.
fn assert_levels_agree(
    scene: &Scene,
    octree: &std::sync::Arc<Octree>,
    label: &str,
    adjust: impl Fn(&mut RenderSettings),
) {
    let render = |level: SimdLevel| {
        let mut settings = scene.render_settings();
        adjust(&mut settings);
        let accel = crate::common::accelerator(scene, &settings, Some(octree));
        let renderer = Renderer::new(scene, &accel, settings)
            .unwrap()
            .with_simd(level);
        assert_eq!(renderer.simd(), level);
        let (frame, counts) = renderer.render(false, None);
        (frame.to_rgb8(), counts.rays)
    };
    let levels = packet_levels();
    if levels.is_empty() {
        return;
    }
    let (scalar, scalar_rays) = render(SimdLevel::Scalar);
    for level in levels {
        let (packets, rays) = render(level);
        let (differing, largest) = common::diff(&scalar, &packets, 0);
        assert_eq!(
            differing,
            0,
            "{label}: {} differs from scalar in {differing} pixels (by up to {largest})",
            level.name()
        );
        assert_eq!(
            rays,
            scalar_rays,
            "{label}: {} cast other rays",
            level.name()
        );
    }
}

#[test]
fn every_scene_renders_the_same_bytes_at_every_level() {
    for name in all_scenes() {
        let loaded = common::loaded(&name);
        let (scene, octree) = (&loaded.0, &loaded.1);
        // Odd sizes leave partial packets at the ends of rows.
        let side = if scene.shapes.len() > 20_000 { 19 } else { 37 };
        for samples in [1, 16] {
            assert_levels_agree(scene, octree, &format!("{name} {samples} spp"), |s| {
                s.width = side;
                s.height = side - 4;
                s.samples = samples;
            });
        }
    }
}

#[test]
fn views_octree_off_and_adaptive_agree_at_every_level() {
    for name in [
        "scenes/bunny.toml",
        "scenes/glass.toml",
        "scenes/quadrics.toml",
    ] {
        let scene = load(name);
        let octree = std::sync::Arc::new(scene.build_octree().unwrap());
        for view in [ViewMode::Normals, ViewMode::Depth, ViewMode::AaNeed] {
            assert_levels_agree(&scene, &octree, &format!("{name} {view:?}"), |s| {
                s.width = 33;
                s.height = 21;
                s.view = view;
            });
        }
        assert_levels_agree(&scene, &octree, &format!("{name} octree off"), |s| {
            s.width = 21;
            s.height = 13;
            s.accel = Accel::BruteForce;
        });
        assert_levels_agree(&scene, &octree, &format!("{name} adaptive"), |s| {
            s.width = 41;
            s.height = 31;
            s.samples = 16;
            s.adaptive = true;
        });
    }
}

/// A random soup of triangles and spheres, some of them glass, some
/// coincident, seen from a random eye: lanes of one packet go different
/// ways through the octree, into different shapes and out through glass.
fn soup_strategy() -> impl Strategy<Value = String> {
    let coord = prop_oneof![3 => -3.0..3.0f64, 1 => Just(0.0), 1 => Just(1.5)];
    let point = (coord.clone(), coord.clone(), coord).prop_map(|(x, y, z)| [x, y, z]);
    let material = prop_oneof![Just("matte"), Just("glass"), Just("mirror")];
    let triangle = (point.clone(), point.clone(), point.clone(), material.clone()).prop_map(
        |(a, b, c, m)| {
            format!(
                "[[objects]]\nkind = \"triangle\"\nmaterial = \"{m}\"\nvertices = [{a:?}, {b:?}, {c:?}]\n"
            )
        },
    );
    let sphere = (point.clone(), 0.1..1.2f64, material).prop_map(|(c, r, m)| {
        format!(
            "[[objects]]\nkind = \"sphere\"\nmaterial = \"{m}\"\ncenter = {c:?}\nradius = {r}\n"
        )
    });
    let eye = (4.0..9.0f64, -1.0..1.0f64, 0.0..std::f64::consts::TAU);
    (
        prop::collection::vec(prop_oneof![triangle, sphere], 1..25),
        eye,
        0usize..3,
    )
        .prop_map(|(objects, (distance, height, angle), duplicate)| {
            let mut text = format!(
                "[camera]\neye = [{}, {}, {}]\nlookat = [0, 0, 0]\nup = [0, 1, 0]\nfov = 50\n\n\
                 [image]\nwidth = 23\nheight = 17\nsamples = 1\nmax_depth = 6\n\n\
                 [materials.matte]\ncolor = [0.8, 0.5, 0.3]\nks = 0.3\nshininess = 20\n\n\
                 [materials.glass]\ncolor = [1, 1, 1]\nkd = 0.1\ntransparency = 0.8\nior = 1.4\n\n\
                 [materials.mirror]\ncolor = [0.9, 0.9, 0.9]\nreflectivity = 0.7\n\n\
                 [[lights]]\nposition = [2, 6, 3]\ncolor = [1, 1, 1]\n\n",
                distance * angle.cos(),
                height * distance,
                distance * angle.sin()
            );
            for o in &objects {
                text.push_str(o);
            }
            // Coincident copies: ties between lanes and between shapes.
            for o in objects.iter().take(duplicate) {
                text.push_str(o);
            }
            text
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]

    #[test]
    fn random_soups_render_the_same_bytes_at_every_level(text in soup_strategy()) {
        let scene = scene_from(&text, "soup.toml");
        let octree = std::sync::Arc::new(scene.build_octree().unwrap());
        assert_levels_agree(&scene, &octree, &text, |_| {});
        assert_levels_agree(&scene, &octree, &text, |s| s.samples = 16);
    }
}
