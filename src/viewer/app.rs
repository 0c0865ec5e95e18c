//! The viewer's application state and frame logic.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use egui::{
    Color32, Key, KeyboardShortcut, Modifiers, PointerButton, Sense, TextureHandle, TextureOptions,
};

use super::orbit;
use super::worker::{Job, PassKind, PassRecord, Preview, Worker};
use crate::accel::Octree;
use crate::camera::CameraSpec;
use crate::export::{RenderRecord, SceneEdits};
use crate::scene::Scene;
use crate::settings::{RenderSettings, ViewMode};

/// Where the current scene came from.
#[derive(Clone, Debug, PartialEq)]
pub enum SceneSource {
    BuiltIn,
    File(PathBuf),
}

impl SceneSource {
    pub fn load(&self) -> anyhow::Result<Scene> {
        Ok(match self {
            SceneSource::BuiltIn => crate::scene::builtin::default_scene()?,
            SceneSource::File(p) => crate::scene::load(p)?,
        })
    }

    /// A short name for file names: the scene file's stem.
    pub fn stem(&self) -> String {
        match self {
            SceneSource::BuiltIn => "default".into(),
            SceneSource::File(p) => p
                .file_stem()
                .map_or("scene".into(), |s| s.to_string_lossy().into_owned()),
        }
    }
}

/// Start-up options of the viewer.
#[derive(Clone, Debug, Default)]
pub struct ViewerOptions {
    /// Save a screenshot of the whole window here once the final pass is on
    /// screen, then exit.
    pub screenshot: Option<PathBuf>,
    /// Frames to wait after the final pass before the screenshot.
    pub frames: u32,
    /// Render threads (0 = one per core).
    pub threads: usize,
    /// Initial settings that differ from the scene's (view mode, octree, AA).
    pub view: Option<ViewMode>,
    pub octree: Option<bool>,
    pub anti_aliasing: Option<crate::settings::AntiAliasing>,
    /// Image size overriding the scene's.
    pub size: Option<(u32, u32)>,
    /// Start with the octree overlay drawn down to this level.
    pub overlay_depth: Option<u32>,
    /// Start with this pixel's ray tree inspected.
    pub inspect: Option<(u32, u32)>,
    /// Start by comparing against the image with this setting flipped:
    /// A is rendered with it flipped and pinned, then B as given.
    pub compare: Option<CompareSetting>,
    /// Show the comparison as a difference rather than a split.
    pub compare_difference: bool,
    /// Start with these rules instead of the scene's (the protocol first:
    /// it sets its depth and sidedness).
    pub protocol: Option<crate::settings::Protocol>,
    pub colors: Option<crate::color::ColorConvention>,
    pub sides: Option<crate::settings::Sides>,
}

/// A setting `--compare` flips for the A image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CompareSetting {
    Octree,
    AntiAliasing,
}

/// A message shown in the status area.
#[derive(Clone, Debug)]
pub struct Message {
    pub text: String,
    pub is_error: bool,
}

/// Everything that decides the rendered image; a change restarts the passes.
#[derive(Clone, Debug, PartialEq)]
struct RenderInputs {
    camera: CameraSpec,
    settings: RenderSettings,
    anti_aliasing: bool,
    scene_version: u64,
    preview: Option<Preview>,
}

/// What the panels ask for; applied once per frame after the UI is drawn.
#[derive(Clone, Debug, PartialEq)]
pub enum Command {
    Open,
    Reload,
    Export,
    ResetCamera,
}

pub struct GlintApp {
    // What the user edits.
    pub(crate) source: SceneSource,
    pub(crate) scene: Arc<Scene>,
    /// Bumped whenever lights or materials are edited.
    pub(crate) scene_version: u64,
    pub(crate) camera: CameraSpec,
    pub(crate) settings: RenderSettings,
    pub(crate) anti_aliasing: bool,
    // Runtime.
    pub(crate) octree: Arc<Octree>,
    pub(crate) build_seconds: f64,
    pub(crate) worker: Worker,
    texture: Option<TextureHandle>,
    shown_version: u64,
    submitted: Option<RenderInputs>,
    pub(crate) dragging: bool,
    /// Target time of a preview pass while the user drags (milliseconds).
    pub(crate) frame_budget_ms: f64,
    asked_focus: bool,
    /// What the budget chose for the last drag, and its estimated seconds.
    pub(crate) last_preview: Option<(Preview, f64)>,
    pub(crate) messages: Vec<Message>,
    pub(crate) commands: Vec<Command>,
    options: ViewerOptions,
    frames_since_final: u32,
    screenshot_requested: bool,
    /// Set when the app wants the window closed (after `--screenshot`).
    pub exit_requested: bool,
    started: Instant,
    pub(crate) inspect: super::inspect::InspectState,
    /// `--compare` waiting for A's final pass to pin it.
    compare_pending: Option<CompareSetting>,
    /// Where the image was drawn in the last frame (screen points).
    image_rect: Option<egui::Rect>,
}

impl GlintApp {
    /// Loads `source` and starts rendering; `repaint` wakes the UI thread.
    pub fn new(
        source: SceneSource,
        options: ViewerOptions,
        repaint: impl Fn() + Send + Sync + 'static,
    ) -> anyhow::Result<Self> {
        let scene = source.load()?;
        let worker = Worker::spawn(options.threads, repaint);
        let mut settings = RenderSettings::from_scene(&scene);
        let aa = options.anti_aliasing.unwrap_or(settings.anti_aliasing());
        let anti_aliasing = aa != crate::settings::AntiAliasing::Off;
        settings.adaptive = aa == crate::settings::AntiAliasing::Adaptive;
        if let Some(v) = options.view {
            settings.view = v;
        }
        if let Some(o) = options.octree {
            settings.use_octree = o;
        }
        if let Some((w, h)) = options.size {
            (settings.width, settings.height) = (w, h);
        }
        if let Some(p) = options.protocol {
            settings = settings.with_protocol(p);
        }
        if let Some(c) = options.colors {
            settings.colors = c;
        }
        if let Some(s) = options.sides {
            settings.sides = s;
        }
        let (octree, build_seconds) = build_octree(&scene)?;
        let mut anti_aliasing = anti_aliasing;
        match options.compare {
            Some(CompareSetting::Octree) => settings.use_octree = !settings.use_octree,
            Some(CompareSetting::AntiAliasing) => anti_aliasing = !anti_aliasing,
            None => {}
        }
        let inspect = super::inspect::InspectState {
            overlay_depth: options.overlay_depth,
            ..Default::default()
        };
        let mut app = Self {
            camera: scene.camera,
            source,
            scene: Arc::new(scene),
            scene_version: 0,
            settings,
            anti_aliasing,
            octree: Arc::new(octree),
            build_seconds,
            worker,
            texture: None,
            shown_version: 0,
            submitted: None,
            dragging: false,
            frame_budget_ms: 33.0,
            last_preview: None,
            asked_focus: false,
            messages: Vec::new(),
            commands: Vec::new(),
            frames_since_final: 0,
            screenshot_requested: false,
            exit_requested: false,
            started: Instant::now(),
            inspect,
            compare_pending: options.compare,
            image_rect: None,
            options,
        };
        if let Some((i, j)) = app.options.inspect {
            app.inspect_pixel(i, j);
        }
        Ok(app)
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
        if self.options.compare_difference
            && let Some(c) = &mut self.inspect.compare
        {
            c.mode = super::inspect::CompareMode::Difference;
        }
        match setting {
            CompareSetting::Octree => self.settings.use_octree = !self.settings.use_octree,
            CompareSetting::AntiAliasing => self.anti_aliasing = !self.anti_aliasing,
        }
        self.compare_pending = None;
    }

    pub fn settings(&self) -> &RenderSettings {
        &self.settings
    }

    /// Render settings as the panels edit them; a change restarts the passes.
    pub fn settings_mut(&mut self) -> &mut RenderSettings {
        &mut self.settings
    }

    pub fn anti_aliasing(&self) -> bool {
        self.anti_aliasing
    }

    /// Turns the 16-sample pass on or off; a change restarts the passes.
    pub fn set_anti_aliasing(&mut self, on: bool) {
        self.anti_aliasing = on;
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
        &self.scene
    }

    pub fn camera(&self) -> &CameraSpec {
        &self.camera
    }

    /// Where the image was drawn in the last frame (screen points).
    pub fn image_rect(&self) -> Option<egui::Rect> {
        self.image_rect
    }

    pub fn inspection(&self) -> Option<&super::inspect::Inspection> {
        self.inspect.inspection.as_ref()
    }

    pub fn compare(&self) -> Option<&super::inspect::Compare> {
        self.inspect.compare.as_ref()
    }

    pub fn messages(&self) -> &[Message] {
        &self.messages
    }

    /// Mutable access to lights and materials; marks the image stale.
    pub fn scene_mut(&mut self) -> &mut Scene {
        self.scene_version += 1;
        Arc::make_mut(&mut self.scene)
    }

    pub(crate) fn say(&mut self, text: impl Into<String>, is_error: bool) {
        let text = text.into();
        if is_error {
            eprintln!("glint: {text}");
        }
        self.messages.push(Message { text, is_error });
        if self.messages.len() > 50 {
            self.messages.remove(0);
        }
    }

    /// The preview to render while dragging (`None` when not): the best
    /// image whose estimated time fits the frame budget. Candidates in order
    /// of preference: full, 1/2, 1/4, 1/8 resolution, each first complete,
    /// then without reflections, then without shadows too. Estimates come
    /// from this scene's last full 1-sample pass (its time per pixel, and
    /// its rays by kind for what dropping reflections or shadows saves),
    /// corrected by how far the last preview's estimate was off.
    fn choose_preview(&self, history: &[PassRecord]) -> Option<(Preview, f64)> {
        if !self.dragging {
            return None;
        }
        let fallback = Preview {
            divisor: 4,
            reflections: true,
            shadows: true,
        };
        let Some(base) = history
            .iter()
            .rev()
            .find(|r| matches!(r.kind, PassKind::OneSample | PassKind::Corners))
        else {
            return Some((fallback, f64::NAN));
        };
        let estimate = |p: &Preview| estimate_preview(base, p, &self.settings);
        // How far off the model was on the last preview it predicted.
        let correction = history
            .iter()
            .rev()
            .find_map(|r| match r.kind {
                PassKind::Preview(p) if r.finished_at > base.finished_at => {
                    Some((r.seconds / estimate(&p)).clamp(0.25, 4.0))
                }
                _ => None,
            })
            .unwrap_or(1.0);
        let budget = self.frame_budget_ms / 1000.0;
        let candidates = [1u32, 2, 4, 8].into_iter().flat_map(|divisor| {
            [(true, true), (false, true), (false, false)].map(|(reflections, shadows)| Preview {
                divisor,
                reflections,
                shadows,
            })
        });
        let mut last = None;
        for p in candidates {
            let t = estimate(&p) * correction;
            if t <= budget {
                return Some((p, t));
            }
            last = Some((p, t));
        }
        last
    }

    /// Submits a new job if anything that decides the image changed.
    pub fn sync_render(&mut self) {
        let history = self.worker.history();
        let inputs = RenderInputs {
            camera: self.camera,
            settings: self.settings,
            anti_aliasing: self.anti_aliasing,
            scene_version: self.scene_version,
            preview: self.choose_preview(&history).map(|(p, _)| p),
        };
        if let Some(choice) = self.choose_preview(&history) {
            self.last_preview = Some(choice);
        }
        if self.submitted.as_ref() == Some(&inputs) {
            return;
        }
        self.worker.submit(Job {
            scene: Arc::clone(&self.scene),
            octree: Arc::clone(&self.octree),
            camera: self.camera,
            settings: self.settings,
            anti_aliasing: self.anti_aliasing,
            preview: inputs.preview,
        });
        self.submitted = Some(inputs);
        // The inspected pixel follows the change: its rays are traced again
        // (one pixel, a few microseconds) so the panel never shows a stale tree.
        if let Some((i, j)) = self.inspect.inspection.as_ref().map(|ins| ins.pixel) {
            self.inspect.inspection = None;
            self.inspect_pixel(i, j);
        }
    }

    /// Uploads the display buffer to the texture if new tiles arrived.
    fn update_texture(&mut self, ctx: &egui::Context) {
        let shown = self.shown_version;
        let update = self.worker.try_with_buffer(|b| {
            (b.version != shown && b.width > 0).then(|| {
                (
                    b.version,
                    egui::ColorImage::from_rgba_unmultiplied(
                        [b.width as usize, b.height as usize],
                        &b.rgba,
                    ),
                )
            })
        });
        if let Some(Some((version, image))) = update {
            self.shown_version = version;
            match &mut self.texture {
                Some(t) => t.set(image, TextureOptions::NEAREST),
                None => {
                    self.texture =
                        Some(ctx.load_texture("glint-render", image, TextureOptions::NEAREST))
                }
            }
        }
    }

    /// Is the final pass of the current job on screen?
    pub fn final_pass_shown(&self) -> bool {
        let generation = self.worker.generation();
        let shown = self.shown_version;
        self.worker
            .try_with_buffer(|b| b.generation == generation && b.finished && b.version == shown)
            .unwrap_or(false)
    }

    fn apply_commands(&mut self, ctx: &egui::Context) {
        for command in std::mem::take(&mut self.commands) {
            match command {
                Command::ResetCamera => self.camera = self.scene.camera,
                Command::Reload => self.reload(),
                Command::Open => self.open_dialog(),
                Command::Export => self.export(),
            }
        }
        let _ = ctx;
    }

    /// Re-reads the scene file, keeping the camera; a failure keeps the
    /// current scene on screen.
    pub fn reload(&mut self) {
        match self
            .source
            .load()
            .and_then(|scene| self.install_scene(scene, false))
        {
            Ok(()) => self.say(format!("reloaded {}", self.scene.name), false),
            Err(e) => self.say(
                format!("reload failed, keeping the previous scene: {e:#}"),
                true,
            ),
        }
    }

    /// Opens another scene file.
    pub fn open(&mut self, path: PathBuf) {
        let source = SceneSource::File(path);
        match source
            .load()
            .and_then(|scene| self.install_scene(scene, true))
        {
            Ok(()) => {
                self.source = source;
                self.say(format!("opened {}", self.scene.name), false);
            }
            Err(e) => self.say(format!("cannot open: {e:#}"), true),
        }
    }

    fn install_scene(&mut self, scene: Scene, take_camera: bool) -> anyhow::Result<()> {
        let (octree, seconds) = build_octree(&scene)?;
        if take_camera {
            self.camera = scene.camera;
            // The new scene's own settings (its colour convention among
            // them), keeping the view, the octree switch and the protocol.
            let keep_view = self.settings.view;
            self.settings = RenderSettings {
                view: keep_view,
                use_octree: self.settings.use_octree,
                ..RenderSettings::from_scene(&scene)
            }
            .with_protocol(self.settings.protocol);
        }
        self.octree = Arc::new(octree);
        self.build_seconds = seconds;
        self.scene = Arc::new(scene);
        self.scene_version += 1;
        Ok(())
    }

    fn open_dialog(&mut self) {
        if !file_dialog_available() {
            self.say("no file dialog is available here (no desktop portal); pass the scene on the command line: glint view SCENE", true);
            return;
        }
        if let Some(path) = rfd::FileDialog::new()
            .add_filter("scenes", &["toml", "nff"])
            .pick_file()
        {
            self.open(path);
        }
    }

    /// Writes the displayed frame to a PNG chosen in a save dialog, or, where
    /// no dialog is available, to the current directory.
    pub fn export(&mut self) {
        let default_name = format!("{}-{}.png", self.source.stem(), timestamp());
        let path = if file_dialog_available() {
            match rfd::FileDialog::new()
                .set_file_name(&default_name)
                .add_filter("PNG", &["png"])
                .save_file()
            {
                Some(p) => p,
                None => return,
            }
        } else {
            // No dialog (no desktop portal, e.g. under Xvfb): a place made
            // for pictures, never the working directory (often a checkout).
            export_dir(&self.source).join(&default_name)
        };
        match self.export_to(&path) {
            Ok(()) => {
                let shown = std::path::absolute(&path).unwrap_or(path);
                self.say(format!("exported {}", shown.display()), false)
            }
            Err(e) => self.say(format!("export to {} failed: {e:#}", path.display()), true),
        }
    }

    /// Saves the display buffer with the record of how it was made (see
    /// [`crate::export`]): the scene, camera and settings of the pass on
    /// screen, not the panels' current values. A finished pass is written
    /// as `glint render` writes it (diagnostic views with their legend
    /// strip, the octree overlay drawn in when it is shown); a pass still
    /// sweeping in is written as displayed and recorded as partial.
    pub fn export_to(&self, path: &Path) -> anyhow::Result<()> {
        let (w, h, rgba, frame, source, finished) = self.worker.with_buffer(|b| {
            (
                b.width,
                b.height,
                b.rgba.clone(),
                b.last_frame.clone(),
                b.source.clone(),
                b.finished,
            )
        });
        anyhow::ensure!(w > 0 && h > 0, "nothing has been rendered yet");
        let Some(source) = source else {
            anyhow::bail!("nothing has been rendered yet");
        };
        let name = match &self.source {
            SceneSource::BuiltIn => crate::scene::builtin::NAME.to_string(),
            SceneSource::File(p) => p.display().to_string(),
        };
        let mut record = RenderRecord::new(&source.scene, &name, &source.camera, source.settings);
        // Lights and materials as rendered (the panels may have edited them).
        record.settings.edits = Some(SceneEdits {
            lights: source.scene.lights.clone(),
            materials: source.scene.materials.clone(),
        });
        match frame {
            Some(f) if finished && f.width == w && f.height == h => {
                match self.inspect.overlay_depth {
                    Some(depth) => {
                        record.settings.overlay_depth = Some(depth);
                        let camera = crate::camera::Camera::new(&source.camera, w, h)?;
                        let cells = self.octree.cells(depth);
                        let (rgb, height) = crate::overlay::annotate(&f, &camera, &cells, depth);
                        crate::export::save_rgb_png(path, w, height, &rgb, Some(&record))?
                    }
                    None => crate::export::save_png(&f, path, Some(&record))?,
                }
            }
            _ => {
                record.settings.partial = true;
                let rgb: Vec<u8> = rgba
                    .chunks_exact(4)
                    .flat_map(|p| [p[0], p[1], p[2]])
                    .collect();
                crate::export::save_rgb_png(path, w, h, &rgb, Some(&record))?
            }
        }
        Ok(())
    }

    /// Keyboard shortcuts; R only when no text field has the focus.
    fn shortcuts(&mut self, ctx: &egui::Context) {
        let open = KeyboardShortcut::new(Modifiers::COMMAND, Key::O);
        let save = KeyboardShortcut::new(Modifiers::COMMAND, Key::S);
        let reload = KeyboardShortcut::new(Modifiers::NONE, Key::F5);
        ctx.input_mut(|i| {
            if i.consume_shortcut(&open) {
                self.commands.push(Command::Open);
            }
            if i.consume_shortcut(&save) {
                self.commands.push(Command::Export);
            }
            if i.consume_shortcut(&reload) {
                self.commands.push(Command::Reload);
            }
        });
        if !ctx.egui_wants_keyboard_input()
            && ctx.input(|i| i.key_pressed(Key::R) && i.modifiers.is_none())
        {
            self.commands.push(Command::ResetCamera);
        }
    }

    /// The image, and mouse control of the camera over it.
    pub(crate) fn image_ui(&mut self, ui: &mut egui::Ui) {
        let available = ui.available_size();
        let aspect = self.settings.width as f32 / self.settings.height.max(1) as f32;
        // Fit the image into the panel (display-only: never restarts a render).
        let mut size = egui::vec2(available.x, available.x / aspect);
        if size.y > available.y {
            size = egui::vec2(available.y * aspect, available.y);
        }
        let (rect, response) = ui.allocate_exact_size(available, Sense::click_and_drag());
        let image_rect = egui::Rect::from_center_size(rect.center(), size);
        self.image_rect = Some(image_rect);
        let live = self.texture.clone();
        let compared = self.compare_image_ui(ui, image_rect, live.as_ref());
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
        self.overlays_ui(ui, image_rect);
        // Inspect: Ctrl+click, or a click in inspect mode, picks a pixel.
        if response.clicked()
            && (self.inspect.inspect_mode || ui.input(|i| i.modifiers.command))
            && let Some(pos) = response.interact_pointer_pos()
            && image_rect.contains(pos)
        {
            let x = (pos.x - image_rect.min.x) / image_rect.width() * self.settings.width as f32;
            let y = (pos.y - image_rect.min.y) / image_rect.height() * self.settings.height as f32;
            self.inspect_pixel(x as u32, y as u32);
        }
        // Mouse: left orbits, right or middle pans, the wheel dollies.
        let delta = response.drag_delta();
        let scale = 1.0 / size.y.max(1.0) as f64;
        let mut moved = false;
        if response.dragged_by(PointerButton::Primary) && delta != egui::Vec2::ZERO {
            self.camera = orbit::orbit(
                &self.camera,
                -delta.x as f64 * scale * 3.0,
                delta.y as f64 * scale * 3.0,
            );
            moved = true;
        }
        if (response.dragged_by(PointerButton::Secondary)
            || response.dragged_by(PointerButton::Middle))
            && delta != egui::Vec2::ZERO
        {
            self.camera = orbit::pan(&self.camera, delta.x as f64, delta.y as f64, size.y as f64);
            moved = true;
        }
        if response.hovered() {
            let scroll = ui.input(|i| i.smooth_scroll_delta.y);
            if scroll != 0.0 {
                self.camera = orbit::dolly(&self.camera, scroll as f64 * 0.002);
            }
        }
        self.dragging = response.is_pointer_button_down_on() && (moved || self.dragging);
        if !response.is_pointer_button_down_on() {
            self.dragging = false;
        }
    }

    /// One frame of the viewer: drawn into `ui`, which covers the window.
    pub fn frame_ui(&mut self, ui: &mut egui::Ui) {
        let ctx = ui.ctx().clone();
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
        self.shortcuts(&ctx);
        egui::Panel::top("menu").show(ui, |ui| super::panels::menu_ui(self, ui));
        egui::Panel::bottom("status").show(ui, |ui| super::panels::status_ui(self, ui));
        // Fixed widths: rows appearing (the RMSE, a ray tree) must not
        // widen a panel and shrink the image.
        egui::Panel::left("controls")
            .resizable(false)
            .exact_size(330.0)
            .show(ui, |ui| super::panels::controls_ui(self, ui));
        egui::Panel::right("timing")
            .resizable(false)
            .exact_size(330.0)
            .show(ui, |ui| super::panels::timing_ui(self, ui));
        egui::CentralPanel::default_margins().show(ui, |ui| self.image_ui(ui));
        self.apply_commands(&ctx);
        self.compare_logic();
        self.sync_render();
        self.screenshot_logic(&ctx);
    }

    fn screenshot_logic(&mut self, ctx: &egui::Context) {
        let Some(path) = self.options.screenshot.clone() else {
            return;
        };
        if self.screenshot_requested {
            // Keep frames coming until the screenshot callback has run.
            ctx.request_repaint();
            return;
        }
        if self.compare_pending.is_none() && self.final_pass_shown() {
            if self.frames_since_final == 0 {
                // Report the passes of the shown image: the measured time to
                // the first and the final pass.
                let generation = self.worker.generation();
                for r in self
                    .worker
                    .history()
                    .iter()
                    .filter(|r| r.generation == generation)
                {
                    eprintln!(
                        "glint: {} pass {}x{}: {:.3} s, {:.2} Mrays/s, octree {}",
                        r.kind.label(),
                        r.width,
                        r.height,
                        r.seconds,
                        r.rays.total() as f64 / r.seconds.max(1e-9) / 1e6,
                        if r.octree { "on" } else { "off" }
                    );
                }
            }
            self.frames_since_final += 1;
            if self.frames_since_final >= self.options.frames.max(1) {
                self.screenshot_requested = true;
                let ctx2 = ctx.clone();
                ctx.request_screenshot(move |image: Arc<egui::ColorImage>| {
                    let [w, h] = image.size;
                    let rgba: Vec<u8> = image.pixels.iter().flat_map(|c| c.to_array()).collect();
                    let result = image::RgbaImage::from_raw(w as u32, h as u32, rgba)
                        .ok_or_else(|| anyhow::anyhow!("bad screenshot size"))
                        .and_then(|img| img.save(&path).map_err(anyhow::Error::from));
                    match result {
                        Ok(()) => eprintln!("glint: saved window screenshot {}", path.display()),
                        Err(e) => eprintln!("glint: screenshot failed: {e:#}"),
                    }
                    ctx2.send_viewport_cmd(egui::ViewportCommand::Close);
                });
            }
            ctx.request_repaint();
        }
    }

    pub(crate) fn uptime(&self) -> f64 {
        self.started.elapsed().as_secs_f64()
    }
}

impl eframe::App for GlintApp {
    fn ui(&mut self, ui: &mut egui::Ui, _frame: &mut eframe::Frame) {
        self.frame_ui(ui);
    }
}

fn build_octree(scene: &Scene) -> anyhow::Result<(Octree, f64)> {
    let start = Instant::now();
    let octree = Octree::build(&scene.shapes, scene.octree_params)
        .map_err(|e| anyhow::anyhow!("{}: {e}", scene.name))?;
    Ok((octree, start.elapsed().as_secs_f64()))
}

/// rfd's dialogs go through the XDG desktop portal on D-Bus; without a
/// session bus (a bare X server such as Xvfb) there is no dialog to show.
fn file_dialog_available() -> bool {
    std::env::var_os("DBUS_SESSION_BUS_ADDRESS").is_some_and(|v| !v.is_empty())
}

/// A readable UTC timestamp for file names, e.g. `2026-11-23T14-05-09Z`.
fn timestamp() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    utc_timestamp(secs)
}

/// `secs` since the Unix epoch as `YYYY-MM-DDTHH-MM-SSZ` (dashes, not
/// colons, so the name is valid everywhere). The date from the day count
/// follows Hinnant's `civil_from_days` ("chrono-Compatible Low-Level Date
/// Algorithms").
fn utc_timestamp(secs: u64) -> String {
    let days = (secs / 86_400) as i64;
    let rem = secs % 86_400;
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1_460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + (month <= 2) as i64;
    format!(
        "{year:04}-{month:02}-{day:02}T{:02}-{:02}-{:02}Z",
        rem / 3600,
        rem / 60 % 60,
        rem % 60
    )
}

/// Where exports go without a file dialog: the user's pictures directory
/// (`XDG_PICTURES_DIR`, from the environment or `~/.config/user-dirs.dirs`,
/// else `~/Pictures`) if it exists, else the scene file's directory, else
/// the temporary directory.
fn export_dir(source: &SceneSource) -> PathBuf {
    let home = std::env::var_os("HOME").map(PathBuf::from);
    let from_user_dirs = || {
        let home = home.as_ref()?;
        let text = std::fs::read_to_string(home.join(".config/user-dirs.dirs")).ok()?;
        let line = text
            .lines()
            .find(|l| l.trim_start().starts_with("XDG_PICTURES_DIR="))?;
        let value = line.split_once('=')?.1.trim().trim_matches('"');
        Some(PathBuf::from(
            value.replace("$HOME", &home.to_string_lossy()),
        ))
    };
    let pictures = std::env::var_os("XDG_PICTURES_DIR")
        .map(PathBuf::from)
        .or_else(from_user_dirs)
        .or_else(|| home.as_ref().map(|h| h.join("Pictures")));
    if let Some(dir) = pictures.filter(|d| d.is_dir()) {
        return dir;
    }
    if let SceneSource::File(p) = source
        && let Some(dir) = p.parent().filter(|d| d.is_dir())
    {
        return std::path::absolute(dir).unwrap_or_else(|_| dir.to_owned());
    }
    std::env::temp_dir()
}

/// Estimated seconds of `preview` at the current settings, from the full
/// 1-sample pass `base`: time per pixel times the pixels, times the share
/// of its rays the preview still casts (dropping reflections drops the
/// secondary rays and the shadow rays from their hits).
fn estimate_preview(base: &PassRecord, preview: &Preview, settings: &RenderSettings) -> f64 {
    let per_pixel = base.seconds / (base.width as f64 * base.height as f64).max(1.0);
    let d = preview.divisor as f64;
    let pixels = (settings.width as f64 / d).max(1.0) * (settings.height as f64 / d).max(1.0);
    let r = base.rays;
    let total = r.total().max(1) as f64;
    let secondary = (r.reflection + r.refraction) as f64;
    let hits = r.primary_hits as f64;
    let mut shadow = r.shadow as f64;
    let mut rays = total;
    if !preview.reflections {
        rays -= secondary;
        // Shadow rays come from primary and secondary hits alike.
        let kept = shadow * hits / (hits + secondary).max(1.0);
        rays -= shadow - kept;
        shadow = kept;
    }
    if !preview.shadows {
        rays -= shadow;
    }
    per_pixel * pixels * (rays / total).max(0.05)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stats::RayCounts;

    fn base() -> PassRecord {
        PassRecord {
            generation: 1,
            kind: PassKind::OneSample,
            seconds: 0.4,
            // 100 eye rays, 80 hit; 40 secondary rays; 240 shadow rays.
            rays: RayCounts {
                primary: 100,
                primary_hits: 80,
                shadow: 240,
                reflection: 30,
                refraction: 10,
                total_internal_reflections: 0,
            },
            octree: true,
            anti_aliasing: false,
            width: 800,
            height: 600,
            finished_at: 1.0,
            one_sample_error: None,
            refined_pixels: None,
            view: crate::settings::ViewMode::Shaded,
            max_depth: 5,
            protocol: crate::settings::Protocol::Glint,
        }
    }

    #[test]
    fn timestamps_are_readable_utc() {
        assert_eq!(utc_timestamp(0), "1970-01-01T00-00-00Z");
        // 2000-02-29 (a leap day) 12:34:56 and 2026-11-23 14:05:09.
        assert_eq!(utc_timestamp(951_827_696), "2000-02-29T12-34-56Z");
        assert_eq!(utc_timestamp(1_795_442_709), "2026-11-23T14-05-09Z");
    }

    #[test]
    fn preview_estimates_scale_with_pixels_and_rays_cast() {
        let settings = RenderSettings {
            width: 800,
            height: 600,
            samples: 1,
            max_depth: 5,
            use_octree: true,
            view: crate::settings::ViewMode::Shaded,
            protocol: crate::settings::Protocol::Glint,
            colors: crate::color::ColorConvention::Linear,
            sides: crate::settings::Sides::Two,
            adaptive: false,
            shadows: true,
        };
        let p = |divisor, reflections, shadows| Preview {
            divisor,
            reflections,
            shadows,
        };
        let full = estimate_preview(&base(), &p(1, true, true), &settings);
        assert!((full - 0.4).abs() < 1e-12, "the base pass itself");
        let half = estimate_preview(&base(), &p(2, true, true), &settings);
        assert!((half - 0.1).abs() < 1e-12, "a quarter of the pixels");
        // Without reflections: 100 eye rays and the 240 * 80/120 = 160
        // shadow rays of eye-ray hits, of 380 rays.
        let flat = estimate_preview(&base(), &p(1, false, true), &settings);
        assert!((flat - 0.4 * 260.0 / 380.0).abs() < 1e-12, "{flat}");
        let bare = estimate_preview(&base(), &p(1, false, false), &settings);
        assert!((bare - 0.4 * 100.0 / 380.0).abs() < 1e-12, "{bare}");
    }
}
