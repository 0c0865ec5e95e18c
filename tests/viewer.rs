//! The viewer without a display: egui_kittest drives the UI headless, and
//! the render worker is checked directly.
#![cfg(feature = "gui")]

mod common;

use std::sync::Arc;
use std::time::Duration;

use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use glint::accel::Octree;
use glint::frame::rgba_to_rgb;
use glint::render::Renderer;
use glint::settings::AntiAliasing;
use glint::viewer::worker::{Job, PassKind, Worker};
use glint::viewer::{GlintApp, SceneSource, ViewerOptions};

const WAIT: Duration = Duration::from_secs(60);

/// The viewer on the scene file `path`, at the scene's own settings.
fn app_at(path: &std::path::Path) -> GlintApp {
    GlintApp::new(
        SceneSource::File(path.to_owned()),
        ViewerOptions::default(),
        || {},
    )
    .unwrap()
}

/// The viewer on a scene of the repository, rendering at `width` x `height`.
fn app_for(scene: &str, width: u32, height: u32) -> GlintApp {
    let mut app = app_at(&common::repo_path(scene));
    app.settings_mut().width = width;
    app.settings_mut().height = height;
    app
}

/// A small, quick scene for UI tests.
fn small_app() -> GlintApp {
    app_for("scenes/sphere.toml", 64, 48)
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
    assert_ne!(h.state().anti_aliasing(), aa);
    assert!(
        [aa, h.state().anti_aliasing()].contains(&AntiAliasing::Off),
        "the checkbox turns anti-aliasing on or off"
    );
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
    let shapes = Arc::clone(&h.state().scene().shapes);
    h.state_mut().scene_mut().lights[0].position.x += 1.0;
    h.run_steps(2);
    assert!(h.state().worker().generation() > generation);
    // The worker still holds the old scene: the edit copied the look, not
    // the geometry.
    assert!(
        Arc::ptr_eq(&shapes, &h.state().scene().shapes),
        "geometry copied"
    );
}

#[test]
fn export_writes_the_displayed_buffer() {
    let h = harness(small_app());
    let generation = h.state().worker().generation();
    assert!(
        h.state().worker().wait_finished(generation, WAIT),
        "the render finished"
    );
    let tmp = common::temp_dir();
    let path = tmp.path().join("export.png");
    h.state().export_to(&path).unwrap();
    let png = image::open(&path).unwrap().to_rgb8();
    let (w, hgt, rgba) = h
        .state()
        .worker()
        .with_buffer(|b| (b.width, b.height, b.rgba.clone()));
    assert_eq!((png.width(), png.height()), (w, hgt));
    let rgb = rgba_to_rgb(&rgba);
    assert!(
        png.into_raw() == rgb,
        "exported pixels equal the display buffer"
    );
}

fn job(
    scene: &str,
    width: u32,
    height: u32,
    anti_aliasing: AntiAliasing,
) -> (Job, Arc<glint::scene::Scene>, Arc<Octree>) {
    let scene = Arc::new(common::load(scene));
    let octree = Arc::new(Octree::build(&scene.shapes, scene.octree_params).unwrap());
    let mut settings = scene.render_settings();
    settings.width = width;
    settings.height = height;
    settings.set_anti_aliasing(anti_aliasing);
    let job = Job {
        scene: Arc::clone(&scene),
        octree: Arc::clone(&octree),
        camera: scene.camera,
        settings,
        preview: None,
        serial: 0,
    };
    (job, scene, octree)
}

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
            vec![PassKind::OneSample, PassKind::SixteenSamples],
        ),
        (
            "scenes/default.toml",
            AntiAliasing::Adaptive,
            None,
            vec![PassKind::OneSample, PassKind::SixteenSamples],
        ),
        (
            "scenes/spd/sizes/balls_s1.nff",
            AntiAliasing::Off,
            Some(spd),
            vec![PassKind::Corners],
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
            .into_iter()
            .filter(|r| r.generation == generation)
            .collect();
        let kinds: Vec<PassKind> = passes.iter().map(|r| r.kind).collect();
        assert_eq!(kinds, expected, "{scene_file}");
        let (frame, counts) = Renderer::new(&scene, &octree, settings)
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

/// While the user drags, previews asked for while one is in flight do not
/// cancel it: it completes and is shown, the newest one waits (replacing
/// the older waiting one) and runs next; a full job cancels both.
#[test]
fn previews_in_flight_complete_and_the_newest_waiting_one_follows() {
    use glint::viewer::worker::{Preview, Reflections};
    let worker = Worker::spawn(2, || {});
    let preview = Preview {
        divisor: 1,
        reflections: Reflections::All,
        shadows: true,
    };
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
            .all(|r| r.generation != first || r.kind == PassKind::OneSample)
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
            .into_iter()
            .filter(|r| r.generation == g)
            .collect();
        assert!(
            !records.is_empty() && records.iter().all(|r| r.from_cache),
            "{name}"
        );
    }
    let mut brute_force = off.clone();
    brute_force.settings.use_octree = false;
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

/// Runs frames until the current generation's final pass is on screen.
fn settle(h: &mut Harness<'static, GlintApp>) {
    let generation = h.state().worker().generation();
    assert!(h.state().worker().wait_finished(generation, WAIT));
    h.run_steps(3);
    assert!(h.state().final_pass_shown(), "final pass on screen");
}

#[test]
fn pin_as_a_then_octree_off_reads_zero_pixels_differ() {
    let mut app = small_app();
    app.settings_mut().use_octree = true;
    let mut h = harness(app);
    settle(&mut h);
    h.get_by_label("Pin as A").click();
    h.run_steps(2);
    assert!(h.state().compare().is_some(), "A is pinned");
    h.get_by_label("Octree").click();
    h.run_steps(2);
    assert!(!h.state().settings().use_octree);
    settle(&mut h);
    let stats = h.state().compare_stats().expect("A and B compared");
    let generation = h.state().worker().generation();
    assert!(
        h.state()
            .worker()
            .history()
            .iter()
            .any(|r| r.generation == generation && !r.octree),
        "B is a finished pass with the octree off"
    );
    assert_eq!(stats.differing, 0, "octree on vs off: {stats:?}");
    assert_eq!(stats.total, 64 * 48);
    h.get_by_label_contains("0 pixels differ of 3072");

    // 1 against 16 samples: exactly the pixels anti-aliasing changes.
    h.get_by_label("Pin as A").click();
    h.run_steps(2);
    let aa = h.state().anti_aliasing();
    h.get_by_label("Anti-aliasing (16 samples, 4x4 grid)")
        .click();
    h.run_steps(2);
    assert_ne!(h.state().anti_aliasing(), aa);
    assert!(
        [aa, h.state().anti_aliasing()].contains(&AntiAliasing::Off),
        "the checkbox turns anti-aliasing on or off"
    );
    settle(&mut h);
    let stats = h.state().compare_stats().unwrap();
    assert!(
        stats.differing > 0 && stats.differing < stats.total / 2,
        "AA changes edge pixels only: {stats:?}"
    );
}

/// The octree switch always renders, and while the new pass runs the
/// timing panel shows no figure of the image before: its rows read
/// "rendering…", nothing is "kept", the status is not "done".
#[test]
fn an_octree_toggle_renders_and_the_panel_waits_for_the_new_figures() {
    let mut app = app_for("scenes/default.toml", 160, 120);
    app.set_anti_aliasing(AntiAliasing::Off);
    let mut h = harness(app);
    settle(&mut h);
    let labels =
        |h: &Harness<'static, GlintApp>, text: &str| h.query_all_by_label_contains(text).count();
    for on in [false, true, false] {
        h.get_by_label("Octree").click();
        h.run_steps(2);
        assert_eq!(h.state().settings().use_octree, on);
        let generation = h.state().worker().generation();
        if !h.state().final_pass_shown() {
            // Mid-pass (the brute-force passes take seconds here).
            assert!(labels(&h, "rendering…") >= 1, "octree {on}: the rows wait");
            assert_eq!(labels(&h, "kept"), 0, "octree {on}: no kept figure");
            assert_eq!(labels(&h, "done:"), 0, "octree {on}: not done");
        }
        settle(&mut h);
        assert!(
            h.state().worker().tiles_started(generation) > 0,
            "octree {on}: the switch rendered"
        );
        h.run_steps(2);
        assert_eq!(labels(&h, "kept"), 0, "octree {on}: rendered, not kept");
        assert_eq!(labels(&h, "rendering…"), 0, "octree {on}: figures in");
    }
}

/// Dragging sends every frame's camera to the worker, yet cancels no
/// preview: each generation the drag uses is a preview that started (a
/// preview asked for while one renders waits instead of bumping it), and
/// once the drag holds still the image on screen is the preview of the
/// newest camera.
#[test]
fn a_drag_cancels_no_preview_and_ends_on_the_newest_camera() {
    let mut h = harness(app_for("scenes/glass.toml", 320, 240));
    settle(&mut h);
    let generation_before = h.state().worker().generation();
    let before = h.state().worker().preview_counts();
    let camera = *h.state().camera();
    let start = h.state().image_rect().unwrap().center();
    h.hover_at(start);
    h.run_steps(1);
    h.drag_at(start);
    h.run_steps(1);
    for k in 1..=20 {
        h.hover_at(start + egui::vec2(3.0 * k as f32, 0.0));
        h.run_steps(1);
    }
    assert_ne!(*h.state().camera(), camera, "the drag orbits");
    // The button is still down: wait until the last camera's preview is
    // on screen.
    let waited = std::time::Instant::now();
    while h.state().worker().with_buffer(|b| b.serial) != h.state().input_serial() {
        assert!(
            waited.elapsed() < WAIT,
            "the newest camera's preview never showed"
        );
        std::thread::sleep(Duration::from_millis(2));
        h.run_steps(1);
    }
    let counts = h.state().worker().preview_counts();
    let started = counts.started - before.started;
    assert!(started >= 2, "{counts:?}");
    assert_eq!(
        counts.completed - before.completed,
        started,
        "every preview started was completed"
    );
    assert_eq!(
        h.state().worker().generation() - generation_before,
        started,
        "no generation went to a preview that never started"
    );
    assert!(
        h.state()
            .worker()
            .with_buffer(|b| matches!(b.pass, Some(PassKind::Preview(_))) && b.finished)
    );
    h.drop_at(start + egui::vec2(60.0, 0.0));
    h.run_steps(1);
    settle(&mut h);
    assert!(h.state().final_pass_shown());
}

#[test]
fn dragging_the_divider_moves_it_and_not_the_camera() {
    let mut h = harness(small_app());
    settle(&mut h);
    h.state_mut().pin_as_a();
    h.run_steps(2);
    let rect = h.state().image_rect().unwrap();
    let camera = *h.state().camera();
    let start = egui::pos2(rect.center().x, rect.center().y);
    let dx = rect.width() * 0.25;
    h.hover_at(start);
    h.run_steps(1);
    h.drag_at(start);
    h.run_steps(1);
    for k in 1..=4 {
        h.hover_at(start + egui::vec2(dx * k as f32 / 4.0, 0.0));
        h.run_steps(1);
    }
    h.drop_at(start + egui::vec2(dx, 0.0));
    h.run_steps(2);
    let divider = h.state().compare().unwrap().divider;
    assert!(
        (divider - 0.75).abs() < 0.05,
        "divider moved from 0.5 to {divider}"
    );
    assert_eq!(*h.state().camera(), camera, "the camera did not orbit");
}

#[test]
fn clicking_in_inspect_mode_picks_the_pixel_and_its_ray_tree() {
    let mut h = harness(small_app());
    settle(&mut h);
    h.get_by_label("Inspect: click picks a pixel").click();
    h.run_steps(2);
    let rect = h.state().image_rect().unwrap();
    // The centre of pixel (40, 30) of the 64x48 image.
    let at = rect.min + egui::vec2(rect.width() * 40.5 / 64.0, rect.height() * 30.5 / 48.0);
    let camera = *h.state().camera();
    h.hover_at(at);
    h.run_steps(1);
    for pressed in [true, false] {
        h.event(egui::Event::PointerButton {
            pos: at,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: egui::Modifiers::NONE,
        });
        h.run_steps(1);
    }
    h.run_steps(1);
    let ins = h.state().inspection().expect("a pixel was picked");
    assert_eq!(ins.pixel, (40, 30));
    assert_eq!(ins.tree.depth, 1);
    assert!(
        ins.tree.hit.is_some(),
        "the pixel sees the sphere or the floor"
    );
    assert_eq!(
        *h.state().camera(),
        camera,
        "a click does not move the camera"
    );
    h.get_by_label_contains("pixel 40,30");
    // An edit traces the inspected pixel again: the tree follows the scene.
    let before = h.state().inspection().unwrap().tree.clone();
    for m in &mut h.state_mut().scene_mut().materials {
        m.color *= 0.5;
    }
    h.run_steps(2);
    let after = &h.state().inspection().expect("still inspected").tree;
    assert_eq!(h.state().inspection().unwrap().pixel, (40, 30));
    assert_ne!(*after, before, "the material's change shows in the tree");
}

#[test]
fn viewer_exports_render_again_identically_from_their_metadata() {
    use glint::settings::ViewMode;
    let tmp = common::temp_dir();
    let dir = tmp.path();
    let (first, again) = (dir.join("first.png"), dir.join("again.png"));
    let mut h = harness(small_app());
    settle(&mut h);
    let unedited = h.state().worker().with_buffer(|b| b.rgba.clone());
    // Edits made in the window travel with the export.
    h.state_mut().scene_mut().materials[0].color = glint::math::DVec3::new(0.9, 0.1, 0.6);
    h.state_mut().scene_mut().lights[0].position.y += 2.0;
    h.run_steps(2);
    settle(&mut h);
    assert_ne!(
        h.state().worker().with_buffer(|b| b.rgba.clone()),
        unedited,
        "the edit shows in the image"
    );
    // Shaded with edits, then a diagnostic view, aa-need (its 1- and
    // 16-sample passes' difference), and the octree overlay.
    type Setup = Box<dyn Fn(&mut GlintApp)>;
    let cases: [(&str, Setup); 4] = [
        ("shaded, edited", Box::new(|_| {})),
        ("cost", Box::new(|a| a.settings_mut().view = ViewMode::Cost)),
        (
            "aa-need",
            Box::new(|a| {
                a.settings_mut().view = ViewMode::AaNeed;
                a.set_anti_aliasing(AntiAliasing::Off);
            }),
        ),
        (
            "overlay",
            Box::new(|a| {
                a.settings_mut().view = ViewMode::Shaded;
                a.set_overlay_depth(Some(2));
            }),
        ),
    ];
    for (name, setup) in cases {
        setup(h.state_mut());
        h.run_steps(2);
        settle(&mut h);
        h.state().export_to(&first).unwrap();
        let record = glint::export::read_record(&first).unwrap();
        assert!(
            record.settings.edits.is_some(),
            "{name}: edits are recorded"
        );
        assert!(!record.settings.partial, "{name}: a finished pass");
        let (n, largest) = common::rerender_from_png(&first, &again);
        assert_eq!(n, 0, "{name}: {n} pixels differ (largest {largest})");
    }
}

#[test]
fn protocol_spd_in_the_viewer_is_one_corner_pass() {
    let mut app = app_for("scenes/spd/sizes/balls_s1.nff", 48, 40);
    app.set_anti_aliasing(AntiAliasing::Full);
    let mut h = harness(app);
    // NFF scenes shade display values by default; the panel says so.
    assert_eq!(
        h.state().settings().colors,
        glint::color::ColorConvention::Display
    );
    let before = h.state().worker().generation();
    h.get_by_label("spd").click();
    h.run_steps(2);
    let settings = *h.state().settings();
    assert_eq!(settings.protocol, glint::settings::Protocol::Spd);
    assert_eq!(settings.max_depth, 5, "the protocol's depth");
    assert_eq!(settings.sides, glint::settings::Sides::One);
    assert!(h.state().worker().generation() > before, "restarted");
    settle(&mut h);
    let generation = h.state().worker().generation();
    let kinds: Vec<PassKind> = h
        .state()
        .worker()
        .history()
        .iter()
        .filter(|r| r.generation == generation)
        .map(|r| r.kind)
        .collect();
    assert_eq!(
        kinds,
        vec![PassKind::Corners],
        "no 16-sample pass under the protocol"
    );
    let record = h.state().worker().history().last().copied().unwrap();
    assert_eq!(record.rays.primary, 49 * 41, "every corner once");
    // Back to glint's rules: the scene's own depth and sides return.
    h.get_by_label("glint").click();
    h.run_steps(2);
    let scene = common::load("scenes/spd/sizes/balls_s1.nff").render_settings();
    assert_eq!(h.state().settings().max_depth, scene.max_depth);
    assert_eq!(h.state().settings().sides, scene.sides);
}

#[test]
fn a_budget_preview_drops_what_it_says() {
    let worker = Worker::spawn(2, || {});
    let (mut job, _, _) = job("scenes/glass.toml", 96, 72, AntiAliasing::Full);
    let preview = glint::viewer::worker::Preview {
        divisor: 2,
        reflections: glint::viewer::worker::Reflections::Off,
        shadows: false,
    };
    job.preview = Some(preview);
    let generation = worker.submit(job);
    assert!(worker.wait_finished(generation, WAIT));
    let passes: Vec<_> = worker
        .history()
        .into_iter()
        .filter(|r| r.generation == generation)
        .collect();
    assert_eq!(passes.len(), 1, "one quick pass only");
    let r = passes[0];
    assert_eq!(r.kind, PassKind::Preview(preview));
    assert_eq!((r.width, r.height), (48, 36));
    assert_eq!(r.rays.primary, 48 * 36);
    assert_eq!(
        (r.rays.shadow, r.rays.reflection, r.rays.refraction),
        (0, 0, 0)
    );

    // One bounce: the picture of a 1-sample render at depth 2 (glass keeps
    // its refraction, a black sphere it is not).
    let one = glint::viewer::worker::Preview {
        reflections: glint::viewer::worker::Reflections::OneBounce,
        shadows: true,
        ..preview
    };
    let (mut deep, scene, octree) = crate::job("scenes/glass.toml", 96, 72, AntiAliasing::Full);
    deep.preview = Some(one);
    let generation = worker.submit(deep);
    assert!(worker.wait_finished(generation, WAIT));
    let mut settings = scene.render_settings();
    (settings.width, settings.height, settings.max_depth) = (48, 36, 2);
    settings.set_anti_aliasing(AntiAliasing::Off);
    let (frame, counts) = Renderer::new(&scene, &octree, settings)
        .unwrap()
        .render(false, None);
    assert!(counts.rays.refraction > 0, "the scene has glass");
    let r = worker
        .history()
        .into_iter()
        .rfind(|r| r.generation == generation)
        .unwrap();
    assert_eq!(r.kind, PassKind::Preview(one));
    assert_eq!(r.rays, counts.rays);
    let shown: Vec<u8> = worker.with_buffer(|b| rgba_to_rgb(&b.rgba));
    assert!(
        shown == frame.to_rgb8(),
        "the preview is the depth-2 render"
    );
}

#[test]
fn a_deep_ray_tree_leaves_the_panels_and_the_image_apart() {
    // The glass pixel's tree nests four levels of headers, which do not
    // wrap; once they widened the timing panel and the image slid under it.
    let mut h = harness(app_for("scenes/glass.toml", 480, 360));
    let before = h.state().image_rect().unwrap();
    h.state_mut().inspect_pixel(250, 200);
    h.run_steps(4);
    assert_eq!(h.state().inspection().unwrap().tree.depth, 1);
    let after = h.state().image_rect().unwrap();
    assert_eq!(after, before, "the image keeps its place");
    // The fixed-width panels: 330 points each side of a 1200-point window.
    assert!(after.max.x <= 1200.0 - 330.0, "{after:?}");
    assert!(after.min.x >= 330.0, "{after:?}");
}

/// A number typed into a field is taken on Enter, not key by key: typing
/// 200 into the width does not first render widths 2 and 20.
#[test]
fn a_typed_number_is_taken_on_enter() {
    let mut h = harness(app_for("scenes/sphere.toml", 77, 48));
    let generation = h.state().worker().generation();
    h.get_by_value("77").focus();
    h.run_steps(1);
    // Focused, the field is a text edit with the whole number selected.
    for key in ["2", "0", "0"] {
        h.get_by(|n| n.is_focused()).type_text(key);
        h.run_steps(1);
    }
    h.run_steps(2);
    assert_eq!(h.state().settings().width, 77, "taken while typing");
    assert_eq!(
        h.state().worker().generation(),
        generation,
        "restarted while typing"
    );
    h.key_press(egui::Key::Enter);
    h.run_steps(2);
    assert_eq!(h.state().settings().width, 200);
    assert!(h.state().worker().generation() > generation);
}

/// A scene file in a fresh folder, its size small enough for UI tests.
fn scene_in_temp_folder() -> (tempfile::TempDir, std::path::PathBuf) {
    let dir = tempfile::tempdir().unwrap();
    let text = std::fs::read_to_string(common::repo_path("scenes/sphere.toml"))
        .unwrap()
        .replace("width = 400\nheight = 300", "width = 64\nheight = 48");
    let path = dir.path().join("sphere.toml");
    std::fs::write(&path, text).unwrap();
    (dir, path)
}

fn press(h: &mut Harness<'static, GlintApp>, modifiers: egui::Modifiers, key: egui::Key) {
    h.key_press_modifiers(modifiers, key);
    h.run_steps(2);
}

/// Edits can be undone and redone, are marked in the title until saved,
/// and Save writes them into the scene file, comments kept; a reload over
/// unsaved edits asks first.
#[test]
fn edits_undo_redo_save_and_a_reload_that_asks() {
    use egui::{Key, Modifiers};
    let (_dir, path) = scene_in_temp_folder();
    let app = app_at(&path);
    let mut h = harness(app);
    assert!(!h.state().unsaved());
    assert!(!h.state().title().starts_with('●'), "{}", h.state().title());
    let original = h.state().scene().lights.clone();
    let edited = glint::math::DVec3::new(0.25, 0.5, 0.75);
    h.state_mut().scene_mut().lights[0].color = edited;
    h.state_mut().settings_mut().max_depth = 7;
    h.run_steps(2);
    assert!(h.state().unsaved());
    assert!(h.state().title().starts_with('●'), "{}", h.state().title());

    press(&mut h, Modifiers::COMMAND, Key::Z);
    assert_eq!(
        h.state().scene().lights,
        original,
        "undo restores the light"
    );
    assert_eq!(
        h.state().settings().max_depth,
        3,
        "and the depth, changed in the same moment"
    );
    assert!(!h.state().unsaved());
    press(&mut h, Modifiers::COMMAND | Modifiers::SHIFT, Key::Z);
    assert_eq!(
        h.state().scene().lights[0].color,
        edited,
        "redo puts it back"
    );
    assert_eq!(h.state().settings().max_depth, 7);

    press(&mut h, Modifiers::COMMAND, Key::S);
    assert!(!h.state().unsaved(), "{:?}", h.state().messages().last());
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        text.starts_with("# One sphere on a plane"),
        "comments kept:\n{text}"
    );
    let saved = glint::scene::load(&path).unwrap();
    assert_eq!(saved.lights[0].color, edited);
    assert_eq!(saved.image.max_depth, 7);
    assert!(
        h.state()
            .messages()
            .last()
            .unwrap()
            .text
            .starts_with("saved ")
    );

    // Unsaved again: F5 asks, Cancel keeps the edit, Discard reloads the file.
    h.state_mut().scene_mut().lights[0].color = original[0].color;
    h.run_steps(2);
    press(&mut h, Modifiers::NONE, Key::F5);
    h.get_by_label("Unsaved edits");
    h.get_by_label("Cancel").click();
    h.run_steps(2);
    assert_eq!(h.state().scene().lights, original, "cancel keeps the edit");
    press(&mut h, Modifiers::NONE, Key::F5);
    h.get_by_label("Discard").click();
    h.run_steps(2);
    assert_eq!(
        h.state().scene().lights[0].color,
        edited,
        "the saved file was reloaded"
    );
    assert!(!h.state().unsaved());
}

/// An NFF scene is saved in place as NFF: its comments kept, the edits
/// in; what NFF cannot say (a reflectivity apart from Ks) is named and
/// stays marked unsaved.
#[test]
fn an_nff_scene_is_saved_as_nff_and_what_it_cannot_hold_stays_unsaved() {
    use egui::{Key, Modifiers};
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("balls.nff");
    let text = "# two balls\nv\nfrom 0 -4 1\nat 0 0 0\nup 0 0 1\nangle 40\nhither 0.01\n\
                resolution 64 48\nb 0.1 0.2 0.3\nl 4 -3 5\n\
                f 1 0.5 0.2 0.7 0.3 20 0 1\ns 0 0 0 1\ns 1 0 0 0.5\n";
    std::fs::write(&path, text).unwrap();
    let mut h = harness(app_at(&path));
    settle(&mut h);
    h.state_mut().camera_mut().fov = 35.0;
    h.state_mut().scene_mut().lights[0].color = glint::math::DVec3::new(0.9, 0.8, 0.7);
    h.state_mut().scene_mut().materials[0].color = glint::math::DVec3::new(0.2, 0.4, 0.6);
    h.run_steps(2);
    assert!(h.state().unsaved());
    press(&mut h, Modifiers::COMMAND, Key::S);
    assert!(!h.state().unsaved(), "{:?}", h.state().messages().last());
    let written = std::fs::read_to_string(&path).unwrap();
    assert!(written.starts_with("# two balls\n"), "{written}");
    assert!(written.contains("l 4 -3 5 0.9 0.8 0.7\n"), "{written}");
    let saved = glint::scene::load(&path).unwrap();
    assert!((saved.camera.fov - 35.0).abs() < 1e-12);
    assert_eq!(saved.materials, h.state().scene().materials);

    h.state_mut().scene_mut().materials[0].reflectivity = 0.05;
    h.run_steps(2);
    press(&mut h, Modifiers::COMMAND, Key::S);
    let message = &h.state().messages().last().unwrap().text;
    assert!(message.contains("the reflectivity of f1"), "{message}");
    assert!(h.state().unsaved(), "the reflectivity is not in the file");

    // Settings NFF has no place for stay marked too.
    h.state_mut().scene_mut().materials[0].reflectivity = h.state().scene().materials[0].ks;
    h.state_mut().settings_mut().samples = 16;
    h.run_steps(2);
    press(&mut h, Modifiers::COMMAND, Key::S);
    let message = &h.state().messages().last().unwrap().text;
    assert!(message.contains("samples"), "{message}");
    assert!(h.state().unsaved(), "the samples are not in the file");
}

/// An OBJ opened on its own, its MTL material edited: "Save as" writes
/// a TOML scene that holds the edit (in the mesh object's `materials`).
#[test]
fn edits_to_an_objs_mtl_materials_are_saved() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness(app_for("assets/cornell_box/cornell_box.obj", 48, 48));
    settle(&mut h);
    let i = h
        .state()
        .scene()
        .materials
        .iter()
        .position(|m| m.name == "red")
        .expect("the Cornell box's red wall");
    h.state_mut().scene_mut().materials[i].color = glint::math::DVec3::new(0.1, 0.2, 0.9);
    h.run_steps(2);
    let path = dir.path().join("box.toml");
    h.state_mut().save_to(&path);
    assert!(!h.state().unsaved(), "{:?}", h.state().messages().last());
    let saved = glint::scene::load(&path).unwrap();
    assert_eq!(saved.materials, h.state().scene().materials);
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains("[objects.materials.red]"), "{text}");
}

/// The built-in scene has no file: Save writes a new TOML scene (with the
/// bunny beside it) that loads to the same scene.
#[test]
fn the_built_in_scene_is_saved_as_a_new_file_with_its_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let app = GlintApp::new(SceneSource::BuiltIn, ViewerOptions::default(), || {}).unwrap();
    let mut h = harness(app);
    let mut camera = *h.state().camera();
    camera.fov = 33.0;
    *h.state_mut().camera_mut() = camera;
    h.run_steps(1);
    let path = dir.path().join("copy.toml");
    h.state_mut().save_to(&path);
    assert!(!h.state().unsaved(), "{:?}", h.state().messages().last());
    let copy = glint::scene::load(&path).unwrap();
    let builtin = glint::scene::builtin::default_scene().unwrap();
    assert_eq!(copy.camera, camera);
    assert_eq!(copy.shapes, builtin.shapes);
    assert_eq!(copy.materials, builtin.materials);
    assert!(dir.path().join("bunny.obj").is_file());
}

/// A scene opened by a relative name is recorded in exports by its
/// absolute path, so `--from-png` works from any folder.
#[test]
fn exports_record_the_scene_by_its_absolute_path() {
    let relative = std::path::PathBuf::from("scenes/sphere.toml");
    assert!(relative.is_file(), "tests run from the repository root");
    let app = app_at(&relative);
    let mut h = harness(app);
    h.state_mut().settings_mut().width = 32;
    h.state_mut().settings_mut().height = 24;
    h.run_steps(2);
    settle(&mut h);
    let tmp = common::temp_dir();
    let png = tmp.path().join("x.png");
    h.state().export_to(&png).unwrap();
    let record = glint::export::read_record(&png).unwrap();
    assert_eq!(
        std::path::PathBuf::from(&record.scene_path),
        std::fs::canonicalize(&relative).unwrap()
    );
}

/// The image is scaled by a whole number of screen pixels per image pixel
/// (even, crisp blocks), or to fit at any scale, or 1:1.
#[test]
fn the_image_is_magnified_by_whole_pixels_to_fit_or_one_to_one() {
    use glint::viewer::state::Magnification;
    let mut h = harness(small_app());
    let ppp = h.ctx.pixels_per_point();
    let whole = h.state().image_rect().unwrap();
    let block = whole.width() * ppp / 64.0;
    assert!(block >= 2.0 && block == block.round(), "{block}");
    assert_eq!(whole.height() * ppp / 48.0, block);
    assert_eq!(
        whole.min.x * ppp,
        (whole.min.x * ppp).round(),
        "on the pixel grid"
    );

    h.state_mut().set_magnification(Magnification::Fit);
    h.run_steps(2);
    let fit = h.state().image_rect().unwrap();
    assert!(fit.width() >= whole.width() && fit.width() < whole.width() * (block + 1.0) / block);

    h.state_mut().set_magnification(Magnification::Actual);
    h.run_steps(2);
    let actual = h.state().image_rect().unwrap();
    assert_eq!((actual.width() * ppp, actual.height() * ppp), (64.0, 48.0));
}

/// Stop ends a long pass (here brute force on 91,850 triangles) within a
/// tile per thread and keeps the image as far as it got; the next job
/// renders as usual.
#[test]
fn a_long_pass_can_be_stopped_and_the_next_change_renders_again() {
    let worker = Worker::spawn(2, || {});
    let (mut slow, _, _) = job("scenes/bunnies.toml", 96, 72, AntiAliasing::Full);
    slow.settings.use_octree = false;
    let generation = worker.submit(slow);
    let start = std::time::Instant::now();
    while worker.with_buffer(|b| b.tiles_done) < 1 {
        assert!(start.elapsed() < WAIT, "no tile finished");
        std::thread::sleep(Duration::from_millis(5));
    }
    worker.stop();
    let (stopped, finished) = worker.with_buffer(|b| (b.stopped, b.finished));
    assert!(stopped && !finished);
    // The tiles in flight finish; no new one starts.
    std::thread::sleep(Duration::from_millis(1500));
    let started = worker.tiles_started(generation);
    std::thread::sleep(Duration::from_millis(500));
    assert_eq!(
        worker.tiles_started(generation),
        started,
        "tiles went on after stop"
    );
    assert!(worker.with_buffer(|b| b.stopped && !b.finished && b.generation == generation));

    let (quick, _, _) = job("scenes/sphere.toml", 32, 24, AntiAliasing::Off);
    let next = worker.submit(quick);
    assert!(worker.wait_finished(next, WAIT));
    assert!(!worker.with_buffer(|b| b.stopped));
}

/// An export records the name and text of the scene it rendered, which
/// belong together: after "Save as" (which renders nothing) the image on
/// screen is still the old file's, until the next change renders the new.
#[test]
fn an_export_after_save_as_records_the_file_its_image_was_rendered_from() {
    let (dir, path) = scene_in_temp_folder();
    let app = app_at(&path);
    let mut h = harness(app);
    settle(&mut h);
    let other = dir.path().join("elsewhere");
    std::fs::create_dir(&other).unwrap();
    let copy = other.join("copy.toml");
    h.state_mut().camera_mut().fov = 30.0;
    h.run_steps(2);
    settle(&mut h);
    h.state_mut().save_to(&copy);
    assert!(!h.state().unsaved());
    let png = dir.path().join("x.png");
    let recorded = |h: &Harness<'static, GlintApp>| {
        h.state().export_to(&png).unwrap();
        let r = glint::export::read_record(&png).unwrap();
        (std::path::PathBuf::from(r.scene_path), r.scene_text)
    };
    let (name, text) = recorded(&h);
    assert_eq!(name, std::fs::canonicalize(&path).unwrap());
    assert_eq!(text, std::fs::read_to_string(&path).unwrap());
    h.state_mut().camera_mut().fov = 31.0;
    h.run_steps(2);
    settle(&mut h);
    let (name, text) = recorded(&h);
    assert_eq!(name, std::fs::canonicalize(&copy).unwrap());
    assert_eq!(text, std::fs::read_to_string(&copy).unwrap());
}

#[test]
fn octree_parameters_rebuild_the_tree_and_its_prediction_without_rendering() {
    let mut h = harness(app_for("scenes/spd/teapot.nff", 96, 96));
    settle(&mut h);
    h.run_steps(2);
    assert!(
        h.state().unit_costs().is_some(),
        "measured once the scene rendered"
    );
    let generation = h.state().worker().generation();
    let coarse = h.state().octree().stats();
    let coarse_cost = h.state().octree().predicted_cost();
    let mut params = h.state().scene().octree_params;
    params.leaf_size = 1;
    params.max_depth = 8;
    h.state_mut().set_octree_params(params);
    h.run_steps(3);
    assert_eq!(h.state().scene().octree_params, params);
    assert_ne!(h.state().octree().stats().nodes, coarse.nodes, "rebuilt");
    assert_ne!(h.state().octree().predicted_cost(), coarse_cost);
    assert_eq!(
        h.state().worker().generation(),
        generation,
        "nothing rendered"
    );
    // The panel shows the prediction for the last pass's rays.
    h.get_by_label("Octree parameters").click();
    h.run_steps(2);
    let shown = h
        .get_all_by(|n| {
            n.label()
                .or(n.value())
                .is_some_and(|t| t.starts_with("Predicted 1-sample pass"))
        })
        .count();
    assert!(shown > 0, "the predicted render time is shown");
}

#[test]
fn a_rays_walk_steps_through_the_octree_in_the_panel() {
    let mut h = harness(app_for("scenes/spd/teapot.nff", 96, 96));
    settle(&mut h);
    h.state_mut().inspect_pixel(48, 46);
    h.run_steps(3);
    let tree = &h.state().inspection().unwrap().tree;
    let steps = tree.query.as_ref().unwrap().walk.as_ref().unwrap().len();
    assert!(steps > 2, "{steps} steps");
    // The eye ray's "walk" button is the first.
    h.get_all_by_label("walk").next().unwrap().click();
    h.run_steps(2);
    assert_eq!(h.state().walk().0.map(|t| t.path.len()), Some(0));
    assert_eq!(h.state().walk().1, 0);
    h.get_by_label(">").click();
    h.run_steps(1);
    h.get_by_label(">").click();
    h.run_steps(1);
    assert_eq!(h.state().walk().1, 2, "two steps taken");
    h.get_by_label("|<").click();
    h.run_steps(1);
    assert_eq!(h.state().walk().1, 0);
}
