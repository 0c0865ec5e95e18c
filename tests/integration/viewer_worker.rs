//! The viewer's render worker, checked directly: each plan's passes,
//! cancellation, previews in flight, the pass cache.
#![cfg(feature = "gui")]

use crate::common;
use glint::settings::Accel;

use std::sync::Arc;
use std::time::Duration;

use common::viewer::*;
use glint::accel::Octree;
use glint::image::frame::rgba_to_rgb;
use glint::image::metrics::psnr_8bit;
use glint::render::PassKind as Engine;
use glint::render::Renderer;
use glint::settings::AntiAliasing;
use glint::viewer::worker::{Job, ShownPass, Worker};

/// The worker shows each pass of the engine's plan, and the buffer it ends
/// on is exactly the frame `glint render` writes: the tiles it swept in
/// were replaced by the finished frame.
#[test]
fn each_plan_shows_its_passes_and_ends_on_the_cli_frame() {
    let worker = Worker::spawn(2, || {});
    let spd = glint::settings::Protocol::Spd;
    let cases = [
        (
            "scenes/glass.toml",
            AntiAliasing::Full,
            None,
            vec![
                ShownPass::full(Engine::OneSample),
                ShownPass::full(Engine::Grid),
            ],
        ),
        (
            "scenes/default.toml",
            AntiAliasing::Adaptive,
            None,
            vec![
                ShownPass::full(Engine::OneSample),
                ShownPass::full(Engine::Refine),
            ],
        ),
        (
            "scenes/spd/sizes/balls_s1.nff",
            AntiAliasing::Off,
            Some(spd),
            vec![ShownPass::full(Engine::Corners)],
        ),
    ];
    for (scene_file, aa, protocol, expected) in cases {
        let (mut job, scene, octree) = job(scene_file, 120, 90, aa);
        if let Some(p) = protocol {
            job.settings = job.settings.with_protocol(p);
        }
        let settings = job.settings;
        let generation = worker.submit(job);
        assert!(worker.wait_finished(generation, WAIT));
        let passes: Vec<_> = worker
            .history()
            .iter()
            .copied()
            .filter(|r| r.generation == generation)
            .collect();
        let kinds: Vec<ShownPass> = passes.iter().map(|r| r.kind).collect();
        assert_eq!(kinds, expected, "{scene_file}");
        let accel = crate::common::accelerator(&scene, &settings, Some(&octree));
        let (frame, counts) = Renderer::new(&scene, &accel, settings)
            .unwrap()
            .render(false, None);
        let last = passes.last().unwrap();
        assert_eq!(last.refined_pixels.is_some(), aa == AntiAliasing::Adaptive);
        if let Some(refined) = last.refined_pixels {
            assert!(refined > 0 && refined < 120 * 90);
            assert_eq!(refined, counts.refined_pixels);
        }
        let shown: Vec<u8> = worker.with_buffer(|b| rgba_to_rgb(&b.rgba));
        assert!(
            shown == frame.to_rgb8(),
            "{scene_file}: the finished buffer equals the CLI render"
        );
    }
}

/// A render-cache preview while moving fills the whole image, is seeded
/// from the finished image on screen, is close to the exact picture at its
/// camera (reflections and refraction included), and says what it is made
/// of; the full passes after it still end on `glint render`'s bytes.
#[test]
fn render_cache_previews_fill_the_image_and_the_passes_still_end_on_the_cli_frame() {
    use glint::viewer::worker::Preview;
    let worker = Worker::spawn(2, || {});
    let (still, scene, octree) = job("scenes/glass.toml", 240, 180, AntiAliasing::Off);
    let g = worker.submit(still.clone());
    assert!(worker.wait_finished(g, WAIT));
    let mut moving = still.clone();
    moving.preview = Some(Preview::Reuse);
    moving.camera.eye.x += 0.05 * (moving.camera.eye - moving.camera.lookat).length();
    moving.serial = 1;
    worker.submit_preview(moving.clone());
    let start = std::time::Instant::now();
    while worker.with_buffer(|b| b.serial) != 1 || worker.preview_counts().completed < 1 {
        assert!(start.elapsed() < WAIT, "{:?}", worker.preview_counts());
        std::thread::sleep(Duration::from_millis(1));
    }
    let (shown, pass) = worker.with_buffer(|b| {
        assert_eq!((b.width, b.height, b.rgba.len()), (240, 180, 4 * 240 * 180));
        (rgba_to_rgb(&b.rgba), b.pass)
    });
    assert_eq!(pass.and_then(|p| p.preview), Some(Preview::Reuse));
    let history = worker.history();
    let summary = history
        .iter()
        .rev()
        .find_map(|r| r.reuse)
        .expect("the preview's record says what it is made of");
    assert!(summary.seeded, "{summary:?}");
    assert!(summary.scale >= 1 && summary.pixels() > 0, "{summary:?}");
    let mut settings = moving.settings;
    settings.set_anti_aliasing(AntiAliasing::Off);
    let exact = |camera: &glint::camera::CameraSpec| {
        let accel = crate::common::accelerator(&scene, &settings, Some(&octree));
        Renderer::with_camera(&scene, &accel, settings, camera)
            .unwrap()
            .render(false, None)
            .0
            .to_rgb8()
    };
    let truth = exact(&moving.camera);
    let db = psnr_8bit(&shown, &truth, 3);
    // Closer to the picture at the new camera than the picture at the old
    // one is: the points moved with the view.
    let old = psnr_8bit(&exact(&still.camera), &truth, 3);
    assert!(
        db > old + 2.0,
        "preview {db:.1} dB, old picture {old:.1} dB"
    );
    // Released: the full passes at the moved camera, exact as ever.
    let mut released = moving.clone();
    released.preview = None;
    released.serial = 2;
    let g = worker.submit(released);
    assert!(worker.wait_finished(g, WAIT));
    assert!(worker.with_buffer(|b| rgba_to_rgb(&b.rgba)) == truth);
}

/// While the user drags, previews asked for while one is in flight do not
/// cancel it: it completes and is shown, the newest one waits (replacing
/// the older waiting one) and runs next; a full job cancels both.
#[test]
fn previews_in_flight_complete_and_the_newest_waiting_one_follows() {
    use glint::viewer::worker::{Preview, Reduced, Reflections};
    let worker = Worker::spawn(2, || {});
    let preview = Preview::Reduced(Reduced {
        divisor: 1,
        reflections: Reflections::All,
        shadows: true,
    });
    // A preview that takes a while: the glass scene at 640x480.
    let (mut slow, _, _) = job("scenes/glass.toml", 640, 480, AntiAliasing::Off);
    slow.preview = Some(preview);
    slow.serial = 1;
    worker.submit_preview(slow.clone());
    let first = worker.generation();
    let start = std::time::Instant::now();
    while worker.tiles_started(first) == 0 {
        assert!(start.elapsed() < WAIT);
        std::thread::sleep(Duration::from_millis(1));
    }
    // Two newer cameras while it renders: the second replaces the first.
    for serial in [2, 3] {
        let mut newer = slow.clone();
        newer.camera.eye.x += 0.1 * serial as f64;
        newer.serial = serial;
        worker.submit_preview(newer);
    }
    assert_eq!(worker.generation(), first, "nothing was cancelled");
    let start = std::time::Instant::now();
    while worker.with_buffer(|b| b.serial) != 3 || worker.preview_counts().completed < 2 {
        assert!(start.elapsed() < WAIT, "{:?}", worker.preview_counts());
        std::thread::sleep(Duration::from_millis(1));
    }
    let counts = worker.preview_counts();
    assert_eq!(
        (counts.started, counts.completed),
        (2, 2),
        "the preview in flight and the newest waiting one ran, both to the end"
    );
    assert!(worker.with_buffer(|b| b.finished && b.width == 640));

    // A preview in flight with one waiting, then a full job: both go.
    // (A new worker: the first may not yet have emptied its queue.)
    let worker = Worker::spawn(2, || {});
    slow.serial = 4;
    worker.submit_preview(slow.clone());
    let in_flight = worker.generation();
    while worker.tiles_started(in_flight) == 0 {
        std::thread::sleep(Duration::from_millis(1));
    }
    slow.serial = 5;
    worker.submit_preview(slow.clone());
    let (mut full, _, _) = job("scenes/sphere.toml", 32, 24, AntiAliasing::Off);
    full.serial = 6;
    let g = worker.submit(full);
    assert!(worker.wait_finished(g, WAIT));
    assert_eq!(worker.with_buffer(|b| b.serial), 6);
    std::thread::sleep(Duration::from_millis(50));
    let counts = worker.preview_counts();
    assert_eq!(counts.started, 1, "the waiting preview never started");
    assert_eq!(counts.completed, 0, "the one in flight was cancelled");
    assert_eq!(worker.generation(), g);
}

#[test]
fn a_new_job_cancels_the_old_one_within_a_tile() {
    let threads = 2;
    let worker = Worker::spawn(threads, || {});
    // Big enough to take a while: 16 samples at 640x480 of the glass scene.
    let (slow, _, _) = job("scenes/glass.toml", 640, 480, AntiAliasing::Full);
    let first = worker.submit(slow);
    // Wait until the first pass has produced some tiles.
    let start = std::time::Instant::now();
    while worker.with_buffer(|b| b.generation != first || b.tiles_done < 2) {
        assert!(start.elapsed() < WAIT);
        std::thread::sleep(Duration::from_millis(1));
    }
    let (quick, _, _) = job("scenes/sphere.toml", 32, 24, AntiAliasing::Off);
    let started_at_cancel = worker.tiles_started(first);
    let second = worker.submit(quick);
    assert!(worker.wait_finished(second, WAIT));
    let total_first = worker.tiles_started(first);
    assert!(
        total_first <= started_at_cancel + threads as u64,
        "after cancellation at most one more tile per thread: {started_at_cancel} then {total_first}"
    );
    let tiles_in_full_job = 2 * glint::render::tiles::tiles(640, 480).len() as u64;
    assert!(
        total_first < tiles_in_full_job,
        "the first job did not run to completion"
    );
    assert!(
        worker
            .history()
            .iter()
            .all(|r| r.generation != first || r.kind == ShownPass::full(Engine::OneSample))
    );
}

/// Switching back to an image already rendered (the view, anti-aliasing)
/// shows it from the worker's cache: no tile is rendered, and the bytes
/// are those a fresh render gives. The octree switch (whose time is the
/// point of toggling it) and an edit (a new scene) render again.
#[test]
fn view_switches_show_passes_already_rendered_without_rendering() {
    use glint::settings::ViewMode;
    let worker = Worker::spawn(2, || {});
    let (full, scene, octree) = job("scenes/glass.toml", 48, 36, AntiAliasing::Full);
    let first = worker.submit(full.clone());
    assert!(worker.wait_finished(first, WAIT));
    let fresh = |j: &Job| {
        let other = Worker::spawn(2, || {});
        let g = other.submit(j.clone());
        assert!(other.wait_finished(g, WAIT));
        other.with_buffer(|b| b.rgba.clone())
    };
    let mut aa_need = full.clone();
    aa_need.settings.view = ViewMode::AaNeed;
    let mut off = full.clone();
    off.settings.set_anti_aliasing(AntiAliasing::Off);
    for (name, j) in [("aa-need", &aa_need), ("AA off", &off), ("shaded", &full)] {
        let g = worker.submit(j.clone());
        assert!(worker.wait_finished(g, WAIT), "{name}");
        assert_eq!(worker.tiles_started(g), 0, "{name} was rendered again");
        assert_eq!(worker.with_buffer(|b| b.rgba.clone()), fresh(j), "{name}");
        let records: Vec<_> = worker
            .history()
            .iter()
            .copied()
            .filter(|r| r.generation == g)
            .collect();
        assert!(
            !records.is_empty() && records.iter().all(|r| r.from_cache),
            "{name}"
        );
    }
    let mut brute_force = off.clone();
    brute_force.settings.accel = Accel::BruteForce;
    let g = worker.submit(brute_force);
    assert!(worker.wait_finished(g, WAIT));
    assert!(
        worker.tiles_started(g) > 0,
        "octree off: rendered and timed"
    );
    // The cost view counts the octree's tests: another octree, another image.
    let mut cost = full.clone();
    cost.settings.view = ViewMode::Cost;
    let g = worker.submit(cost.clone());
    assert!(worker.wait_finished(g, WAIT));
    assert!(worker.tiles_started(g) > 0);
    let finer = glint::accel::OctreeParams {
        leaf_size: 1,
        ..scene.octree_params
    };
    cost.octree = Arc::new(Octree::build(&scene.shapes, finer).unwrap());
    let g = worker.submit(cost);
    assert!(worker.wait_finished(g, WAIT));
    assert!(
        worker.tiles_started(g) > 0,
        "cost view, another octree: rendered"
    );
    // An edited scene is a new scene.
    let mut edited = (*scene).clone();
    edited.lights[0].color *= 0.5;
    let edited_job = Job {
        scene: Arc::new(edited),
        octree,
        ..full
    };
    let g = worker.submit(edited_job);
    assert!(worker.wait_finished(g, WAIT));
    assert!(worker.tiles_started(g) > 0, "an edit renders again");
}
