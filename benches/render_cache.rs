//! The render cache on its own, without the viewer: a scene orbited as the
//! viewer's orbit benchmark orbits it (5.6 radians about the up axis in
//! `FRAMES` previews), each preview given `MS` milliseconds of fresh rays,
//! and every `EVERY`-th preview compared with the exact 1-sample picture at
//! its camera. Prints each compared preview's timings, sources and PSNR.
//!
//!     cargo bench --bench render_cache -- scenes/default.toml [FRAMES] [MS] [EVERY]
//!
//! For tuning the cache's steps; the figures users see are the viewer's
//! (`benches/orbit_previews.py`), where the window's own drawing shares
//! the cores.

use std::time::{Duration, Instant};

use glint::camera::CameraSpec;
use glint::image::frame::rgb_to_rgba;
use glint::image::metrics::psnr_8bit;
use glint::math::DVec3;
use glint::render::Renderer;
use glint::render::render_cache::{PreviewBudget, RenderCache};
use glint::settings::AntiAliasing;

fn orbit(c: &CameraSpec, angle: f64) -> CameraSpec {
    let axis = c.up.normalize();
    let d = c.eye - c.lookat;
    let (s, co) = angle.sin_cos();
    let along = axis * d.dot(axis);
    let across = d - along;
    let rotated = across * co + axis.cross(across) * s;
    CameraSpec {
        eye: c.lookat + along + rotated,
        ..*c
    }
}

fn main() {
    let args: Vec<String> = std::env::args()
        .skip(1)
        .filter(|a| a != "--bench")
        .collect();
    let path = args.first().map_or("scenes/default.toml", String::as_str);
    let frames: usize = args.get(1).and_then(|a| a.parse().ok()).unwrap_or(150);
    let ms: f64 = args.get(2).and_then(|a| a.parse().ok()).unwrap_or(12.0);
    let every: usize = args.get(3).and_then(|a| a.parse().ok()).unwrap_or(15);
    let scene = glint::scene::load(std::path::Path::new(path)).expect("scene");
    let mut settings = scene.render_settings();
    let accel =
        glint::render::Accelerator::build(&scene, &settings, Default::default()).expect("octree");
    let final_settings = settings;
    settings.set_anti_aliasing(AntiAliasing::Off);
    let renderer_at = |camera: &CameraSpec, s| {
        Renderer::with_camera(&scene, &accel, s, camera).expect("renderer")
    };
    let start_camera = scene.camera;
    let (seed_frame, _) = renderer_at(&start_camera, final_settings).render(false, None);
    // With SCALE=k, the cache keeps a point for every k x k pixels and the
    // picture is enlarged to the image's size.
    let scale: u32 = std::env::var("SCALE")
        .ok()
        .and_then(|s| s.parse().ok())
        .unwrap_or(1);
    let full = (settings.width, settings.height);
    settings.width = settings.width.div_ceil(scale);
    settings.height = settings.height.div_ceil(scale);
    let seed_rgba =
        glint::render::render_cache::shrink(&rgb_to_rgba(&seed_frame.to_rgb8()), full, scale);
    let mut enlarged = Vec::new();
    let mut cache = RenderCache::default();
    let step = 5.6 / frames as f64;
    let seed_renderer = renderer_at(&start_camera, settings);
    let mut total = Duration::ZERO;
    let mut values = Vec::new();
    for k in 1..=frames {
        let camera = if std::env::var_os("PAN").is_some() {
            // Turning on the spot: the eye stays, lookat turns about it.
            let c = start_camera;
            let turned = orbit(
                &CameraSpec {
                    eye: c.lookat,
                    lookat: c.eye,
                    ..c
                },
                -step * k as f64,
            );
            CameraSpec {
                eye: c.eye,
                lookat: turned.eye,
                ..c
            }
        } else {
            orbit(&start_camera, -step * k as f64)
        };
        let r = renderer_at(&camera, settings);
        let start = Instant::now();
        let budget = PreviewBudget {
            rays: Duration::from_secs_f64(ms / 1000.0),
        };
        let seed = (k == 1).then_some((&seed_renderer, seed_rgba.as_slice()));
        let s = cache.preview(&r, seed, budget);
        let took = start.elapsed();
        total += took;
        if k % every == 0 || k == 1 {
            let (exact, _) = renderer_at(&camera, final_settings).render(false, None);
            let truth = rgb_to_rgba(&exact.to_rgb8());
            let (image, w, h) = cache.image();
            glint::render::render_cache::enlarge(image, (w, h), full, true, &mut enlarged);
            let (image, width, height) = (enlarged.as_slice(), full.0, full.1);
            let db = psnr_8bit(image, &truth, 4);
            values.push(db);
            println!(
                "frame {k:4}: {:6.1} ms (seed {:.1}, reproject {:.1}, rays {:.1}, fill {:.1}) {:5.2} dB  {}",
                took.as_secs_f64() * 1e3,
                s.seed_seconds * 1e3,
                s.reproject_seconds * 1e3,
                s.trace_seconds * 1e3,
                s.fill_seconds * 1e3,
                db,
                s.describe()
            );
            if std::env::var_os("SAVE").is_some() {
                let dir = std::path::Path::new("/tmp/rc");
                std::fs::create_dir_all(dir).ok();
                let save = |name: String, rgba: &[u8]| {
                    let rgb = glint::image::frame::rgba_to_rgb(rgba);
                    glint::export::save_rgb_png(&dir.join(name), width, height, &rgb, None).ok();
                };
                save(format!("p{k:04}.png"), image);
                save(format!("t{k:04}.png"), &truth);
                let mut sources = Vec::new();
                cache.source_colors(&mut sources);
                let mut big = Vec::new();
                glint::render::render_cache::enlarge(&sources, (w, h), full, false, &mut big);
                save(format!("s{k:04}.png"), &big);
            }
        }
    }
    values.sort_by(f64::total_cmp);
    println!(
        "{frames} previews, mean {:.1} ms; PSNR median {:.2} dB, min {:.2} dB over {} compared",
        total.as_secs_f64() * 1e3 / frames as f64,
        values[values.len() / 2],
        values[0],
        values.len()
    );
    let _ = DVec3::ZERO;
}
