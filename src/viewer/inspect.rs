//! Seeing inside the render in the viewer: the octree overlay, a pixel's
//! ray tree, and the A/B comparison. The core computes (octree cells, ray
//! trees, projections); this module only shows.

use std::sync::Arc;

use egui::{Color32, Pos2, Rect, Sense, Stroke, TextureHandle, TextureOptions};

use super::command::Command;
use super::state::EditState;
use super::worker::{PassKind, PassRecord, Worker};
use crate::accel::{Octree, OctreeCell};
use crate::camera::Camera;
use crate::math::DVec3;
use crate::ray_tree::{RayKind, RayNode, ShadowVerdict};
use crate::render::{RenderError, Renderer};
use crate::settings::{RenderSettings, ViewMode};

/// The inspected pixel and the tree of rays its centre ray spawned.
#[derive(Clone, Debug)]
pub struct Inspection {
    pub pixel: (u32, u32),
    pub tree: RayNode,
    pub lights: Vec<DVec3>,
}

/// A frame kept as "A" for comparison with the live image ("B").
#[derive(Clone, Debug)]
pub struct Pinned {
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<u8>,
    pub label: String,
    pub timing: String,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CompareMode {
    /// A left of the divider, B right of it.
    Split,
    /// |A − B| times the gain.
    Difference,
}

/// Pixels that differ between two RGBA8 frames of equal size.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct DiffStats {
    pub differing: usize,
    pub total: usize,
    /// Largest difference of one colour channel, in 8-bit levels.
    pub largest: u8,
}

pub fn diff_stats(a: &[u8], b: &[u8]) -> DiffStats {
    let mut stats = DiffStats {
        differing: 0,
        total: a.len() / 4,
        largest: 0,
    };
    for (p, q) in a.chunks_exact(4).zip(b.chunks_exact(4)) {
        let d = (0..3).map(|c| p[c].abs_diff(q[c])).max().unwrap_or(0);
        if d > 0 {
            stats.differing += 1;
            stats.largest = stats.largest.max(d);
        }
    }
    stats
}

pub struct Compare {
    pub pinned: Pinned,
    pub mode: CompareMode,
    /// Divider position across the image, 0 (left) to 1 (right).
    pub divider: f32,
    pub gain: f32,
    texture: Option<TextureHandle>,
    diff_texture: Option<(u64, u32, TextureHandle)>,
    /// The last comparison, by buffer version: counted once per change.
    stats: std::cell::Cell<Option<(u64, Option<DiffStats>)>>,
}

/// Run-time state of the inspection tools (none of it restarts a render).
#[derive(Default)]
pub struct InspectState {
    /// Octree overlay down to this level; `None` hides it.
    pub overlay_depth: Option<u32>,
    /// The overlay's cells, for the octree at this address and this depth.
    cells: Option<(usize, u32, Arc<Vec<OctreeCell>>)>,
    /// Clicking the image picks a pixel (Ctrl+click does so any time).
    pub inspect_mode: bool,
    pub inspection: Option<Inspection>,
    pub compare: Option<Compare>,
}

fn to_screen(image_rect: Rect, width: u32, height: u32, (x, y): (f64, f64)) -> Pos2 {
    Pos2::new(
        image_rect.min.x + (x / width as f64) as f32 * image_rect.width(),
        image_rect.min.y + (y / height as f64) as f32 * image_rect.height(),
    )
}

fn color32(c: [u8; 3]) -> Color32 {
    Color32::from_rgb(c[0], c[1], c[2])
}

/// The passes of generation `generation` that count (no previews), e.g.
/// "1 sample 0.120 s, 16 samples 1.530 s".
pub fn timing_label(history: &[PassRecord], generation: u64) -> String {
    let parts: Vec<String> = history
        .iter()
        .filter(|r| r.generation == generation && !matches!(r.kind, PassKind::Preview(_)))
        .map(|r| format!("{} {:.3} s", r.kind.label(), r.seconds))
        .collect();
    if parts.is_empty() {
        "not finished".into()
    } else {
        parts.join(", ")
    }
}

impl InspectState {
    pub fn new(overlay_depth: Option<u32>) -> Self {
        Self {
            overlay_depth,
            ..Self::default()
        }
    }

    /// The octree cells for the overlay at `depth` (cached per octree).
    fn overlay_cells(&mut self, octree: &Arc<Octree>, depth: u32) -> Arc<Vec<OctreeCell>> {
        let key = Arc::as_ptr(octree) as usize;
        if let Some((k, d, cells)) = &self.cells
            && *k == key
            && *d == depth
        {
            return Arc::clone(cells);
        }
        let cells = Arc::new(octree.cells(depth));
        self.cells = Some((key, depth, Arc::clone(&cells)));
        cells
    }

    /// Picks pixel `(i, j)` of the image `edit` describes and traces its
    /// centre ray's tree on this thread: one pixel is microseconds of work.
    /// A pixel outside the image picks nothing.
    pub fn inspect_pixel(
        &mut self,
        edit: &EditState,
        octree: &Octree,
        (i, j): (u32, u32),
    ) -> Result<(), RenderError> {
        let settings = RenderSettings {
            samples: 1,
            view: ViewMode::Shaded,
            ..edit.settings
        };
        if i >= settings.width || j >= settings.height {
            return Ok(());
        }
        let renderer = Renderer::with_camera(&edit.scene, octree, settings, &edit.camera)?;
        self.inspection = Some(Inspection {
            pixel: (i, j),
            tree: renderer.ray_tree(i, j),
            lights: edit.scene.lights.iter().map(|l| l.position).collect(),
        });
        Ok(())
    }

    /// Keeps the frame on screen as "A", labelled with its settings.
    pub fn pin_as_a(&mut self, worker: &Worker, label: String) {
        let (width, height, rgba, generation) =
            worker.with_buffer(|b| (b.width, b.height, b.rgba.clone(), b.generation));
        if width == 0 {
            return;
        }
        self.compare = Some(Compare {
            pinned: Pinned {
                width,
                height,
                rgba,
                label,
                timing: timing_label(&worker.history(), generation),
            },
            mode: CompareMode::Split,
            divider: 0.5,
            gain: 8.0,
            texture: None,
            diff_texture: None,
            stats: std::cell::Cell::new(None),
        });
    }

    /// A versus B, when B is complete: the pixels that differ.
    pub fn compare_stats(&self, worker: &Worker) -> Option<DiffStats> {
        let c = self.compare.as_ref()?;
        let generation = worker.generation();
        let cached = c.stats.get();
        let result = worker.with_buffer(|b| {
            if let Some((version, stats)) = cached
                && version == b.version
            {
                return (version, stats);
            }
            let stats = (b.finished
                && b.generation == generation
                && b.width == c.pinned.width
                && b.height == c.pinned.height)
                .then(|| diff_stats(&c.pinned.rgba, &b.rgba));
            (b.version, stats)
        });
        c.stats.set(Some(result));
        result.1
    }

    /// Draws A over the live image (split or difference) where a comparison
    /// is active; returns whether it drew the image itself.
    pub fn compare_image_ui(
        &mut self,
        ui: &mut egui::Ui,
        image_rect: Rect,
        live: Option<&TextureHandle>,
        worker: &Worker,
    ) -> bool {
        let Some(c) = &mut self.compare else {
            return false;
        };
        let (w, h) = worker
            .try_with_buffer(|b| (b.width, b.height))
            .unwrap_or((0, 0));
        if (w, h) != (c.pinned.width, c.pinned.height) {
            return false;
        }
        let ctx = ui.ctx().clone();
        let texture = c.texture.get_or_insert_with(|| {
            ctx.load_texture(
                "glint-pinned-a",
                egui::ColorImage::from_rgba_unmultiplied(
                    [c.pinned.width as usize, c.pinned.height as usize],
                    &c.pinned.rgba,
                ),
                TextureOptions::NEAREST,
            )
        });
        let full = Rect::from_min_max(Pos2::ZERO, Pos2::new(1.0, 1.0));
        match c.mode {
            CompareMode::Split => {
                let Some(live) = live else { return false };
                let x = image_rect.min.x + c.divider * image_rect.width();
                let left = Rect::from_min_max(image_rect.min, Pos2::new(x, image_rect.max.y));
                let right = Rect::from_min_max(Pos2::new(x, image_rect.min.y), image_rect.max);
                let painter = ui.painter();
                painter.image(
                    texture.id(),
                    left,
                    Rect::from_min_max(Pos2::ZERO, Pos2::new(c.divider, 1.0)),
                    Color32::WHITE,
                );
                painter.image(
                    live.id(),
                    right,
                    Rect::from_min_max(Pos2::new(c.divider, 0.0), Pos2::new(1.0, 1.0)),
                    Color32::WHITE,
                );
                // The divider: a handle that takes drags before the camera does.
                let handle = Rect::from_center_size(
                    Pos2::new(x, image_rect.center().y),
                    egui::vec2(12.0, image_rect.height()),
                );
                let response = ui
                    .interact(handle, ui.scope_id().with("ab-divider"), Sense::drag())
                    .on_hover_cursor(egui::CursorIcon::ResizeHorizontal);
                if response.dragged() {
                    let dx = response.drag_delta().x / image_rect.width().max(1.0);
                    c.divider = (c.divider + dx).clamp(0.0, 1.0);
                }
                let painter = ui.painter();
                painter.line_segment(
                    [
                        Pos2::new(x, image_rect.min.y),
                        Pos2::new(x, image_rect.max.y),
                    ],
                    Stroke::new(2.0, Color32::WHITE),
                );
                // Labels inset from the top corners.
                for (text, pos, align, inset) in [
                    ("A", image_rect.left_top(), egui::Align2::LEFT_TOP, 6.0),
                    ("B", image_rect.right_top(), egui::Align2::RIGHT_TOP, -6.0),
                ] {
                    painter.text(
                        pos + egui::vec2(inset, 4.0),
                        align,
                        text,
                        egui::FontId::proportional(18.0),
                        Color32::WHITE,
                    );
                }
            }
            CompareMode::Difference => {
                // Size and pixels under one lock, copied only when they
                // changed; a busy buffer is simply tried again next frame.
                let gain_key = c.gain.to_bits();
                let cached = c.diff_texture.as_ref().map(|(v, g, _)| (*v, *g));
                let fresh = worker
                    .try_with_buffer(|b| {
                        let size_ok = (b.width, b.height) == (c.pinned.width, c.pinned.height)
                            && b.rgba.len() == c.pinned.rgba.len();
                        (size_ok && cached != Some((b.version, gain_key)))
                            .then(|| (b.version, b.rgba.clone()))
                    })
                    .flatten();
                if let Some((version, rgba)) = fresh {
                    let diff: Vec<u8> = c
                        .pinned
                        .rgba
                        .chunks_exact(4)
                        .zip(rgba.chunks_exact(4))
                        .flat_map(|(p, q)| {
                            let d =
                                |k: usize| (p[k].abs_diff(q[k]) as f32 * c.gain).min(255.0) as u8;
                            [d(0), d(1), d(2), 255]
                        })
                        .collect();
                    let image =
                        egui::ColorImage::from_rgba_unmultiplied([w as usize, h as usize], &diff);
                    let handle = ctx.load_texture("glint-ab-diff", image, TextureOptions::NEAREST);
                    c.diff_texture = Some((version, gain_key, handle));
                }
                if let Some((_, _, t)) = &c.diff_texture {
                    ui.painter().image(t.id(), image_rect, full, Color32::WHITE);
                }
            }
        }
        true
    }

    /// Overlay and ray-tree drawings over the image, and the hover read-out.
    pub fn overlays_ui(
        &mut self,
        ui: &mut egui::Ui,
        image_rect: Rect,
        edit: &EditState,
        octree: &Arc<Octree>,
    ) {
        let (w, h) = (edit.settings.width, edit.settings.height);
        let Ok(camera) = Camera::new(&edit.camera, w, h) else {
            return;
        };
        let painter = ui.painter_at(image_rect);
        if let Some(depth) = self.overlay_depth {
            let cells = self.overlay_cells(octree, depth);
            for (cell, color) in crate::overlay::styled_cells(&cells) {
                let color = color32(color);
                for (a, b) in crate::overlay::cell_segments(&camera, cell) {
                    painter.line_segment(
                        [
                            to_screen(image_rect, w, h, a),
                            to_screen(image_rect, w, h, b),
                        ],
                        Stroke::new(1.0, color),
                    );
                }
            }
            if let Some(pos) = ui.ctx().pointer_hover_pos()
                && image_rect.contains(pos)
            {
                let x = (pos.x - image_rect.min.x) / image_rect.width() * w as f32;
                let y = (pos.y - image_rect.min.y) / image_rect.height() * h as f32;
                if let Some(cell) = crate::overlay::cell_at(&camera, &cells, x as f64, y as f64) {
                    let b = cell.bounds;
                    let text = format!(
                        "depth {}\nbounds ({:.3}, {:.3}, {:.3})\n  to ({:.3}, {:.3}, {:.3})\nreferences {}",
                        cell.depth,
                        b.min.x,
                        b.min.y,
                        b.min.z,
                        b.max.x,
                        b.max.y,
                        b.max.z,
                        cell.references
                    );
                    let galley =
                        painter.layout_no_wrap(text, egui::FontId::monospace(12.0), Color32::WHITE);
                    let at = pos + egui::vec2(14.0, 14.0);
                    let rect = Rect::from_min_size(at, galley.size()).expand(4.0);
                    painter.rect_filled(rect, 3.0, Color32::from_black_alpha(200));
                    painter.galley(at, galley, Color32::WHITE);
                }
            }
        }
        if let Some(ins) = &self.inspection {
            let extent = edit.scene.extent_bounds().extent().length().max(1e-9);
            draw_tree(
                &painter,
                &camera,
                image_rect,
                &ins.tree,
                &ins.lights,
                extent,
            );
            let (i, j) = ins.pixel;
            let p = to_screen(image_rect, w, h, (i as f64 + 0.5, j as f64 + 0.5));
            painter.circle_stroke(p, 6.0, Stroke::new(2.0, Color32::from_rgb(255, 80, 200)));
        }
    }
}

fn kind_color(kind: RayKind) -> Color32 {
    match kind {
        RayKind::Eye => Color32::WHITE,
        RayKind::Reflection => Color32::from_rgb(80, 220, 255),
        RayKind::Refraction => Color32::from_rgb(255, 170, 60),
    }
}

/// Projects and draws a world-space segment, cut at the near plane.
fn segment(
    painter: &egui::Painter,
    camera: &Camera,
    image_rect: Rect,
    a: DVec3,
    b: DVec3,
    stroke: Stroke,
) {
    if let Some((p, q)) = crate::overlay::project_segment(camera, a, b) {
        let (w, h) = (camera.width(), camera.height());
        painter.line_segment(
            [
                to_screen(image_rect, w, h, p),
                to_screen(image_rect, w, h, q),
            ],
            stroke,
        );
    }
}

fn draw_tree(
    painter: &egui::Painter,
    camera: &Camera,
    image_rect: Rect,
    node: &RayNode,
    lights: &[DVec3],
    extent: f64,
) {
    let origin = DVec3::from_array(node.origin);
    let dir = DVec3::from_array(node.direction);
    let end = node
        .hit
        .as_ref()
        .map_or(origin + dir * extent, |h| DVec3::from_array(h.point));
    segment(
        painter,
        camera,
        image_rect,
        origin,
        end,
        Stroke::new(2.0, kind_color(node.kind)),
    );
    if node.hit.is_some() {
        for s in &node.shadows {
            let Some(&light) = lights.get(s.light) else {
                continue;
            };
            let color = match s.verdict {
                ShadowVerdict::Lit => Color32::from_rgb(255, 230, 80),
                ShadowVerdict::Attenuated => Color32::from_rgb(200, 160, 60),
                ShadowVerdict::Blocked => Color32::from_rgb(200, 40, 40),
                ShadowVerdict::FacesAway => continue,
            };
            segment(
                painter,
                camera,
                image_rect,
                end,
                light,
                Stroke::new(1.0, color),
            );
        }
    }
    for c in &node.children {
        draw_tree(painter, camera, image_rect, c, lights, extent);
    }
}

fn rgb_text(c: [f64; 3]) -> String {
    format!("({:.3}, {:.3}, {:.3})", c[0], c[1], c[2])
}

/// The inspected pixel's ray tree as nested, collapsible rows.
pub fn ray_tree_ui(inspect: &InspectState, ui: &mut egui::Ui) {
    let Some(ins) = &inspect.inspection else {
        ui.label("Ctrl+click the image (or turn on Inspect and click) to see a pixel's rays.");
        return;
    };
    ui.label(format!(
        "pixel {},{} — colour {}",
        ins.pixel.0,
        ins.pixel.1,
        rgb_text(ins.tree.color)
    ));
    node_ui(ui, &ins.tree, "ray");
}

fn node_ui(ui: &mut egui::Ui, node: &RayNode, path: &str) {
    let kind = match node.kind {
        RayKind::Eye => "eye",
        RayKind::Reflection => "reflection",
        RayKind::Refraction => "refraction",
    };
    let what = match &node.hit {
        Some(h) => format!(
            "{} #{} ({}) at {:.4}",
            h.kind.name(),
            h.object,
            h.material,
            h.distance
        ),
        None => "background".into(),
    };
    egui::CollapsingHeader::new(
        egui::RichText::new(format!("{kind} ray, depth {}: {what}", node.depth))
            .color(kind_color(node.kind)),
    )
    .id_salt(path)
    .default_open(node.depth <= 2)
    .show(ui, |ui| {
        let v = |v: [f64; 3]| format!("({:.4}, {:.4}, {:.4})", v[0], v[1], v[2]);
        ui.label(format!("origin {}", v(node.origin)));
        ui.label(format!("direction {}", v(node.direction)));
        if let Some(h) = &node.hit {
            ui.label(format!("point {}", v(h.point)));
            ui.label(format!(
                "normal {} ({})",
                v(h.normal),
                if h.entering { "entering" } else { "leaving" }
            ));
        }
        for s in &node.shadows {
            ui.label(format!(
                "light {}: {} (transmittance {:.3}) adds {}",
                s.light,
                s.verdict.name(),
                s.transmittance,
                rgb_text(s.color)
            ));
        }
        ui.label(format!("local {}", rgb_text(node.local_color)));
        ui.label(format!(
            "colour {} × weight {:.3} = {}",
            rgb_text(node.color),
            node.weight,
            rgb_text(node.contribution)
        ));
        for (k, c) in node.children.iter().enumerate() {
            node_ui(ui, c, &format!("{path}/{k}"));
        }
    });
}

/// The overlay, inspect and A/B controls. `label` describes the current
/// settings (B's); "Pin as A" is returned as a command, since pinning needs
/// the app's settings label at the moment it is applied.
pub fn inspect_controls_ui(
    inspect: &mut InspectState,
    worker: &Worker,
    label: &str,
    ui: &mut egui::Ui,
) -> Vec<Command> {
    let mut commands = Vec::new();
    let mut overlay = inspect.overlay_depth.is_some();
    ui.horizontal(|ui| {
        ui.checkbox(&mut overlay, "Octree overlay");
        let mut depth = inspect.overlay_depth.unwrap_or(3);
        ui.label("to depth");
        ui.add(egui::DragValue::new(&mut depth).range(0..=crate::limits::MAX_OCTREE_DEPTH));
        inspect.overlay_depth = overlay.then_some(depth);
    });
    ui.checkbox(&mut inspect.inspect_mode, "Inspect: click picks a pixel");
    if inspect.inspection.is_some() && ui.button("Clear inspected pixel").clicked() {
        inspect.inspection = None;
    }
    ui.separator();
    ui.horizontal(|ui| {
        if ui.button("Pin as A").clicked() {
            commands.push(Command::PinAsA);
        }
        if inspect.compare.is_some() && ui.button("Unpin").clicked() {
            inspect.compare = None;
        }
    });
    let stats = inspect.compare_stats(worker);
    let b_timing = timing_label(&worker.history(), worker.generation());
    if let Some(c) = &mut inspect.compare {
        ui.horizontal(|ui| {
            ui.selectable_value(&mut c.mode, CompareMode::Split, "Split");
            ui.selectable_value(&mut c.mode, CompareMode::Difference, "Difference");
        });
        if c.mode == CompareMode::Split {
            ui.add(egui::Slider::new(&mut c.divider, 0.0..=1.0).text("divider"));
        } else {
            ui.add(
                egui::Slider::new(&mut c.gain, 1.0..=64.0)
                    .logarithmic(true)
                    .text("gain"),
            );
        }
        ui.label(format!("A: {}", c.pinned.label));
        ui.label(format!("   {}", c.pinned.timing));
        ui.label(format!("B: {label}"));
        ui.label(format!("   {b_timing}"));
        match stats {
            Some(s) => {
                let text = format!(
                    "{} pixels differ of {} ({:.2}%), largest difference {}/255",
                    s.differing,
                    s.total,
                    100.0 * s.differing as f64 / s.total.max(1) as f64,
                    s.largest
                );
                let color = if s.differing == 0 {
                    Color32::from_rgb(90, 200, 120)
                } else {
                    ui.visuals().text_color()
                };
                ui.add(egui::Label::new(egui::RichText::new(text).color(color).strong()).wrap());
            }
            None => {
                ui.label("B is rendering (or has another size)…");
            }
        }
    }
    commands
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stats::RayCounts;

    #[test]
    fn differences_count_pixels_and_the_largest_channel_step() {
        let a = [10, 20, 30, 255, 0, 0, 0, 255, 5, 5, 5, 255];
        // Pixel 0 equal; pixel 1 differs by 7 in blue; pixel 2 by 3 in red
        // (alpha is not compared).
        let b = [10, 20, 30, 0, 0, 0, 7, 255, 8, 5, 5, 255];
        assert_eq!(
            diff_stats(&a, &b),
            DiffStats {
                differing: 2,
                total: 3,
                largest: 7
            }
        );
        assert_eq!(diff_stats(&a, &a).differing, 0);
    }

    #[test]
    fn timing_labels_list_the_full_passes_of_one_generation() {
        let pass = |generation, kind, seconds| PassRecord {
            generation,
            kind,
            seconds,
            rays: RayCounts::default(),
            octree: true,
            anti_aliasing: true,
            width: 8,
            height: 8,
            finished_at: 0.0,
            one_sample_error: None,
            refined_pixels: None,
            view: ViewMode::Shaded,
            max_depth: 5,
            protocol: crate::settings::Protocol::Glint,
        };
        let preview = PassKind::Preview(super::super::worker::Preview {
            divisor: 2,
            reflections: true,
            shadows: true,
        });
        let history = [
            pass(1, PassKind::OneSample, 0.5),
            pass(2, preview, 0.01),
            pass(2, PassKind::OneSample, 0.125),
            pass(2, PassKind::SixteenSamples, 1.5),
        ];
        assert_eq!(
            timing_label(&history, 2),
            "1 sample 0.125 s, 16 samples 1.500 s"
        );
        assert_eq!(timing_label(&history, 3), "not finished");
    }
}
