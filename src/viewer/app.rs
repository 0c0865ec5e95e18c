//! The viewer's application: what the user edits ([`EditState`]), the
//! runtime that renders it and shows it, and one frame of the UI. Panels
//! and input return [`Command`]s; this file applies them.

use std::io::Write as _;
use std::path::{Path, PathBuf};
use std::sync::Arc;

use egui::{Color32, Sense, TextureHandle, TextureOptions};

mod camera_path;
mod octree_tuning;
mod options;
mod scene_files;

use octree_tuning::build_octree;
pub use options::ViewerOptions;

use super::command::Command;
use super::compare::{Compare, CompareMode, DiffStats};
use super::inspect::InspectState;
use super::octree_panel::{OctreeInfo, RaySampleJob, SuggestionJob, last_full_pass};
use super::orbit_bench::{CapturedPreview, OrbitBench, ShownFrame};
use super::panels::{Message, RenderInfo};
use super::pixel::Inspection;
use super::pixel::WalkTarget;
use super::screenshot::Screenshot;
pub use super::state::{CompareSetting, SceneSource};
use super::state::{EditState, Magnification, Snapshot};
use super::worker::{Job, Preview, Worker};
use super::{budget, export, input, panels, path_panel, timing};
use crate::accel::{Octree, OctreeParams};
use crate::camera::CameraSpec;
use crate::render::UnitCosts;
use crate::scene::Scene;
use crate::settings::{AntiAliasing, RenderSettings};

/// Pixels stay sharp blocks when magnified; a large image shrunk to fit
/// is filtered rather than losing whole rows.
const TEXTURE: TextureOptions = TextureOptions {
    magnification: egui::TextureFilter::Nearest,
    minification: egui::TextureFilter::Linear,
    ..TextureOptions::NEAREST
};

/// Everything that decides the rendered image; a change restarts the passes.
#[derive(Clone, Debug, PartialEq)]
struct RenderInputs {
    camera: CameraSpec,
    settings: RenderSettings,
    scene_version: u64,
    /// The octree's parameters: a new tree renders again (for its times).
    octree: OctreeParams,
    preview: Option<Preview>,
    show_sources: bool,
}

/// What waits for the user to confirm that unsaved edits may go.
#[derive(Clone, Debug, PartialEq)]
enum Discarding {
    Reload,
    Open(PathBuf),
    Quit,
}

pub struct GlintApp {
    /// What the user edits.
    edit: EditState,
    /// Undo and redo over every edit (camera, settings, lights, materials);
    /// changes within a second of each other are one step.
    undoer: egui::util::undoer::Undoer<Snapshot>,
    /// The edits as last loaded or saved: the title marks any difference.
    saved: Snapshot,
    /// An action that would drop unsaved edits, waiting for the user's word.
    discarding: Option<Discarding>,
    /// The path typed where no file dialog is available (Ctrl+O).
    path_prompt: Option<scene_files::PathPrompt>,
    /// The window title last sent.
    title: String,
    /// How the image is scaled into its panel.
    magnification: Magnification,
    // The runtime: the octree of the scene, the render worker and what
    // is on screen.
    octree: Arc<Octree>,
    build_seconds: f64,
    /// The BVH, built the first time the accelerator choice asks for it
    /// (and again for other geometry).
    bvh: Option<octree_tuning::BuiltBvh>,
    /// What a traversal step, an intersection test and the rest of a ray
    /// cost here, measured on the scene when it was installed: they turn
    /// the octree's predicted work into a predicted time.
    unit_costs: Option<UnitCosts>,
    /// A suggested octree setting, being worked out or found.
    suggestion: Option<SuggestionJob>,
    /// A tree's work per ray on a thumbnail of the view (the octree
    /// panel's prediction from rays), for the tree it was measured on.
    ray_sample: Option<RaySampleJob>,
    worker: Worker,
    texture: Option<TextureHandle>,
    shown_version: u64,
    submitted: Option<RenderInputs>,
    dragging: bool,
    /// A panel's value (a light, a material, the camera) is being dragged:
    /// its changes are previewed like the camera's drag.
    widget_dragged: bool,
    /// What the budget chose for the last drag, and its estimated seconds.
    last_preview: Option<(Preview, f64)>,
    asked_focus: bool,
    messages: Vec<Message>,
    inspect: InspectState,
    /// `--compare` waiting for A's final pass to pin it.
    compare_pending: Option<CompareSetting>,
    compare_difference: bool,
    screenshot: Option<Screenshot>,
    /// Where the image was drawn in the last frame (screen points).
    image_rect: Option<egui::Rect>,
    /// Pointer events so far: each job carries the count it reflects.
    input_serial: u64,
    orbit_bench: Option<OrbitBench>,
    /// Recording or playing the camera path.
    path_player: path_panel::PathPlayer,
}

impl GlintApp {
    /// Loads `source` and starts rendering; `repaint` wakes the UI thread.
    pub fn new(
        source: SceneSource,
        options: ViewerOptions,
        repaint: impl Fn() + Send + Sync + 'static,
    ) -> anyhow::Result<Self> {
        let mut scene = source.load()?;
        let worker = Worker::spawn(options.threads, repaint);
        let mut settings = scene.render_settings();
        options
            .overrides
            .apply(&mut settings, &mut scene.octree_params);
        let (octree, build_seconds) = build_octree(&scene)?;
        let mut edit = EditState {
            camera: scene.camera,
            camera_path: scene.camera_path.clone(),
            source,
            loaded: Arc::new(scene.clone()),
            scene: Arc::new(scene),
            scene_version: 0,
            settings,
            frame_budget_ms: 33.0,
            show_sources: options.show_sources,
        };
        // Before `--compare` flips a setting for its A image: B, which
        // follows, is the state as loaded.
        let saved = edit.snapshot();
        if let Some(setting) = options.compare {
            edit.flip(setting);
        }
        let mut app = Self {
            edit,
            undoer: Default::default(),
            saved,
            discarding: None,
            path_prompt: None,
            title: String::new(),
            magnification: Magnification::default(),
            octree: Arc::new(octree),
            build_seconds,
            bvh: None,
            unit_costs: None,
            suggestion: None,
            ray_sample: None,
            worker,
            texture: None,
            shown_version: 0,
            submitted: None,
            dragging: false,
            widget_dragged: false,
            last_preview: None,
            asked_focus: false,
            messages: Vec::new(),
            inspect: InspectState::new(options.overlay_depth),
            compare_pending: options.compare,
            compare_difference: options.compare_difference,
            screenshot: options.screenshot.map(|path| {
                Screenshot::new(path, options.frames, options.screenshot_outcome.clone())
            }),
            image_rect: None,
            input_serial: 0,
            orbit_bench: options.orbit_bench.map(OrbitBench::new),
            path_player: Default::default(),
        };
        if let Some((i, j)) = options.inspect {
            app.inspect_pixel(i, j);
        }
        if let Some((target, step)) = options.walk {
            // A ray the pixel does not have would show nothing: refuse it
            // with the rays there are.
            if let Some(inspection) = &app.inspect.inspection
                && super::walk_view::walked_ray(inspection, &target).is_none()
            {
                let (i, j) = inspection.pixel;
                anyhow::bail!(
                    "--walk {}: pixel {i},{j} has no such ray; its rays: {}",
                    target.name(),
                    super::walk_view::ray_names(inspection).join(", ")
                );
            }
            // A step past the walk's end would show its end: say so.
            let steps = app.inspect.inspection.as_ref().and_then(|inspection| {
                let ray = super::walk_view::walked_ray(inspection, &target)?;
                ray.query.and_then(|q| q.walk.as_ref()).map(Vec::len)
            });
            if let (Some(step), Some(steps)) = (step, steps)
                && step > steps
            {
                anyhow::bail!(
                    "--walk-step {step}: the walk of {} has {steps} steps",
                    target.name()
                );
            }
            app.inspect.walk.target = Some(target);
            app.inspect.walk.shown = step.unwrap_or(usize::MAX);
        }
        Ok(app)
    }

    pub fn settings(&self) -> &RenderSettings {
        &self.edit.settings
    }

    /// Render settings as the panels edit them; a change restarts the passes.
    pub fn settings_mut(&mut self) -> &mut RenderSettings {
        &mut self.edit.settings
    }

    pub fn anti_aliasing(&self) -> AntiAliasing {
        self.edit.settings.anti_aliasing()
    }

    /// Sets the anti-aliasing; a change restarts the passes.
    pub fn set_anti_aliasing(&mut self, aa: AntiAliasing) {
        self.edit.settings.set_anti_aliasing(aa);
    }

    /// Shows the octree overlay down to `depth`, or hides it (`None`);
    /// display-only, nothing is re-rendered.
    pub fn set_overlay_depth(&mut self, depth: Option<u32>) {
        self.inspect.overlay_depth = depth;
    }

    pub fn worker(&self) -> &Worker {
        &self.worker
    }

    pub fn scene(&self) -> &Scene {
        &self.edit.scene
    }

    /// Mutable access to lights and materials; marks the image stale.
    pub fn scene_mut(&mut self) -> &mut Scene {
        self.edit.scene_mut()
    }

    pub fn set_magnification(&mut self, m: Magnification) {
        self.magnification = m;
    }

    pub fn camera_mut(&mut self) -> &mut CameraSpec {
        &mut self.edit.camera
    }

    pub fn camera(&self) -> &CameraSpec {
        &self.edit.camera
    }

    /// Where the image was drawn in the last frame (screen points).
    pub fn image_rect(&self) -> Option<egui::Rect> {
        self.image_rect
    }

    pub fn inspection(&self) -> Option<&Inspection> {
        self.inspect.inspection.as_ref()
    }

    pub fn compare(&self) -> Option<&Compare> {
        self.inspect.compare.as_ref()
    }

    /// A versus B, when B is complete: the pixels that differ.
    pub fn compare_stats(&self) -> Option<DiffStats> {
        self.inspect.compare_stats(&self.worker)
    }

    pub fn messages(&self) -> &[Message] {
        &self.messages
    }

    /// Picks pixel `(i, j)` and shows the tree of rays its centre ray spawns.
    pub fn inspect_pixel(&mut self, i: u32, j: u32) {
        // The pixel's walks are counted: no light buffer.
        let reuse = crate::render::Reuse {
            bvh: self.bvh_if_chosen(),
            ..crate::render::Reuse::octree_alone(&self.octree)
        };
        if let Err(e) = self.inspect.inspect_pixel(&self.edit, reuse, (i, j)) {
            self.say(format!("cannot inspect: {e}"), true);
        }
    }

    /// Keeps the frame on screen as "A" of an A/B comparison.
    pub fn pin_as_a(&mut self) {
        self.inspect
            .pin_as_a(&self.worker, self.edit.settings_label());
    }

    /// Saves the frame on screen with the record of how it was made (see
    /// [`crate::export`]): the scene, camera and settings of the pass on
    /// screen, not the panels' current values; a pass still sweeping in is
    /// written as displayed and recorded as partial.
    pub fn export_to(&self, path: &Path) -> anyhow::Result<()> {
        export::export_to(path, &self.worker, &self.octree, self.inspect.overlay_depth)
    }

    /// Is the final pass of the current job on screen?
    pub fn final_pass_shown(&self) -> bool {
        let generation = self.worker.generation();
        let shown = self.shown_version;
        self.worker
            .try_with_buffer(|b| b.generation == generation && b.finished && b.version == shown)
            .unwrap_or(false)
    }

    fn say(&mut self, text: impl Into<String>, is_error: bool) {
        let text = text.into();
        if is_error {
            // Lost, not a panic, where standard error is closed.
            let _ = writeln!(std::io::stderr().lock(), "glint: {text}");
        }
        self.messages.push(Message { text, is_error });
        if self.messages.len() > 50 {
            self.messages.remove(0);
        }
    }

    /// One frame of the viewer: drawn into `ui`, which covers the window.
    pub fn frame_ui(&mut self, ui: &mut egui::Ui) {
        let ctx = ui.ctx().clone();
        self.input_serial += ctx.input(|i| {
            i.events
                .iter()
                .filter(|e| super::orbit_bench::is_pointer(e))
                .count() as u64
        });
        if let Some(failure) = self.worker.take_failure() {
            self.say(failure, true);
        }
        if !self.asked_focus {
            // Keys (R, Ctrl+S) work only in a focused window, and some
            // window managers focus a new window only when clicked.
            ctx.send_viewport_cmd(egui::ViewportCommand::Focus);
            self.asked_focus = true;
        }
        self.update_texture(&ctx);
        let mut commands = input::shortcuts(&ctx);
        if self.discarding.is_none()
            && ctx.input(|i| i.viewport().close_requested())
            && self.unsaved()
            && self.screenshot.is_none()
            && self.orbit_bench.is_none()
        {
            ctx.send_viewport_cmd(egui::ViewportCommand::CancelClose);
            self.discarding = Some(Discarding::Quit);
        }
        let snapshot = self.edit.snapshot();
        let menu = panels::MenuState {
            scene_name: &self.edit.scene.name,
            unsaved: self.unsaved(),
            can_undo: self.undoer.has_undo(&snapshot),
            can_redo: self.undoer.has_redo(&snapshot),
        };
        let magnification = &mut self.magnification;
        egui::Panel::top("menu").show(ui, |ui| {
            commands.extend(panels::menu_ui(&menu, magnification, ui))
        });
        let info = RenderInfo {
            worker: &self.worker,
            octree: &self.octree,
            build_seconds: self.build_seconds,
            bvh: self.bvh.as_ref().map(|b| (&*b.tree, b.seconds)),
            last_preview: self.last_preview,
            message: self.messages.last(),
        };
        egui::Panel::bottom("status").show(ui, |ui| {
            commands.extend(panels::status_ui(&self.edit, &info, ui))
        });
        // Fixed widths: rows appearing (the RMSE, a ray tree) must not
        // widen a panel and shrink the image.
        egui::Panel::left("controls")
            .resizable(false)
            .exact_size(330.0)
            .show(ui, |ui| {
                let history = self.worker.history();
                let octree = OctreeInfo {
                    octree: &self.octree,
                    build_seconds: self.build_seconds,
                    unit_costs: self.unit_costs,
                    last_pass: last_full_pass(&history),
                    threads: self.worker.threads(),
                    suggestion: self.suggestion.as_ref(),
                    ray_sample: self.ray_sample.as_ref().and_then(RaySampleJob::result),
                    ray_sample_taken: self
                        .ray_sample
                        .as_ref()
                        .is_some_and(|job| Arc::ptr_eq(&job.octree, &self.octree)),
                };
                let path = (&self.path_player, ui.input(|i| i.time));
                commands.extend(panels::controls_ui(
                    &mut self.edit,
                    &mut self.inspect,
                    &self.worker,
                    (&octree, path),
                    ui,
                ))
            });
        egui::Panel::right("timing")
            .resizable(false)
            .exact_size(330.0)
            .show(ui, |ui| {
                timing::timing_ui(&self.edit, &info, &mut self.inspect, ui)
            });
        egui::CentralPanel::default_margins().show(ui, |ui| commands.extend(self.image_ui(ui)));
        self.discard_prompt_ui(&ctx);
        self.path_prompt_ui(&ctx);
        self.apply(commands, &ctx);
        self.path_logic(&ctx);
        self.sync_octree();
        self.octree_tuning_logic(&ctx);
        self.undoer
            .feed_state(ctx.input(|i| i.time), &self.edit.snapshot());
        self.title_logic(&ctx);
        self.compare_logic();
        self.sync_render();
        self.screenshot_logic(&ctx);
        self.orbit_bench_logic(&ctx);
    }

    /// Before a frame: the orbit benchmark's events go into its input.
    pub fn raw_input_logic(&mut self, raw: &mut egui::RawInput) {
        if self.orbit_bench.is_some() {
            let ready = self.compare_pending.is_none() && self.final_pass_shown();
            let state = (
                self.input_serial,
                self.worker.generation(),
                self.worker.preview_counts(),
            );
            if let Some(bench) = &mut self.orbit_bench {
                bench.inject(raw, self.image_rect, ready, state);
            }
        }
    }

    /// Pointer events so far; a job submitted now carries this number.
    pub fn input_serial(&self) -> u64 {
        self.input_serial
    }

    /// After a frame: the orbit benchmark's report once the final pass after
    /// its drag is on screen, and the window closes.
    fn orbit_bench_logic(&mut self, ctx: &egui::Context) {
        if let Some(bench) = &mut self.orbit_bench {
            bench.request_wake(ctx);
        }
        if self.orbit_bench.as_ref().is_none_or(OrbitBench::is_done) {
            return;
        }
        let final_shown = self
            .final_pass_shown()
            .then(|| self.worker.with_buffer(|b| b.serial));
        let (w, h) = (self.edit.settings.width, self.edit.settings.height);
        let describe = serde_json::json!({
            "scene": self.edit.source.display_name(),
            "image": [w, h],
            "window": [ctx.content_rect().width(), ctx.content_rect().height()],
            "threads": self.worker.threads(),
            "simd": crate::simd::SimdLevel::current().name(),
            "final_pass": self.edit.settings.anti_aliasing().name(),
        });
        let history = self.worker.history();
        let counts = self.worker.preview_counts();
        if let Some(report) = self
            .orbit_bench
            .as_mut()
            .and_then(|bench| bench.finish(final_shown, &history, counts, describe))
        {
            let _ = writeln!(std::io::stdout().lock(), "{report}");
            ctx.send_viewport_cmd(egui::ViewportCommand::Close);
        }
    }

    /// The image, and mouse control of the camera over it.
    fn image_ui(&mut self, ui: &mut egui::Ui) -> Vec<Command> {
        let (width, height) = (self.edit.settings.width, self.edit.settings.height);
        let available = ui.available_size();
        // Scale the image into the panel (display-only: never restarts a render).
        let pixels_per_point = ui.ctx().pixels_per_point();
        let scale = self
            .magnification
            .scale((width, height), available, pixels_per_point);
        let size = egui::vec2(width as f32 * scale, height as f32 * scale);
        let (rect, response) = ui.allocate_exact_size(available, Sense::click_and_drag());
        // On the screen's pixel grid, so whole-pixel blocks stay even.
        let snap = |x: f32| (x * pixels_per_point).round() / pixels_per_point;
        let min = rect.center() - size / 2.0;
        let image_rect = egui::Rect::from_min_size(egui::pos2(snap(min.x), snap(min.y)), size);
        self.image_rect = Some(image_rect);
        // 1:1 may be larger than the panel: cut it at the panel's edges.
        ui.set_clip_rect(rect.intersect(ui.clip_rect()));
        let live = self.texture.clone();
        let compared = self
            .inspect
            .compare_image_ui(ui, image_rect, live.as_ref(), &self.worker);
        match &live {
            _ if compared => {}
            Some(t) => {
                let uv = egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
                ui.painter().image(t.id(), image_rect, uv, Color32::WHITE);
            }
            None => {
                ui.painter().text(
                    rect.center(),
                    egui::Align2::CENTER_CENTER,
                    "rendering…",
                    egui::FontId::proportional(16.0),
                    ui.visuals().text_color(),
                );
            }
        }
        self.inspect
            .overlays_ui(ui, image_rect, &self.edit, &self.octree);
        let mut commands = Vec::new();
        if let Some((i, j)) = input::picked_pixel(
            ui,
            &response,
            image_rect,
            (width, height),
            self.inspect.inspect_mode,
        ) {
            commands.push(Command::InspectPixel(i, j));
        }
        let (camera, moved) = input::camera_control(ui, &response, &self.edit.camera, size.y);
        self.edit.camera = camera;
        let on_image = response.is_pointer_button_down_on();
        self.dragging = on_image && (moved || self.dragging);
        self.widget_dragged = ui.ctx().dragged_id().is_some() && !on_image;
        commands
    }

    fn apply(&mut self, commands: Vec<Command>, ctx: &egui::Context) {
        for command in commands {
            match command {
                Command::ResetCamera => self.edit.camera = self.edit.scene.camera,
                Command::Reload if self.unsaved() => self.discarding = Some(Discarding::Reload),
                Command::Reload => self.reload(),
                Command::Open => self.open_dialog(),
                Command::Save => self.save(),
                Command::StopPass => self.worker.stop(),
                Command::SaveAs => self.save_as(),
                Command::Undo => {
                    let now = self.edit.snapshot();
                    if let Some(s) = self.undoer.undo(&now).cloned() {
                        self.edit.restore(&s);
                    }
                }
                Command::Redo => {
                    let now = self.edit.snapshot();
                    if let Some(s) = self.undoer.redo(&now).cloned() {
                        self.edit.restore(&s);
                    }
                }
                Command::Export => self.export(),
                Command::InspectPixel(i, j) => self.inspect_pixel(i, j),
                Command::PinAsA => self.pin_as_a(),
                Command::SetOctreeParams(params) => self.set_octree_params(params),
                Command::SuggestOctree => self.suggest_octree(),
                Command::SampleRays => self.sample_rays(),
                Command::CameraPath(c) => self.path_command(c, ctx),
                Command::Quit => ctx.send_viewport_cmd(egui::ViewportCommand::Close),
            }
        }
    }

    /// `--compare`: once A (the flipped setting) is complete, pin it and
    /// flip the setting back, so B renders.
    fn compare_logic(&mut self) {
        let Some(setting) = self.compare_pending else {
            return;
        };
        if !self.final_pass_shown() {
            return;
        }
        self.pin_as_a();
        if self.compare_difference
            && let Some(c) = &mut self.inspect.compare
        {
            c.mode = CompareMode::Difference;
        }
        self.edit.flip(setting);
        self.compare_pending = None;
    }

    /// Submits a new job if anything that decides the image changed.
    pub fn sync_render(&mut self) {
        let history = self.worker.history();
        let preview = if self.dragging {
            budget::choose_preview(&history, &self.edit.settings, self.edit.frame_budget_ms)
        } else if self.widget_dragged
            && budget::reuses(&self.edit.settings)
            && self.submitted.as_ref().is_some_and(|s| {
                s.settings == self.edit.settings
                    && s.octree == self.octree.params()
                    && (s.camera != self.edit.camera || s.scene_version != self.edit.scene_version)
            })
        {
            // A light, a material or the camera dragged in a panel: the
            // render cache re-traces what the change touches.
            Some((
                Preview::Reuse,
                budget::reuse_seconds(self.edit.frame_budget_ms),
            ))
        } else {
            None
        };
        let edit = &self.edit;
        let inputs = RenderInputs {
            camera: edit.camera,
            settings: edit.settings,
            scene_version: edit.scene_version,
            octree: self.octree.params(),
            preview: preview.map(|(p, _)| p),
            show_sources: edit.show_sources,
        };
        if self.submitted.as_ref() == Some(&inputs) {
            return;
        }
        // Held still mid-drag, the view on screen is not rendered again at
        // another preview level because the timings moved: under load the
        // choice could alternate on every preview, for as long as the
        // button is down.
        if let Some(submitted) = &self.submitted
            && submitted.preview.is_some()
            && inputs.preview.is_some()
            && (RenderInputs {
                preview: submitted.preview,
                ..inputs.clone()
            }) == *submitted
        {
            return;
        }
        if preview.is_some() {
            self.last_preview = preview;
        }
        let bvh = self.bvh_if_chosen();
        let edit = &self.edit;
        let job = Job {
            scene: Arc::clone(&edit.scene),
            octree: Arc::clone(&self.octree),
            bvh,
            camera: edit.camera,
            settings: edit.settings,
            preview: inputs.preview,
            frame_budget_ms: edit.frame_budget_ms,
            show_sources: edit.show_sources,
            serial: self.input_serial,
        };
        // While dragging, the preview in flight is finished and shown; this
        // camera waits for it (or for the next, newer one).
        if job.preview.is_some() {
            self.worker.submit_preview(job);
        } else {
            self.worker.submit(job);
        }
        self.submitted = Some(inputs);
        // The inspected pixel follows the change: its rays are traced again
        // (one pixel, a few microseconds) so the panel never shows a stale tree.
        if let Some((i, j)) = self.inspect.inspection.take().map(|ins| ins.pixel) {
            self.inspect_pixel(i, j);
        }
    }

    /// Uploads the display buffer to the texture if new tiles arrived.
    fn update_texture(&mut self, ctx: &egui::Context) {
        let shown = self.shown_version;
        let saving = self
            .orbit_bench
            .as_ref()
            .is_some_and(OrbitBench::saves_previews);
        let update = self.worker.try_with_buffer(|b| {
            (b.version != shown && b.width > 0).then(|| {
                // The orbit benchmark keeps previews it saves as shown.
                let capture = saving.then(|| CapturedPreview::of(b)).flatten();
                (
                    b.version,
                    egui::ColorImage::from_rgba_unmultiplied(
                        [b.width as usize, b.height as usize],
                        &b.rgba,
                    ),
                    ShownFrame::of(b),
                    capture,
                )
            })
        });
        if let Some(Some((version, image, frame, capture))) = update {
            if let Some(bench) = &mut self.orbit_bench {
                bench.shown(frame, || capture);
            }
            self.shown_version = version;
            match &mut self.texture {
                Some(t) => t.set(image, TEXTURE),
                None => self.texture = Some(ctx.load_texture("glint-render", image, TEXTURE)),
            }
        }
    }

    fn screenshot_logic(&mut self, ctx: &egui::Context) {
        let ready = self.compare_pending.is_none() && self.final_pass_shown();
        let generation = self.worker.generation();
        let passes = ready.then(|| {
            self.worker
                .history()
                .iter()
                .filter(|r| r.generation == generation)
                .copied()
                .collect()
        });
        if let Some(s) = &mut self.screenshot {
            s.update(ctx, passes);
        }
    }

    /// Whether the edits differ from the scene as last loaded or saved.
    pub fn unsaved(&self) -> bool {
        self.edit.snapshot().differs_in_saved_values(&self.saved)
    }

    /// The window title: the scene, marked while it has unsaved edits, and
    /// saying so when only the camera moved (an orbit is an edit too).
    fn title_logic(&mut self, ctx: &egui::Context) {
        let now = self.edit.snapshot();
        let name = self.edit.source.display_name();
        let title = if !now.differs_in_saved_values(&self.saved) {
            format!("{name} — glint")
        } else if now.differs_only_in_camera(&self.saved) {
            format!("● {name} (camera moved) — glint")
        } else {
            format!("● {name} — glint")
        };
        if title != self.title {
            ctx.send_viewport_cmd(egui::ViewportCommand::Title(title.clone()));
            self.title = title;
        }
    }

    /// The window title as last set.
    pub fn title(&self) -> &str {
        &self.title
    }

    pub fn octree(&self) -> &Octree {
        &self.octree
    }

    /// The unit costs measured on this scene (once its first pass is in).
    pub fn unit_costs(&self) -> Option<UnitCosts> {
        self.unit_costs
    }

    /// The ray whose octree walk is shown, and how many steps.
    pub fn walk(&self) -> (Option<&WalkTarget>, usize) {
        (self.inspect.walk.target.as_ref(), self.inspect.walk.shown)
    }
}

impl eframe::App for GlintApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        self.frame_ui(ui);
    }

    fn raw_input_hook(&mut self, _ctx: &egui::Context, raw_input: &mut egui::RawInput) {
        self.raw_input_logic(raw_input);
    }
}
