//! The viewer without a display: egui_kittest drives the UI headless, and
//! the render worker is checked directly.
#![cfg(feature = "gui")]

mod common;

use std::sync::Arc;
use std::time::Duration;

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use glint::accel::Octree;
use glint::render::{RenderSettings, Renderer};
use glint::viewer::worker::{Job, PassKind, Worker};
use glint::viewer::{GlintApp, SceneSource, ViewerOptions};

const WAIT: Duration = Duration::from_secs(60);

/// A small, quick scene for UI tests.
fn small_app() -> GlintApp {
    let source = SceneSource::File(common::repo_path("scenes/sphere.toml"));
    let mut app = GlintApp::new(source, ViewerOptions::default(), || {}).unwrap();
    app.settings_mut().width = 64;
    app.settings_mut().height = 48;
    app
}

fn harness(app: GlintApp) -> Harness<'static, GlintApp> {
    let mut h = Harness::builder()
        .with_size(egui::vec2(1200.0, 800.0))
        // egui 0.37's DragValue does not expose the names glint gives it
        // (`accessible_name`) to kittest's check; the panels label every one.
        .with_accessibility_check(false)
        .build_ui_state(|ui, app: &mut GlintApp| app.frame_ui(ui), app);
    h.run_steps(2);
    h
}

#[test]
fn toggling_octree_and_anti_aliasing_restarts_the_passes() {
    let mut h = harness(small_app());
    let before = h.state().worker().generation();
    assert!(h.state().settings().use_octree);
    h.get_by_label("Octree").click();
    h.run_steps(2);
    assert!(
        !h.state().settings().use_octree,
        "the checkbox turns the octree off"
    );
    let after_octree = h.state().worker().generation();
    assert!(after_octree > before, "a new render was started");

    let aa = h.state().anti_aliasing();
    h.get_by_label("Anti-aliasing (16 samples, 4x4 grid)")
        .click();
    h.run_steps(2);
    assert_eq!(h.state().anti_aliasing(), !aa);
    assert!(h.state().worker().generation() > after_octree);
}

#[test]
fn display_only_frames_do_not_restart() {
    let mut h = harness(small_app());
    let generation = h.state().worker().generation();
    // Redraws, and a window resize (the image is scaled to fit; its
    // resolution is a render setting), change nothing the renderer uses.
    h.run_steps(5);
    h.set_size(egui::vec2(900.0, 700.0));
    h.run_steps(3);
    assert_eq!(h.state().worker().generation(), generation);
}

#[test]
fn editing_a_light_restarts() {
    let mut h = harness(small_app());
    let generation = h.state().worker().generation();
    h.state_mut().scene_mut().lights[0].position.x += 1.0;
    h.run_steps(2);
    assert!(h.state().worker().generation() > generation);
}

#[test]
fn export_writes_the_displayed_buffer() {
    let mut h = harness(small_app());
    let generation = h.state().worker().generation();
    assert!(
        h.state().worker().wait_finished(generation, WAIT),
        "the render finished"
    );
    let path = std::env::temp_dir().join(format!("glint-export-{}.png", std::process::id()));
    h.state().export_to(&path).unwrap();
    let png = image::open(&path).unwrap().to_rgb8();
    let _ = std::fs::remove_file(&path);
    let (w, hgt, rgba) = h
        .state()
        .worker()
        .with_buffer(|b| (b.width, b.height, b.rgba.clone()));
    assert_eq!((png.width(), png.height()), (w, hgt));
    let rgb: Vec<u8> = rgba
        .chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect();
    assert!(
        png.into_raw() == rgb,
        "exported pixels equal the display buffer"
    );
}

fn job(
    scene: &str,
    width: u32,
    height: u32,
    anti_aliasing: bool,
) -> (Job, Arc<glint::scene::Scene>, Arc<Octree>) {
    let scene = Arc::new(common::load(scene));
    let octree = Arc::new(Octree::build(&scene.shapes, scene.octree_params));
    let mut settings = RenderSettings::from_scene(&scene);
    settings.width = width;
    settings.height = height;
    let job = Job {
        scene: Arc::clone(&scene),
        octree: Arc::clone(&octree),
        camera: scene.camera,
        settings,
        anti_aliasing,
        preview_divisor: 1,
    };
    (job, scene, octree)
}

#[test]
fn passes_run_one_then_sixteen_and_the_final_buffer_equals_the_cli_render() {
    let worker = Worker::spawn(2, || {});
    let (job, scene, octree) = job("scenes/glass.toml", 96, 72, true);
    let settings = job.settings;
    let generation = worker.submit(job);
    assert!(worker.wait_finished(generation, WAIT));
    let kinds: Vec<PassKind> = worker
        .history()
        .iter()
        .filter(|r| r.generation == generation)
        .map(|r| r.kind)
        .collect();
    assert_eq!(kinds, vec![PassKind::OneSample, PassKind::SixteenSamples]);
    // What `glint render --samples 16` computes for the same settings.
    let cli = Renderer::new(
        &scene,
        &octree,
        RenderSettings {
            samples: 16,
            ..settings
        },
    )
    .unwrap()
    .render(false, None)
    .0
    .to_rgb8();
    let shown: Vec<u8> = worker.with_buffer(|b| {
        b.rgba
            .chunks_exact(4)
            .flat_map(|p| [p[0], p[1], p[2]])
            .collect()
    });
    assert!(
        shown == cli,
        "the finished 16-sample buffer is byte-identical to the CLI render"
    );
}

#[test]
fn a_new_job_cancels_the_old_one_within_a_tile() {
    let threads = 2;
    let worker = Worker::spawn(threads, || {});
    // Big enough to take a while: 16 samples at 640x480 of the glass scene.
    let (slow, _, _) = job("scenes/glass.toml", 640, 480, true);
    let first = worker.submit(slow);
    // Wait until the first pass has produced some tiles.
    let start = std::time::Instant::now();
    while worker.with_buffer(|b| b.generation != first || b.tiles_done < 2) {
        assert!(start.elapsed() < WAIT);
        std::thread::sleep(Duration::from_millis(1));
    }
    let (quick, _, _) = job("scenes/sphere.toml", 32, 24, false);
    let started_at_cancel = worker.tiles_started(first);
    let second = worker.submit(quick);
    assert!(worker.wait_finished(second, WAIT));
    let total_first = worker.tiles_started(first);
    assert!(
        total_first <= started_at_cancel + threads as u64,
        "after cancellation at most one more tile per thread: {started_at_cancel} then {total_first}"
    );
    let tiles_in_full_job = 2 * glint::render::tiles(640, 480).len() as u64;
    assert!(
        total_first < tiles_in_full_job,
        "the first job did not run to completion"
    );
    assert!(
        worker
            .history()
            .iter()
            .all(|r| r.generation != first || r.kind == PassKind::OneSample)
    );
}
