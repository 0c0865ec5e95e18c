//! Helpers of the viewer's tests (cargo feature `gui`): the app on a
//! scene, a headless harness, render jobs, and waiting for a final pass.

use std::sync::Arc;
use std::time::Duration;

use egui_kittest::Harness;
use glint::accel::Octree;
use glint::settings::AntiAliasing;
use glint::viewer::worker::Job;
use glint::viewer::{GlintApp, SceneSource, ViewerOptions};

pub const WAIT: Duration = Duration::from_secs(60);

/// The viewer on the scene file `path`, at the scene's own settings.
pub fn app_at(path: &std::path::Path) -> GlintApp {
    GlintApp::new(
        SceneSource::File(path.to_owned()),
        ViewerOptions::default(),
        || {},
    )
    .unwrap()
}

/// The viewer on a scene of the repository, rendering at `width` x `height`.
pub fn app_for(scene: &str, width: u32, height: u32) -> GlintApp {
    let mut app = app_at(&super::repo_path(scene));
    app.settings_mut().width = width;
    app.settings_mut().height = height;
    app
}

/// A small, quick scene for UI tests.
pub fn small_app() -> GlintApp {
    app_for("scenes/sphere.toml", 64, 48)
}

pub fn harness(app: GlintApp) -> Harness<'static, GlintApp> {
    let mut h = Harness::builder()
        .with_size(egui::vec2(1200.0, 800.0))
        // egui 0.37's DragValue does not expose the names glint gives it
        // (`accessible_name`) to kittest's check; the panels label every one.
        .with_accessibility_check(false)
        .build_ui_state(|ui, app: &mut GlintApp| app.frame_ui(ui), app);
    h.run_steps(2);
    h
}

pub fn job(
    scene: &str,
    width: u32,
    height: u32,
    anti_aliasing: AntiAliasing,
) -> (Job, Arc<glint::scene::Scene>, Arc<Octree>) {
    let scene = Arc::new(super::load(scene));
    let octree = Arc::new(scene.build_octree().unwrap());
    let mut settings = scene.render_settings();
    settings.width = width;
    settings.height = height;
    settings.set_anti_aliasing(anti_aliasing);
    let job = Job {
        scene: Arc::clone(&scene),
        octree: Arc::clone(&octree),
        bvh: None,
        camera: scene.camera,
        settings,
        preview: None,
        frame_budget_ms: 33.0,
        show_sources: false,
        serial: 0,
    };
    (job, scene, octree)
}

/// Runs frames until the current generation's final pass is on screen.
pub fn settle(h: &mut Harness<'static, GlintApp>) {
    let generation = h.state().worker().generation();
    assert!(h.state().worker().wait_finished(generation, WAIT));
    h.run_steps(3);
    assert!(h.state().final_pass_shown(), "final pass on screen");
}

/// A scene file in a fresh folder, its size small enough for UI tests.
pub fn scene_in_temp_folder() -> (tempfile::TempDir, std::path::PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(super::repo_path("scenes/sphere.toml"))
        .unwrap()
        .replace("width = 400\nheight = 300", "width = 64\nheight = 48");
    let path = dir.path().join("sphere.toml");
    std::fs::write(&path, text).unwrap();
    (dir, path)
}

/// Presses a key with modifiers and lets the frame after it run.
pub fn press(h: &mut Harness<'static, GlintApp>, modifiers: egui::Modifiers, key: egui::Key) {
    h.key_press_modifiers(modifiers, key);
    h.run_steps(2);
}
