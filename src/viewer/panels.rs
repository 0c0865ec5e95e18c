//! The viewer's panels. Each `*_ui` function draws one panel from the
//! state it is given: it edits plain state (settings, camera, lights) in
//! place and returns the actions the user asked for as [`Command`]s, which
//! the app applies after the frame.

use egui::{Color32, DragValue, RichText};

use super::command::Command;
use super::inspect::InspectState;
use super::state::EditState;
use super::worker::{Preview, Worker};
use crate::accel::Octree;
use crate::color::ColorConvention;
use crate::math::DVec3;
use crate::settings::{Accel, AntiAliasing, Protocol, Sides, ViewMode};

/// A message shown in the status bar.
#[derive(Clone, Debug)]
pub struct Message {
    pub text: String,
    pub is_error: bool,
}

/// What the timing and status panels report besides the edited state.
pub struct RenderInfo<'a> {
    pub worker: &'a Worker,
    pub octree: &'a Octree,
    pub build_seconds: f64,
    /// The BVH and its build's seconds, once one was asked for.
    pub bvh: Option<(&'a crate::accel::Bvh, f64)>,
    /// The preview chosen for the last drag, and its estimated seconds.
    pub last_preview: Option<(Preview, f64)>,
    pub message: Option<&'a Message>,
}

/// What the menu bar shows besides its commands.
pub struct MenuState<'a> {
    pub scene_name: &'a str,
    pub unsaved: bool,
    pub can_undo: bool,
    pub can_redo: bool,
}

pub fn menu_ui(
    state: &MenuState,
    magnification: &mut super::state::Magnification,
    ui: &mut egui::Ui,
) -> Vec<Command> {
    let mut commands = Vec::new();
    let mut item = |ui: &mut egui::Ui, enabled: bool, label: &str, command: Command| {
        if ui.add_enabled(enabled, egui::Button::new(label)).clicked() {
            commands.push(command);
            ui.close();
        }
    };
    egui::MenuBar::new().ui(ui, |ui| {
        ui.menu_button("File", |ui| {
            item(ui, true, "Open scene…  (Ctrl+O)", Command::Open);
            item(ui, true, "Reload  (F5)", Command::Reload);
            ui.separator();
            item(ui, true, "Save scene  (Ctrl+S)", Command::Save);
            item(ui, true, "Save scene as…  (Ctrl+Shift+S)", Command::SaveAs);
            item(ui, true, "Export PNG…  (Ctrl+E)", Command::Export);
            ui.separator();
            item(ui, true, "Quit", Command::Quit);
        });
        ui.menu_button("Edit", |ui| {
            item(ui, state.can_undo, "Undo  (Ctrl+Z)", Command::Undo);
            item(ui, state.can_redo, "Redo  (Ctrl+Shift+Z)", Command::Redo);
        });
        ui.menu_button("View", |ui| {
            item(ui, true, "Reset camera  (R)", Command::ResetCamera);
            ui.separator();
            for m in super::state::Magnification::ALL {
                ui.radio_value(magnification, m, m.name());
            }
        });
        ui.separator();
        let name = if state.unsaved {
            format!("{} (edited, unsaved)", state.scene_name)
        } else {
            state.scene_name.to_owned()
        };
        ui.label(RichText::new(name).weak());
    });
    commands
}

fn vec3_ui(ui: &mut egui::Ui, label: &str, v: &mut DVec3, speed: f64) -> bool {
    let mut changed = false;
    ui.horizontal(|ui| {
        ui.label(label);
        for c in [&mut v.x, &mut v.y, &mut v.z] {
            changed |= ui
                .add(
                    DragValue::new(c)
                        .update_while_editing(false)
                        .speed(speed)
                        .max_decimals(4),
                )
                .changed();
        }
    });
    changed
}

fn color_ui(ui: &mut egui::Ui, label: &str, c: &mut DVec3) -> bool {
    // egui's picker edits linear RGB, as glint's colours are.
    let mut rgb = [c.x as f32, c.y as f32, c.z as f32];
    let mut changed = false;
    ui.horizontal(|ui| {
        ui.label(label);
        if ui
            .color_edit_button_rgb(&mut rgb)
            .accessible_name(label)
            .changed()
        {
            changed = true;
        }
    });
    if changed {
        *c = DVec3::new(rgb[0] as f64, rgb[1] as f64, rgb[2] as f64);
    }
    changed
}

/// Render settings, the inspection tools, camera, lights and materials.
pub fn controls_ui(
    edit: &mut EditState,
    inspect: &mut InspectState,
    worker: &Worker,
    (octree, (player, now)): (
        &super::octree_panel::OctreeInfo,
        (&super::path_panel::PathPlayer, f64),
    ),
    ui: &mut egui::Ui,
) -> Vec<Command> {
    let mut commands = Vec::new();
    egui::ScrollArea::vertical().show(ui, |ui| {
        let extent = edit.scene.extent_bounds().extent().max_element().max(1e-9);
        let speed = extent * 0.002;
        egui::CollapsingHeader::new("Render settings")
            .default_open(true)
            .show(ui, |ui| render_settings_ui(edit, ui));
        egui::CollapsingHeader::new("Inspect and compare")
            .default_open(true)
            .show(ui, |ui| {
                let label = edit.settings_label();
                commands.extend(super::inspect::inspect_controls_ui(
                    inspect, worker, &label, ui,
                ));
            });
        egui::CollapsingHeader::new("Octree parameters")
            .default_open(false)
            .show(ui, |ui| {
                commands.extend(super::octree_panel::octree_ui(
                    edit.scene.octree_params,
                    octree,
                    ui,
                ))
            });
        egui::CollapsingHeader::new("Camera")
            .default_open(true)
            .show(ui, |ui| commands.extend(camera_ui(edit, speed, ui)));
        egui::CollapsingHeader::new("Camera path")
            .default_open(true)
            .show(ui, |ui| {
                commands.extend(super::path_panel::path_ui(edit, player, now, ui))
            });
        egui::CollapsingHeader::new("Lights")
            .default_open(true)
            .show(ui, |ui| lights_ui(edit, speed, ui));
        ui.collapsing("Materials", |ui| materials_ui(edit, ui));
    });
    commands
}

/// Protocol, anti-aliasing, octree, depth, colours, sides, frame budget,
/// image size and view.
fn render_settings_ui(edit: &mut EditState, ui: &mut egui::Ui) {
    let spd = edit.settings.protocol == Protocol::Spd;
    ui.horizontal(|ui| {
            ui.label("Protocol");
            let mut protocol = edit.settings.protocol;
            for p in Protocol::ALL {
                ui.selectable_value(&mut protocol, p, p.name())
                    .on_hover_text(match p {
                        Protocol::Glint => "pixel centres (or the 4x4 grid with anti-aliasing)",
                        Protocol::Spd => "the SPD test protocol: rays through the pixel corners, depth 5, a reflection ray from every reflective or transmitting surface, opaque surfaces one-sided",
                    });
            }
            edit.settings = edit
                .settings
                .switch_protocol(protocol, &edit.scene.render_settings());
        });
    // Off keeps whether anti-aliasing is adaptive, for when it
    // is turned on again.
    let mut anti_aliasing = edit.settings.samples > 1;
    if ui
        .add_enabled(
            !spd,
            egui::Checkbox::new(&mut anti_aliasing, "Anti-aliasing (16 samples, 4x4 grid)"),
        )
        .changed()
    {
        edit.settings.samples = if anti_aliasing {
            AntiAliasing::SAMPLES
        } else {
            1
        };
    }
    ui.add_enabled(
        !spd && anti_aliasing,
        egui::Checkbox::new(
            &mut edit.settings.adaptive,
            "only where the picture needs it (adaptive)",
        ),
    )
    .on_hover_text(
        "trace every pixel's centre, then the 4x4 grid only where neighbours differ: \
             another material, a shadow edge, a visible contrast",
    );
    ui.horizontal(|ui| {
        ui.label("Accelerator");
        let mut accel = edit.settings.accel;
        for (choice, label, hover) in [
            (Accel::Octree, "Octree", "the octree: glint's default, and what the overlay and walk views show"),
            (Accel::Bvh, "BVH", "a bounding volume hierarchy, to compare: the same image, other build and render times"),
            (Accel::BruteForce, "None", "no accelerator: every ray tests every shape"),
        ] {
            ui.selectable_value(&mut accel, choice, label)
                .on_hover_text(hover);
        }
        if accel != edit.settings.accel {
            edit.settings.accel = accel;
        }
    });
    ui.horizontal(|ui| {
        ui.label("Max depth");
        ui.add_enabled(
            !spd,
            DragValue::new(&mut edit.settings.max_depth)
                .update_while_editing(false)
                .range(1..=crate::limits::MAX_RAY_DEPTH),
        );
    });
    ui.horizontal(|ui| {
        ui.label("Colours");
        for c in ColorConvention::ALL {
            ui.selectable_value(&mut edit.settings.colors, c, c.name())
                .on_hover_text(match c {
                    ColorConvention::Linear => "shade in linear light, show sRGB-encoded",
                    ColorConvention::Display => {
                        "shade display values, show them unchanged (the SPD's pictures)"
                    }
                });
        }
    });
    ui.horizontal(|ui| {
            ui.label("Sides");
            for side in Sides::ALL {
                ui.selectable_value(&mut edit.settings.sides, side, side.name())
                    .on_hover_text(match side {
                        Sides::Two => "every surface seen from both sides",
                        Sides::One => "opaque surfaces seen from outside only (patches with vertex normals stay two-sided)",
                    });
            }
        });
    if !edit.scene.textures.is_empty() {
        let images = edit.scene.textures.len();
        ui.checkbox(
            &mut edit.settings.textures,
            format!(
                "Textures ({images} image{})",
                if images == 1 { "" } else { "s" }
            ),
        )
        .on_hover_text(
            "draw the materials' image textures and their cut-outs; off, each textured \
             material shows its own colour and its cut-out parts are solid, to compare",
        );
    }
    ui.horizontal(|ui| {
        ui.label("Frame budget while moving");
        ui.add(
            DragValue::new(&mut edit.frame_budget_ms)
                .update_while_editing(false)
                .range(5.0..=1000.0)
                .speed(1.0)
                .suffix(" ms"),
        )
        .on_hover_text(
            "while you drag, each preview fits this time: the shaded view moves the last \
                 picture's points into the new view and spends what that leaves of three \
                 quarters of it on fresh rays where the picture needs them most (the render \
                 cache, a point for every pixel or every 2x2 to 4x4 pixels as the time allows); \
                 the other views render the best \
                 reduced preview estimated to fit: full resolution, then 1/2, 1/4, 1/8, each \
                 complete, then with one bounce of reflection, then without reflections, then \
                 without shadows too",
        );
    });
    ui.checkbox(
        &mut edit.show_sources,
        "While moving, show where pixels come from",
    )
    .on_hover_text(
        "colour each pixel of the moving picture by its source: a fresh ray (green), a \
             point reused from earlier frames (blue when new, violet when old), a point an edit \
             changed and not yet traced again (orange), or filled from its neighbours (red)",
    );
    image_size_ui(edit, ui);
    ui.horizontal_wrapped(|ui| {
        ui.label("View");
        for v in ViewMode::ALL {
            ui.selectable_value(&mut edit.settings.view, v, v.name());
        }
    });
}

/// Eye, lookat, up and fov; only cameras the renderer accepts are applied.
fn camera_ui(edit: &mut EditState, speed: f64, ui: &mut egui::Ui) -> Vec<Command> {
    let mut commands = Vec::new();
    let mut c = edit.camera;
    vec3_ui(ui, "eye", &mut c.eye, speed);
    vec3_ui(ui, "lookat", &mut c.lookat, speed);
    vec3_ui(ui, "up", &mut c.up, 0.01);
    ui.horizontal(|ui| {
        ui.label("fov");
        ui.add(
            DragValue::new(&mut c.fov)
                .update_while_editing(false)
                .range(0.01..=179.0)
                .speed(0.1)
                .suffix("°"),
        );
    });
    // Apply only cameras the renderer accepts (up not parallel to the view).
    if c != edit.camera && crate::camera::Camera::new(&c, 2, 2).is_ok() {
        edit.camera = c;
    }
    if ui.button("Reset camera (R)").clicked() {
        commands.push(Command::ResetCamera);
    }
    commands
}

/// Every light's position and colour.
fn lights_ui(edit: &mut EditState, speed: f64, ui: &mut egui::Ui) {
    for i in 0..edit.scene.lights.len() {
        let mut light = edit.scene.lights[i].clone();
        ui.label(format!("Light {}", i + 1));
        let mut changed = vec3_ui(ui, "position", &mut light.position, speed);
        changed |= color_ui(ui, "colour", &mut light.color);
        if changed {
            edit.scene_mut().lights[i] = light;
        }
        ui.separator();
    }
}

/// A number field held to `range` (the scene files' limit): a value typed
/// or dragged past it is brought back to its end, and the field says so
/// beside it ("2 is past 0 to 1: 1 kept") until the next edit. Returns
/// whether the value changed.
fn bounded_value_ui(
    ui: &mut egui::Ui,
    salt: impl std::hash::Hash + std::fmt::Debug,
    value: &mut f64,
    range: std::ops::RangeInclusive<f64>,
    step: f64,
) -> bool {
    let id = ui.scope_id().with(("bounded", salt));
    let response = ui
        .add(
            DragValue::new(value)
                .update_while_editing(false)
                .speed(step),
        )
        .on_hover_text(format!(
            "from {} to {}, as scene files allow",
            range.start(),
            range.end()
        ));
    if response.changed() {
        let note = clamp_note(value, &range);
        ui.data_mut(|d| match note {
            Some(n) => {
                d.insert_temp(id, n);
            }
            None => d.remove::<String>(id),
        });
    }
    match ui.data(|d| d.get_temp::<String>(id)) {
        Some(note) => {
            ui.colored_label(ui.visuals().warn_fg_color, note);
        }
        None => {
            ui.label("");
        }
    }
    response.changed()
}

/// `value` brought into `range` if it lies past it (or is not a number),
/// and the words that say so.
fn clamp_note(value: &mut f64, range: &std::ops::RangeInclusive<f64>) -> Option<String> {
    if range.contains(value) {
        return None;
    }
    let asked = *value;
    *value = if asked > *range.end() {
        *range.end()
    } else {
        *range.start()
    };
    Some(format!(
        "{asked} is past {} to {}: {} kept",
        range.start(),
        range.end(),
        value
    ))
}

/// Every material's colour and coefficients, within the ranges scene files
/// are held to.
fn materials_ui(edit: &mut EditState, ui: &mut egui::Ui) {
    // NFF weights the ambient term by Kd: an edit keeps them together, as
    // the saved file will.
    let ka_follows_kd = super::save::is_nff(&edit.source);
    for i in 0..edit.scene.materials.len() {
        let mut m = edit.scene.materials[i].clone();
        let mut changed = false;
        egui::CollapsingHeader::new(&m.name)
            .id_salt(("material", i))
            .show(ui, |ui| {
                changed |= color_ui(ui, "colour", &mut m.color);
                egui::Grid::new(("material-grid", i))
                    .num_columns(3)
                    .show(ui, |ui| {
                        // The ranges scene files are held to.
                        use crate::limits::{IOR_RANGE, SHININESS_RANGE, UNIT_RANGE};
                        for (label, value, range, step) in [
                            ("kd", &mut m.kd, UNIT_RANGE, 0.005),
                            ("ks", &mut m.ks, UNIT_RANGE, 0.005),
                            ("shininess", &mut m.shininess, SHININESS_RANGE, 1.0),
                            ("reflectivity", &mut m.reflectivity, UNIT_RANGE, 0.005),
                            ("transparency", &mut m.transparency, UNIT_RANGE, 0.005),
                            ("ior", &mut m.ior, IOR_RANGE, 0.005),
                        ] {
                            ui.label(label);
                            changed |= bounded_value_ui(ui, (i, label), value, range, step);
                            ui.end_row();
                        }
                    });
                texture_maps_ui(&edit.scene, &m, ui);
            });
        if changed {
            if ka_follows_kd {
                m.ka = m.kd;
            }
            edit.scene_mut().materials[i] = m;
        }
    }
}

/// The textures on material `m`: each map's file as the scene names it and
/// the image's size (read-only: a texture is changed in its file).
fn texture_maps_ui(scene: &crate::scene::Scene, m: &crate::material::Material, ui: &mut egui::Ui) {
    let same = m.color_map.is_some() && m.color_map == m.cutout_map;
    for (label, map) in [
        (
            if same {
                "texture (and cut-out)"
            } else {
                "texture"
            },
            &m.color_map,
        ),
        ("cut-out", if same { &None } else { &m.cutout_map }),
    ] {
        let Some(map) = map else { continue };
        let Some(texture) = scene.textures.get(map.texture as usize) else {
            continue;
        };
        ui.label(format!(
            "{label}: {} ({}x{})",
            map.name, texture.width, texture.height
        ))
        .on_hover_text(texture.path.display().to_string());
    }
}

/// Progress of the pass on screen, with the time left and a stop button,
/// and the newest message.
pub fn status_ui(edit: &EditState, info: &RenderInfo, ui: &mut egui::Ui) -> Vec<Command> {
    let mut commands = Vec::new();
    ui.horizontal(|ui| {
        let newest = info.worker.generation();
        let status = info.worker.try_with_buffer(|b| {
            (
                b.pass,
                b.tiles_done,
                b.tiles_total,
                b.finished,
                b.pass_started.map(|t| t.elapsed().as_secs_f64()),
                b.stopped,
                b.generation == newest,
                b.generation,
            )
        });
        match status {
            // The buffer describes the image before until the new job's
            // first pass starts: that image is neither "done" nor the
            // progress of the new one.
            Some((Some(pass), .., false, false, _)) if pass.preview.is_none() => {
                ui.label("starting the new image…");
            }
            Some((Some(pass), done, total, _, _, true, _, _)) => {
                let pct = 100.0 * done as f64 / total.max(1) as f64;
                ui.label(format!(
                    "stopped: {} at {pct:.0}% (any change renders again)",
                    pass.label()
                ));
            }
            Some((Some(pass), done, total, finished, elapsed, false, _, generation)) => {
                if let Some(p) = pass.preview {
                    // The frames while moving: the full passes follow on release.
                    ui.label(match p {
                        Preview::Reuse => {
                            let made_of = info
                                .worker
                                .history()
                                .iter()
                                .rev()
                                .find(|r| r.generation == generation)
                                .and_then(|r| r.reuse)
                                .map_or_else(String::new, |s| format!(": {}", s.describe()));
                            format!(
                                "moving: full picture from the render cache{made_of}; \
                                 the exact image follows when you let go"
                            )
                        }
                        Preview::Reduced(r) => format!(
                            "moving: preview {} ({}x{}); the full image follows when you let go",
                            r.describe(),
                            (edit.settings.width / r.divisor).max(1),
                            (edit.settings.height / r.divisor).max(1)
                        ),
                    });
                } else if finished {
                    ui.label(format!(
                        "done: {} ({}x{})",
                        pass.label(),
                        edit.settings.width,
                        edit.settings.height
                    ));
                } else {
                    let pct = 100.0 * done as f64 / total.max(1) as f64;
                    ui.label(format!("rendering {}: {pct:.0}%", pass.label()));
                    ui.add(egui::ProgressBar::new((pct / 100.0) as f32).desired_width(160.0));
                    if let Some(left) = elapsed.and_then(|e| time_left(e, done, total)) {
                        ui.label(format!("about {} left", seconds_text(left)));
                    }
                    if ui
                        .button("Stop")
                        .on_hover_text("stop this pass, keeping the image as far as it got")
                        .clicked()
                    {
                        commands.push(Command::StopPass);
                    }
                }
            }
            Some((None, ..)) => {
                ui.label("starting…");
            }
            None => {
                ui.label("rendering…");
            }
        }
        if let Some(m) = info.message {
            ui.separator();
            let color = if m.is_error {
                Color32::from_rgb(230, 80, 60)
            } else {
                ui.visuals().text_color()
            };
            ui.label(RichText::new(&m.text).color(color));
        }
    });
    commands
}

/// Seconds left of a pass `elapsed` seconds in with `done` of `total`
/// tiles finished, at the pace so far; none until a few tiles and a
/// second have passed (earlier guesses jump about).
pub fn time_left(elapsed: f64, done: u64, total: u64) -> Option<f64> {
    if done < 4 || elapsed < 1.0 || done >= total {
        return None;
    }
    Some(elapsed * (total - done) as f64 / done as f64)
}

/// "42 s", "3 min 5 s", "1 h 12 min".
fn seconds_text(s: f64) -> String {
    let s = s.round() as u64;
    match s {
        0..60 => format!("{s} s"),
        60..3600 => format!("{} min {} s", s / 60, s % 60),
        _ => format!("{} h {} min", s / 3600, s / 60 % 60),
    }
}

/// The image size fields. A side past the viewer's limit is refused with
/// a message in place, not clamped: the field keeps the old value and says
/// why (the command line renders larger images).
fn image_size_ui(edit: &mut EditState, ui: &mut egui::Ui) {
    let id = ui.scope_id().with("image size refused");
    let (mut w, mut h) = (edit.settings.width, edit.settings.height);
    ui.horizontal(|ui| {
        ui.label("Image size");
        // Wider than the limit, so a typed 9000 arrives and is refused
        // rather than silently becoming the limit.
        for (k, v) in [&mut w, &mut h].into_iter().enumerate() {
            if k == 1 {
                ui.label("x");
            }
            ui.add(
                DragValue::new(v)
                    .update_while_editing(false)
                    .range(1..=1 << 20),
            );
        }
    });
    if (w, h) != (edit.settings.width, edit.settings.height) {
        match size_refusal(w, h) {
            Some(message) => {
                ui.ctx().data_mut(|d| d.insert_temp(id, message));
            }
            None => {
                (edit.settings.width, edit.settings.height) = (w, h);
                ui.ctx().data_mut(|d| {
                    d.remove_temp::<String>(id);
                });
            }
        }
    }
    if let Some(message) = ui.ctx().data(|d| d.get_temp::<String>(id)) {
        ui.colored_label(ui.visuals().warn_fg_color, message);
    }
}

/// Why the viewer does not render a `w` x `h` image, if it does not.
fn size_refusal(w: u32, h: u32) -> Option<String> {
    let max = crate::limits::MAX_VIEWER_SIDE;
    (w.max(h) > max).then(|| {
        format!(
            "{w}x{h} refused: the viewer renders sides up to {max} pixels \
             (glint render -o takes up to {})",
            crate::limits::MAX_IMAGE_SIDE
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn time_left_follows_the_pace_so_far() {
        // 10 of 40 tiles in 5 s: 30 more at 0.5 s each.
        assert_eq!(time_left(5.0, 10, 40), Some(15.0));
        assert_eq!(time_left(0.5, 10, 40), None, "too early to tell");
        assert_eq!(time_left(5.0, 2, 40), None, "too few tiles");
        assert_eq!(time_left(5.0, 40, 40), None, "done");
        assert_eq!(seconds_text(42.4), "42 s");
        assert_eq!(seconds_text(185.0), "3 min 5 s");
        assert_eq!(seconds_text(4320.0), "1 h 12 min");
    }

    #[test]
    fn a_value_past_its_range_is_brought_back_and_said() {
        let mut kd = 2.0;
        assert_eq!(
            clamp_note(&mut kd, &(0.0..=1.0)).as_deref(),
            Some("2 is past 0 to 1: 1 kept")
        );
        assert_eq!(kd, 1.0);
        let mut ior = 0.001;
        assert!(clamp_note(&mut ior, &crate::limits::IOR_RANGE).is_some());
        assert_eq!(ior, *crate::limits::IOR_RANGE.start());
        let mut inside = 0.5;
        assert_eq!(clamp_note(&mut inside, &(0.0..=1.0)), None);
        assert_eq!(inside, 0.5);
    }

    #[test]
    fn sizes_past_the_viewers_limit_are_refused_with_the_reason() {
        assert_eq!(size_refusal(8192, 1), None);
        assert_eq!(size_refusal(800, 600), None);
        let message = size_refusal(9000, 600).unwrap();
        assert!(message.starts_with("9000x600 refused"), "{message}");
        assert!(message.contains("8192"), "{message}");
        assert!(size_refusal(1, 8193).is_some());
    }
}
