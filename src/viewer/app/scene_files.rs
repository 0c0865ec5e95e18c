//! The viewer's scene files: open, reload, save and "save as", and the
//! prompt before an action drops unsaved edits.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::octree_tuning::build_octree;
use super::{Discarding, GlintApp};
use crate::scene::Scene;
use crate::scene::save::LeftOut;
use crate::settings::RenderSettings;
use crate::viewer::export;
use crate::viewer::save;
use crate::viewer::state::{SceneSource, Snapshot};

impl GlintApp {
    /// Asks before an action drops unsaved edits.
    pub(super) fn discard_prompt_ui(&mut self, ctx: &egui::Context) {
        let Some(action) = self.discarding.clone() else {
            return;
        };
        let verb = match &action {
            Discarding::Reload => "reload the scene file",
            Discarding::Open(_) => "open another scene",
            Discarding::Quit => "quit",
        };
        let mut choice = None;
        egui::Modal::new(egui::Id::unique("discard-edits")).show(ctx, |ui| {
            ui.heading("Unsaved edits");
            ui.label(format!(
                "{} has edits that are not saved. Discard them and {verb}?",
                self.edit.source.display_name()
            ));
            ui.horizontal(|ui| {
                if ui.button("Save first").clicked() {
                    choice = Some(true);
                }
                if ui.button("Discard").clicked() {
                    choice = Some(false);
                }
                if ui.button("Cancel").clicked() || ui.input(|i| i.key_pressed(egui::Key::Escape)) {
                    self.discarding = None;
                }
            });
        });
        let Some(save_first) = choice else {
            return;
        };
        self.discarding = None;
        if save_first {
            self.save();
            if self.unsaved() {
                return; // not saved (cancelled or failed): do nothing more
            }
        }
        match action {
            Discarding::Reload => self.reload(),
            Discarding::Open(path) => self.open(path),
            Discarding::Quit => {
                self.saved = self.edit.snapshot();
                ctx.send_viewport_cmd(egui::ViewportCommand::Close);
            }
        }
    }

    /// Writes the edits into the scene's TOML or NFF file; a scene without
    /// one (built in, an OBJ file) is saved as a new TOML file.
    pub fn save(&mut self) {
        self.stop_playing();
        match self.edit.source.path() {
            Some(p) if save::saves_in_place(&self.edit.source) => {
                let p = p.to_owned();
                self.save_to(&p)
            }
            _ => self.save_as(),
        }
    }

    /// Writes the scene with its edits to a new file (NFF for an NFF
    /// scene, TOML otherwise) and goes on editing that file.
    /// Without a file dialog, a path field filled in with the name glint
    /// would choose (beside the scene, or where exports go), so another
    /// folder can be named.
    pub fn save_as(&mut self) {
        self.stop_playing();
        if let Some(path) = save::choose_path(&self.edit.source) {
            if export::file_dialog_available() {
                self.save_to(&path);
            } else {
                self.path_prompt = Some(PathPrompt::new(PromptFor::SaveAs, Some(&path)));
            }
        }
    }

    /// Saves to `path`; the saved file becomes the scene's source.
    pub fn save_to(&mut self, path: &Path) {
        match save::save(&self.edit, &self.saved, path) {
            Ok(saved) => {
                let shown = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_owned());
                let name = saved.scene.name.clone();
                self.edit.loaded = Arc::new(saved.scene);
                self.edit.source = SceneSource::File(path.to_owned());
                // The scene text exports record is now the saved file's
                // (no re-render: the picture is the same).
                let scene = Arc::make_mut(&mut self.edit.scene);
                scene.source_text = Arc::clone(&self.edit.loaded.source_text);
                scene.name = name;
                let mut baseline = self.edit.snapshot();
                // What the file holds is saved; edits it could not hold
                // stay marked (the camera is compared as edited: an NFF
                // angle may round the field of view in its last bit).
                let reloaded = Arc::clone(&self.edit.loaded);
                if reloaded.lights.len() == baseline.lights.len() {
                    baseline.lights.clone_from(&reloaded.lights);
                }
                if reloaded.materials.len() == baseline.materials.len() {
                    baseline.materials.clone_from(&reloaded.materials);
                } else if let Err(e) = self.install_scene((*reloaded).clone(), false) {
                    // NFF made equal materials one: the saved scene, which
                    // renders the same, is the one to go on editing.
                    self.say(format!("cannot show the saved scene: {e:#}"), true);
                } else {
                    baseline = self.edit.snapshot();
                }
                // Settings the file cannot hold keep the file's value in
                // the baseline, so they stay marked unsaved.
                let file = reloaded.render_settings();
                let b = &mut baseline.settings;
                for what in &saved.left_out {
                    match what {
                        LeftOut::Samples => (b.samples, b.adaptive) = (file.samples, file.adaptive),
                        LeftOut::MaxDepth => b.max_depth = file.max_depth,
                        LeftOut::Colors => b.colors = file.colors,
                        LeftOut::Sides => b.sides = file.sides,
                        LeftOut::OctreeSwitch => b.accel = file.accel,
                        LeftOut::OctreeParams => baseline.octree = reloaded.octree_params,
                        LeftOut::CameraPath => {
                            baseline.camera_path.clone_from(&reloaded.camera_path)
                        }
                        // Material edits left out are told, not undone: the
                        // materials came back from the file above.
                        LeftOut::Reflectivity { .. }
                        | LeftOut::EqualMaterial { .. }
                        | LeftOut::Material { .. } => {}
                    }
                }
                if saved.left_out.is_empty() {
                    self.say(format!("saved {}", shown.display()), false);
                } else {
                    self.say(
                        format!(
                            "saved {}, without {}: the file's format has no place for them (export a PNG to keep them)",
                            shown.display(),
                            saved
                                .left_out
                                .iter()
                                .map(LeftOut::to_string)
                                .collect::<Vec<_>>()
                                .join(", ")
                        ),
                        true,
                    );
                }
                self.saved = baseline;
            }
            Err(e) => self.say(format!("cannot save {}: {e:#}", path.display()), true),
        }
    }

    /// Re-reads the scene file, keeping the camera; a failure keeps the
    /// current scene on screen.
    pub fn reload(&mut self) {
        match self
            .edit
            .source
            .load()
            .and_then(|scene| self.install_scene(scene, false))
        {
            Ok(()) => {
                // The camera stays where the user put it, which the file
                // may not say.
                self.saved = Snapshot {
                    camera: self.edit.loaded.camera,
                    ..self.edit.snapshot()
                };
                self.say(format!("reloaded {}", self.edit.scene.name), false)
            }
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
                self.edit.source = source;
                self.saved = self.edit.snapshot();
                self.say(format!("opened {}", self.edit.scene.name), false);
                for note in self.edit.scene.notes() {
                    self.say(format!("note: {note}"), false);
                }
            }
            Err(e) => self.say(format!("cannot open: {e:#}"), true),
        }
    }

    pub(super) fn install_scene(&mut self, scene: Scene, take_camera: bool) -> anyhow::Result<()> {
        let (octree, seconds) = build_octree(&scene)?;
        let edit = &mut self.edit;
        if take_camera {
            edit.camera = scene.camera;
            // The new scene's own settings (its colour convention among
            // them), keeping the view, the accelerator and the protocol.
            edit.settings = RenderSettings {
                view: edit.settings.view,
                accel: edit.settings.accel,
                ..scene.render_settings()
            }
            .with_protocol(edit.settings.protocol);
        }
        edit.camera_path.clone_from(&scene.camera_path);
        edit.loaded = Arc::new(scene.clone());
        edit.scene = Arc::new(scene);
        edit.scene_version += 1;
        // Undo does not reach into another scene (or an earlier version
        // of this one).
        self.undoer = Default::default();
        self.octree = Arc::new(octree);
        self.build_seconds = seconds;
        // Measured again on the new scene once it has rendered.
        self.unit_costs = None;
        Ok(())
    }

    pub(super) fn open_dialog(&mut self) {
        if !export::file_dialog_available() {
            // A path field instead (Xvfb, minimal desktops).
            self.path_prompt = Some(PathPrompt::new(PromptFor::Open, None));
            return;
        }
        if let Some(path) = rfd::FileDialog::new()
            .add_filter("scenes and models", &["toml", "nff", "obj"])
            .pick_file()
        {
            self.open_asking_first(path);
        }
    }

    fn open_asking_first(&mut self, path: PathBuf) {
        if self.unsaved() {
            self.discarding = Some(Discarding::Open(path));
        } else {
            self.open(path);
        }
    }

    /// Writes the displayed frame to a PNG chosen in a save dialog, or,
    /// where no dialog is available, named in a path field filled in with
    /// a timestamped name where exports go (`export::choose_path`).
    pub fn export(&mut self) {
        let Some(path) = export::choose_path(&self.edit.source) else {
            return;
        };
        if export::file_dialog_available() {
            self.export_at(path);
        } else {
            // A field filled in with the name chosen, so another can be given.
            let prompt = PathPrompt::new(PromptFor::Export, Some(&path));
            self.path_prompt = Some(prompt);
        }
    }

    /// Exports to `path` and says where it went.
    pub(super) fn export_at(&mut self, path: PathBuf) {
        match self.export_to(&path) {
            Ok(()) => {
                let shown = std::path::absolute(&path).unwrap_or(path);
                self.say(format!("exported {}", shown.display()), false)
            }
            Err(e) => self.say(format!("export to {} failed: {e:#}", path.display()), true),
        }
    }

    /// Where no file dialog is available: a field for the path to open,
    /// save as or export to (the latter two filled in with the name glint
    /// would choose), checked before it is used.
    pub(super) fn path_prompt_ui(&mut self, ctx: &egui::Context) {
        let Some(prompt) = &mut self.path_prompt else {
            return;
        };
        let mut chosen = None;
        let mut cancel = false;
        let (heading, ask, button, hint) = match prompt.purpose {
            PromptFor::Open => (
                "Open a scene",
                "Type the path of a scene (.toml, .nff or .obj):",
                "Open",
                "scenes/glass.toml",
            ),
            PromptFor::SaveAs => (
                "Save the scene as",
                "Type the path of the new scene file (.toml, or .nff for an NFF scene):",
                "Save",
                "my-scene.toml",
            ),
            PromptFor::Export => (
                "Export the image",
                "Type the path of the PNG to write:",
                "Export",
                "picture.png",
            ),
        };
        egui::Modal::new(egui::Id::unique("path-prompt")).show(ctx, |ui| {
            ui.heading(heading);
            ui.label(format!(
                "No file dialog is available here (no desktop portal). {ask}"
            ));
            if let Ok(dir) = std::env::current_dir() {
                ui.weak(format!("relative to {}", dir.display()));
            }
            let field = ui.add(
                egui::TextEdit::singleline(&mut prompt.text)
                    .desired_width(520.0)
                    .hint_text(hint),
            );
            if !prompt.focused {
                field.request_focus();
                prompt.focused = true;
            }
            let entered = field.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
            if let Some(error) = &prompt.error {
                ui.colored_label(ui.visuals().error_fg_color, error);
            }
            ui.horizontal(|ui| {
                if ui.button(button).clicked() || entered {
                    chosen = Some(PathBuf::from(prompt.text.trim()));
                }
                if ui.button("Cancel").clicked() || ui.input(|i| i.key_pressed(egui::Key::Escape)) {
                    cancel = true;
                }
            });
        });
        if cancel {
            self.path_prompt = None;
            return;
        }
        let Some(path) = chosen else { return };
        let purpose = prompt.purpose;
        let folder = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_owned(),
            _ => PathBuf::from("."),
        };
        let refusal = if path.as_os_str().is_empty() {
            Some("type a path".to_owned())
        } else if purpose == PromptFor::Open && !path.is_file() {
            Some(format!("{}: no such file", path.display()))
        } else if purpose != PromptFor::Open && !folder.is_dir() {
            Some(format!("{}: no such folder", folder.display()))
        } else if purpose != PromptFor::Open && path.is_dir() {
            Some(format!("{} is a folder: add a file name", path.display()))
        } else {
            None
        };
        if let Some(error) = refusal {
            if let Some(prompt) = &mut self.path_prompt {
                prompt.error = Some(error);
                prompt.focused = false;
            }
            return;
        }
        self.path_prompt = None;
        match purpose {
            PromptFor::Open => self.open_asking_first(path),
            PromptFor::SaveAs => self.save_to(&path),
            PromptFor::Export => self.export_at(path),
        }
    }
}

/// What a path field asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum PromptFor {
    Open,
    SaveAs,
    Export,
}

/// The path field shown for Open, Save as and Export where no file dialog
/// is available.
#[derive(Debug)]
pub(super) struct PathPrompt {
    purpose: PromptFor,
    text: String,
    /// Why the last path was refused.
    error: Option<String>,
    /// Focus was given to the field (once, so a click elsewhere stays).
    focused: bool,
}

impl PathPrompt {
    /// A field for `purpose`, filled in with `path` (empty for Open).
    pub(super) fn new(purpose: PromptFor, path: Option<&Path>) -> Self {
        Self {
            purpose,
            text: path.map(|p| p.display().to_string()).unwrap_or_default(),
            error: None,
            focused: false,
        }
    }
}
