//! Adaptive anti-aliasing: refined pixels are exactly the full grid's,
//! the others exactly the centre sample's, and the picture stays within a
//! stated error of the full grid.

use crate::common;
use glint::settings::Accel;

use glint::accel::Octree;
use glint::image::frame::Frame;
use glint::render::Renderer;
use glint::scene::Scene;
use glint::settings::AntiAliasing;

fn render(
    scene: &Scene,
    octree: &std::sync::Arc<Octree>,
    aa: AntiAliasing,
    w: u32,
    h: u32,
) -> (Frame, u64) {
    let mut settings = scene.render_settings();
    (settings.width, settings.height) = (w, h);
    settings.set_anti_aliasing(aa);
    let accel = crate::common::accelerator(scene, &settings, Some(octree));
    let (frame, counts) = Renderer::new(scene, &accel, settings)
        .unwrap()
        .render(false, None);
    assert_eq!(counts.nonfinite_samples, 0);
    (frame, counts.refined_pixels)
}

#[test]
fn adaptive_pixels_are_either_the_full_grid_or_the_centre() {
    let scene = common::load("scenes/default.toml");
    let octree = std::sync::Arc::new(scene.build_octree().unwrap());
    let (w, h) = (160, 120);
    let (off, _) = render(&scene, &octree, AntiAliasing::Off, w, h);
    let (full, _) = render(&scene, &octree, AntiAliasing::Full, w, h);
    let (adaptive, refined) = render(&scene, &octree, AntiAliasing::Adaptive, w, h);
    let (mut from_full, mut from_centre) = (0u64, 0u64);
    for k in 0..(w * h) as usize {
        let p = adaptive.pixels[k];
        if p == full.pixels[k] && p != off.pixels[k] {
            from_full += 1;
        } else if p == off.pixels[k] {
            from_centre += 1;
        } else {
            panic!("pixel {k} is neither the full grid's nor the centre's");
        }
    }
    assert!(
        refined > 0 && refined < (w * h) as u64 / 2,
        "refined {refined}"
    );
    // Refined pixels equal to their centre sample count as either.
    assert!(from_full <= refined && refined <= from_full + from_centre);
    eprintln!("adaptive: {refined} of {} pixels refined", w * h);
}

#[test]
fn adaptive_is_within_45_db_of_the_full_grid_on_every_scene_kind() {
    for name in [
        "scenes/default.toml",
        "scenes/glass.toml",
        "scenes/spd/balls.nff",
    ] {
        let scene = common::load(name);
        let octree = std::sync::Arc::new(scene.build_octree().unwrap());
        let (full, _) = render(&scene, &octree, AntiAliasing::Full, 200, 150);
        let (adaptive, refined) = render(&scene, &octree, AntiAliasing::Adaptive, 200, 150);
        let (off, _) = render(&scene, &octree, AntiAliasing::Off, 200, 150);
        let psnr = |image: &glint::image::frame::Frame| {
            glint::image::metrics::image_error(&image.pixels, &full.pixels, full.colors)
                .psnr_display
        };
        let db = psnr(&adaptive);
        eprintln!(
            "{name}: adaptive {db:.1} dB ({:.1}% refined), off {:.1} dB",
            100.0 * refined as f64 / 30_000.0,
            psnr(&off)
        );
        assert!(db >= 45.0, "{name}: {db:.1} dB");
        assert!(
            db > psnr(&off),
            "{name}: refining improves on the centre alone"
        );
    }
}

#[test]
fn adaptive_is_the_same_with_the_octree_off() {
    let scene = common::load("scenes/glass.toml");
    let octree = std::sync::Arc::new(scene.build_octree().unwrap());
    let mut settings = scene.render_settings();
    (settings.width, settings.height) = (96, 72);
    settings.set_anti_aliasing(AntiAliasing::Adaptive);
    let accel = crate::common::accelerator(&scene, &settings, Some(&octree));
    let on = Renderer::new(&scene, &accel, settings)
        .unwrap()
        .render(false, None);
    settings.accel = Accel::BruteForce;
    let accel = crate::common::accelerator(&scene, &settings, Some(&octree));
    let off = Renderer::new(&scene, &accel, settings)
        .unwrap()
        .render(false, None);
    assert_eq!(on.0, off.0);
    assert_eq!(on.1.refined_pixels, off.1.refined_pixels);
}
