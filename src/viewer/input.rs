//! Keyboard and mouse: shortcuts become commands; over the image, the left
//! button orbits, the right or middle one pans, the wheel dollies, and a
//! click in inspect mode (or Ctrl+click) picks a pixel.

use egui::{Key, KeyboardShortcut, Modifiers, PointerButton};

use super::command::Command;
use super::orbit;
use crate::camera::CameraSpec;

/// Keyboard shortcuts; R, undo and redo only when no text field has the
/// focus (a field being typed in has its own undo).
pub fn shortcuts(ctx: &egui::Context) -> Vec<Command> {
    let mut commands = Vec::new();
    let command_shift = Modifiers::COMMAND | Modifiers::SHIFT;
    // A shortcut with Shift comes before the same one without: egui
    // matches Ctrl+S on Ctrl+Shift+S too.
    let mut table = vec![
        (
            KeyboardShortcut::new(Modifiers::COMMAND, Key::O),
            Command::Open,
        ),
        (
            KeyboardShortcut::new(command_shift, Key::S),
            Command::SaveAs,
        ),
        (
            KeyboardShortcut::new(Modifiers::COMMAND, Key::S),
            Command::Save,
        ),
        (
            KeyboardShortcut::new(Modifiers::COMMAND, Key::E),
            Command::Export,
        ),
        (
            KeyboardShortcut::new(Modifiers::NONE, Key::F5),
            Command::Reload,
        ),
    ];
    let typing = ctx.egui_wants_keyboard_input();
    if !typing {
        table.extend([
            (KeyboardShortcut::new(command_shift, Key::Z), Command::Redo),
            (
                KeyboardShortcut::new(Modifiers::COMMAND, Key::Y),
                Command::Redo,
            ),
            (
                KeyboardShortcut::new(Modifiers::COMMAND, Key::Z),
                Command::Undo,
            ),
        ]);
    }
    ctx.input_mut(|i| {
        for (shortcut, command) in table {
            if i.consume_shortcut(&shortcut) {
                commands.push(command);
            }
        }
    });
    if !typing && ctx.input(|i| i.key_pressed(Key::R) && i.modifiers.is_none()) {
        commands.push(Command::ResetCamera);
    }
    commands.extend(super::path_panel::shortcuts(ctx, typing));
    commands
}

/// The camera after this frame's drags and wheel over the image drawn
/// `height_points` tall, and whether a drag moved it.
pub fn camera_control(
    ui: &egui::Ui,
    response: &egui::Response,
    camera: &CameraSpec,
    height_points: f32,
) -> (CameraSpec, bool) {
    let delta = response.drag_delta();
    let scale = 1.0 / height_points.max(1.0) as f64;
    let mut camera = *camera;
    let mut moved = false;
    if response.dragged_by(PointerButton::Primary) && delta != egui::Vec2::ZERO {
        // A drag across the image's height turns the camera three radians.
        camera = orbit::orbit(
            &camera,
            -delta.x as f64 * scale * 3.0,
            delta.y as f64 * scale * 3.0,
        );
        moved = true;
    }
    if (response.dragged_by(PointerButton::Secondary) || response.dragged_by(PointerButton::Middle))
        && delta != egui::Vec2::ZERO
    {
        camera = orbit::pan(
            &camera,
            delta.x as f64,
            delta.y as f64,
            height_points as f64,
        );
        moved = true;
    }
    if response.hovered() {
        let scroll = ui.input(|i| i.smooth_scroll_delta.y);
        if scroll != 0.0 {
            camera = orbit::dolly(&camera, scroll as f64 * 0.002);
        }
    }
    (camera, moved)
}

/// The pixel of a `width` x `height` image drawn in `image_rect` that was
/// clicked to inspect it: in inspect mode any click, otherwise Ctrl+click.
pub fn picked_pixel(
    ui: &egui::Ui,
    response: &egui::Response,
    image_rect: egui::Rect,
    (width, height): (u32, u32),
    inspect_mode: bool,
) -> Option<(u32, u32)> {
    if !response.clicked() || !(inspect_mode || ui.input(|i| i.modifiers.command)) {
        return None;
    }
    let pos = response.interact_pointer_pos()?;
    image_rect
        .contains(pos)
        .then(|| pixel_at(image_rect, (width, height), pos))
}

/// The pixel under screen point `pos` of an image drawn in `image_rect`.
pub fn pixel_at(
    image_rect: egui::Rect,
    (width, height): (u32, u32),
    pos: egui::Pos2,
) -> (u32, u32) {
    let x = (pos.x - image_rect.min.x) / image_rect.width() * width as f32;
    let y = (pos.y - image_rect.min.y) / image_rect.height() * height as f32;
    // The far edges belong to the last pixel.
    (
        (x.max(0.0) as u32).min(width.saturating_sub(1)),
        (y.max(0.0) as u32).min(height.saturating_sub(1)),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn screen_points_map_to_the_pixel_under_them() {
        // An 80x60 image drawn twice its size at (100, 50).
        let rect = egui::Rect::from_min_size(egui::pos2(100.0, 50.0), egui::vec2(160.0, 120.0));
        let at = |x, y| pixel_at(rect, (80, 60), egui::pos2(x, y));
        assert_eq!(at(100.0, 50.0), (0, 0));
        assert_eq!(at(101.9, 51.9), (0, 0));
        assert_eq!(at(102.0, 52.0), (1, 1));
        assert_eq!(at(100.0 + 2.0 * 40.5, 50.0 + 2.0 * 30.5), (40, 30));
        assert_eq!(at(260.0, 170.0), (79, 59), "the far corner");
    }
}
