//! The app's side of the camera path: recording camera moves as
//! keyframes, playing the path back with the preview budget of a drag,
//! and the panel's edits.

use super::GlintApp;
use crate::camera_path::Keyframe;
use crate::viewer::command::PathCommand;
use crate::viewer::path_panel::{self, PathPlayer, RECORD_INTERVAL};

impl GlintApp {
    /// The camera path as edited.
    pub fn camera_path(&self) -> Option<&crate::camera_path::CameraPath> {
        self.edit.camera_path.as_ref()
    }

    pub fn is_recording_path(&self) -> bool {
        self.path_player.is_recording()
    }

    pub fn is_playing_path(&self) -> bool {
        self.path_player.is_playing()
    }

    pub(super) fn path_command(&mut self, command: PathCommand, ctx: &egui::Context) {
        let now = ctx.input(|i| i.time);
        let edit = &mut self.edit;
        match command {
            // Playing moves the camera: what it would record is the path.
            PathCommand::ToggleRecording if self.path_player.is_playing() => {}
            PathCommand::ToggleRecording => {
                self.path_player = if self.path_player.is_recording() {
                    PathPlayer::Idle
                } else {
                    // The camera as it is is the first key of the recording.
                    let offset = path_panel::next_key_time(edit.camera_path.as_ref());
                    let key = Keyframe {
                        time: offset,
                        camera: edit.camera,
                    };
                    edit.camera_path = path_panel::appended(edit.camera_path.as_ref(), key)
                        .or(edit.camera_path.take());
                    PathPlayer::Recording {
                        started: now,
                        offset,
                    }
                };
            }
            PathCommand::TogglePlaying => {
                self.path_player = match &self.path_player {
                    PathPlayer::Playing { camera_before, .. } => {
                        edit.camera = *camera_before;
                        PathPlayer::Idle
                    }
                    _ if edit.camera_path.is_some() => PathPlayer::Playing {
                        started: now,
                        camera_before: edit.camera,
                    },
                    other => other.clone(),
                };
            }
            PathCommand::AddKeyframe if !self.path_player.is_playing() => {
                let key = Keyframe {
                    time: path_panel::next_key_time(edit.camera_path.as_ref()),
                    camera: edit.camera,
                };
                if let Some(path) = path_panel::appended(edit.camera_path.as_ref(), key) {
                    edit.camera_path = Some(path);
                }
            }
            PathCommand::AddKeyframe => {}
            PathCommand::Delete(index) => {
                if let Some(path) = &edit.camera_path {
                    edit.camera_path = path_panel::without(path, index);
                }
            }
            PathCommand::Clear => {
                edit.camera_path = None;
                if self.path_player.is_playing() {
                    self.path_command(PathCommand::TogglePlaying, ctx);
                }
            }
        }
    }

    /// Stops a playback, putting the camera back where it was (before a
    /// save, which would otherwise write a camera half way along the path).
    pub(super) fn stop_playing(&mut self) {
        if let PathPlayer::Playing { camera_before, .. } = self.path_player {
            self.edit.camera = camera_before;
            self.path_player = PathPlayer::Idle;
        }
    }

    /// Once a frame: a recording keeps camera moves (at most one key every
    /// [`RECORD_INTERVAL`]); a playback moves the camera along the path
    /// and renders it as a drag does (previews), then puts it back.
    pub(super) fn path_logic(&mut self, ctx: &egui::Context) {
        let now = ctx.input(|i| i.time);
        match self.path_player.clone() {
            PathPlayer::Idle => return,
            PathPlayer::Recording { started, offset } => {
                let time = offset + (now - started);
                let edit = &mut self.edit;
                let last = edit
                    .camera_path
                    .as_ref()
                    .map(|p| p.keys()[p.keys().len() - 1]);
                let due = last.is_none_or(|k| time - k.time >= RECORD_INTERVAL);
                let moved = last.is_none_or(|k| k.camera != edit.camera);
                if due && moved {
                    let key = Keyframe {
                        time,
                        camera: edit.camera,
                    };
                    if let Some(path) = path_panel::appended(edit.camera_path.as_ref(), key) {
                        edit.camera_path = Some(path);
                    }
                }
            }
            PathPlayer::Playing {
                started,
                camera_before,
            } => {
                let Some(path) = &self.edit.camera_path else {
                    // The path was deleted (or undone) while playing.
                    self.edit.camera = camera_before;
                    self.path_player = PathPlayer::Idle;
                    return;
                };
                let t = now - started;
                if t > path.duration() {
                    self.edit.camera = camera_before;
                    self.path_player = PathPlayer::Idle;
                } else {
                    self.edit.camera = path.at(path.start() + t);
                    // A moving camera: the drag's previews, not full passes.
                    self.dragging = true;
                }
            }
        }
        self.path_status_ui(ctx, now);
        ctx.request_repaint();
    }

    /// The recording or playback shown over the image's top-left corner.
    fn path_status_ui(&self, ctx: &egui::Context, now: f64) {
        let (Some(rect), Some(text)) = (
            self.image_rect,
            path_panel::status_text(&self.path_player, self.edit.camera_path.as_ref(), now),
        ) else {
            return;
        };
        let painter = ctx.layer_painter(egui::LayerId::new(
            egui::Order::Foreground,
            egui::Id::unique("camera path status"),
        ));
        let galley =
            painter.layout_no_wrap(text, egui::FontId::proportional(18.0), egui::Color32::WHITE);
        let at = rect.min + egui::vec2(10.0, 10.0);
        let back = egui::Rect::from_min_size(at, galley.size()).expand(6.0);
        painter.rect_filled(
            back,
            4.0,
            egui::Color32::from_rgba_unmultiplied(180, 30, 30, 210),
        );
        painter.galley(at, galley, egui::Color32::WHITE);
    }
}
