//! The camera path in the viewer: record the camera while orbiting, play
//! the path back, add and delete keyframes. The path itself is part of
//! what the user edits ([`EditState::camera_path`]: undo, the unsaved mark
//! and "Save scene" cover it); recording and playing are runtime state.

use egui::{Color32, RichText};

use super::command::{Command, PathCommand};
use super::state::EditState;
use crate::camera::CameraSpec;
use crate::camera_path::{CameraPath, Keyframe};

/// Least time between two recorded keyframes (seconds): denser keys add
/// nothing the spline does not already give.
pub const RECORD_INTERVAL: f64 = 0.25;
/// The time a keyframe added by hand comes after the path's last one.
pub const ADDED_KEY_SPACING: f64 = 1.0;

/// Whether the path is being recorded or played, since when.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum PathPlayer {
    #[default]
    Idle,
    /// Camera moves become keyframes: `offset` is the path time of
    /// `started` (the UI clock's seconds when recording began).
    Recording { started: f64, offset: f64 },
    /// The camera follows the path from `started`; it goes back to
    /// `camera_before` when playback ends.
    Playing {
        started: f64,
        camera_before: CameraSpec,
    },
}

impl PathPlayer {
    pub fn is_recording(&self) -> bool {
        matches!(self, PathPlayer::Recording { .. })
    }

    pub fn is_playing(&self) -> bool {
        matches!(self, PathPlayer::Playing { .. })
    }
}

/// `path` with `key` appended after its last keyframe (a new path when
/// there is none). `key.time` must come after the last key's.
pub fn appended(path: Option<&CameraPath>, key: Keyframe) -> Option<CameraPath> {
    let mut keys = path.map(|p| p.keys().to_vec()).unwrap_or_default();
    keys.push(key);
    CameraPath::new(keys).ok()
}

/// `path` without keyframe `index` (none left: no path).
pub fn without(path: &CameraPath, index: usize) -> Option<CameraPath> {
    let mut keys = path.keys().to_vec();
    if index < keys.len() {
        keys.remove(index);
    }
    CameraPath::new(keys).ok()
}

/// The time of a keyframe added now: after the last one, or 0.
pub fn next_key_time(path: Option<&CameraPath>) -> f64 {
    path.map_or(0.0, |p| {
        p.keys()[p.keys().len() - 1].time + ADDED_KEY_SPACING
    })
}

/// The panel: what the path holds, the record and play buttons, and the
/// keyframes with their delete buttons.
pub fn path_ui(edit: &EditState, player: &PathPlayer, now: f64, ui: &mut egui::Ui) -> Vec<Command> {
    let mut commands = Vec::new();
    let path = edit.camera_path.as_ref();
    ui.label(match path {
        Some(p) => format!("{} keyframes over {:.2} s", p.keys().len(), p.duration()),
        None => "No camera path: record one while orbiting, or add keyframes.".into(),
    });
    ui.horizontal(|ui| {
        let record = if player.is_recording() {
            RichText::new("Stop recording (Ctrl+R)").color(Color32::from_rgb(220, 60, 50))
        } else {
            RichText::new("Record (Ctrl+R)")
        };
        if ui
            .add_enabled(!player.is_playing(), egui::Button::new(record))
            .on_hover_text(
                "While recording, every camera move becomes a keyframe (at most four a \
                 second), after the path's last one",
            )
            .clicked()
        {
            commands.push(Command::CameraPath(PathCommand::ToggleRecording));
        }
        let play = if player.is_playing() {
            "Stop (P)"
        } else {
            "Play (P)"
        };
        if ui
            .add_enabled(
                path.is_some() && !player.is_recording(),
                egui::Button::new(play),
            )
            .on_hover_text("The camera follows the path in real time, then goes back")
            .clicked()
        {
            commands.push(Command::CameraPath(PathCommand::TogglePlaying));
        }
    });
    if let Some(status) = status_text(player, path, now) {
        ui.label(RichText::new(status).color(Color32::from_rgb(220, 60, 50)));
    }
    ui.horizontal(|ui| {
        if ui
            .add_enabled(!player.is_playing(), egui::Button::new("Add keyframe (K)"))
            .on_hover_text(format!(
                "The camera as it is now, {ADDED_KEY_SPACING} s after the last keyframe"
            ))
            .clicked()
        {
            commands.push(Command::CameraPath(PathCommand::AddKeyframe));
        }
        if ui
            .add_enabled(path.is_some(), egui::Button::new("Delete path"))
            .clicked()
        {
            commands.push(Command::CameraPath(PathCommand::Clear));
        }
    });
    if let Some(p) = path {
        egui::ScrollArea::vertical()
            .id_salt("keyframes")
            .max_height(140.0)
            .show(ui, |ui| {
                egui::Grid::new("keyframes").striped(true).show(ui, |ui| {
                    for (i, k) in p.keys().iter().enumerate() {
                        ui.label(format!("{:.2} s", k.time));
                        let e = k.camera.eye;
                        ui.label(format!("eye {:.2} {:.2} {:.2}", e.x, e.y, e.z))
                            .on_hover_text(format!(
                                "lookat {:.3}\nup {:.3}\nfov {:.1}°",
                                k.camera.lookat, k.camera.up, k.camera.fov
                            ));
                        if ui
                            .small_button("Delete")
                            .on_hover_text("Delete this keyframe")
                            .clicked()
                        {
                            commands.push(Command::CameraPath(PathCommand::Delete(i)));
                        }
                        ui.end_row();
                    }
                });
            });
        ui.label(
            RichText::new("glint render SCENE --path -o frames/f_####.png renders it").small(),
        );
    }
    commands
}

/// What the recording or the playback is doing, in a few words.
pub fn status_text(player: &PathPlayer, path: Option<&CameraPath>, now: f64) -> Option<String> {
    match player {
        PathPlayer::Idle => None,
        PathPlayer::Recording { started, offset } => Some(format!(
            "REC {:.1} s, {} keyframes",
            offset + (now - started),
            path.map_or(0, |p| p.keys().len())
        )),
        PathPlayer::Playing { started, .. } => {
            let duration = path.map_or(0.0, CameraPath::duration);
            Some(format!(
                "Playing {:.1} / {duration:.1} s",
                (now - started).min(duration)
            ))
        }
    }
}

/// The shortcuts: Ctrl+R records, P plays, K adds a keyframe (not while
/// typing in a field).
pub fn shortcuts(ctx: &egui::Context, typing: bool) -> Vec<Command> {
    use egui::{Key, KeyboardShortcut, Modifiers};
    let mut commands = Vec::new();
    if ctx.input_mut(|i| i.consume_shortcut(&KeyboardShortcut::new(Modifiers::COMMAND, Key::R))) {
        commands.push(Command::CameraPath(PathCommand::ToggleRecording));
    }
    if !typing {
        ctx.input(|i| {
            if i.modifiers.is_none() && i.key_pressed(Key::P) {
                commands.push(Command::CameraPath(PathCommand::TogglePlaying));
            }
            if i.modifiers.is_none() && i.key_pressed(Key::K) {
                commands.push(Command::CameraPath(PathCommand::AddKeyframe));
            }
        });
    }
    commands
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::DVec3;

    fn key(time: f64, x: f64) -> Keyframe {
        Keyframe {
            time,
            camera: CameraSpec {
                eye: DVec3::new(x, 0.0, 5.0),
                lookat: DVec3::ZERO,
                up: DVec3::Y,
                fov: 40.0,
            },
        }
    }

    #[test]
    fn keys_append_after_the_last_and_deleting_the_last_leaves_no_path() {
        assert_eq!(next_key_time(None), 0.0);
        let one = appended(None, key(0.0, 0.0)).unwrap();
        assert_eq!(next_key_time(Some(&one)), ADDED_KEY_SPACING);
        let two = appended(Some(&one), key(1.0, 1.0)).unwrap();
        assert_eq!(two.keys().len(), 2);
        // Not after the last key: refused.
        assert!(appended(Some(&two), key(0.5, 2.0)).is_none());
        assert_eq!(without(&two, 0).unwrap().keys()[0], key(1.0, 1.0));
        assert!(without(&one, 0).is_none());
    }
}
