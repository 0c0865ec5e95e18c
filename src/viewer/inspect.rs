//! Seeing inside the render in the viewer: the octree overlay, a pixel's
//! ray tree, and the A/B comparison. The core computes (octree cells, ray
//! trees, projections); this module only shows.

use std::sync::Arc;

use egui::{Color32, Pos2, Rect, Sense, Stroke, TextureHandle, TextureOptions};

use super::app::GlintApp;
use super::worker::PassKind;
use crate::accel::OctreeCell;
use crate::camera::Camera;
use crate::math::DVec3;
use crate::ray_tree::{RayKind, RayNode};
use crate::render::Renderer;
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
pub struct InspectState {
    /// Octree overlay down to this level; `None` hides it.
    pub overlay_depth: Option<u32>,
    pub(crate) cells: Option<(usize, u32, Arc<Vec<OctreeCell>>)>,
    /// Clicking the image picks a pixel (Ctrl+click does so any time).
    pub inspect_mode: bool,
    pub inspection: Option<Inspection>,
    pub compare: Option<Compare>,
}

impl Default for InspectState {
    fn default() -> Self {
        Self {
            overlay_depth: None,
            cells: None,
            inspect_mode: false,
            inspection: None,
            compare: None,
        }
    }
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

impl GlintApp {
    /// The octree cells for the overlay at the current depth (cached).
    fn overlay_cells(&mut self, depth: u32) -> Arc<Vec<OctreeCell>> {
        let key = Arc::as_ptr(&self.octree) as usize;
        if let Some((k, d, cells)) = &self.inspect.cells
            && *k == key
            && *d == depth
        {
            return Arc::clone(cells);
        }
        let cells = Arc::new(self.octree.cells(depth));
        self.inspect.cells = Some((key, depth, Arc::clone(&cells)));
        cells
    }

    /// Picks pixel `(i, j)` and traces its ray tree on this thread: one
    /// pixel is microseconds of work.
    pub fn inspect_pixel(&mut self, i: u32, j: u32) {
        let settings = RenderSettings {
            samples: 1,
            view: ViewMode::Shaded,
            ..self.settings
        };
        if i >= settings.width || j >= settings.height {
            return;
        }
        match Renderer::with_camera(&self.scene, &self.octree, settings, &self.camera) {
            Ok(r) => {
                self.inspect.inspection = Some(Inspection {
                    pixel: (i, j),
                    tree: r.ray_tree(i, j),
                    lights: self.scene.lights.iter().map(|l| l.position).collect(),
                })
            }
            Err(e) => self.say(format!("cannot inspect: {e}"), true),
        }
    }

    /// Keeps the frame on screen as "A".
    pub fn pin_as_a(&mut self) {
        let (width, height, rgba, generation) = self
            .worker
            .with_buffer(|b| (b.width, b.height, b.rgba.clone(), b.generation));
        if width == 0 {
            return;
        }
        self.inspect.compare = Some(Compare {
            pinned: Pinned {
                width,
                height,
                rgba,
                label: self.settings_label(),
                timing: self.timing_label(generation),
            },
            mode: CompareMode::Split,
            divider: 0.5,
            gain: 8.0,
            texture: None,
            diff_texture: None,
            stats: std::cell::Cell::new(None),
        });
    }

    pub fn settings_label(&self) -> String {
        let s = &self.settings;
        format!(
            "{}, AA {}, octree {}, depth {}, {}x{}",
            s.view.name(),
            if self.anti_aliasing { "on" } else { "off" },
            if s.use_octree { "on" } else { "off" },
            s.max_depth,
            s.width,
            s.height
        )
    }

    fn timing_label(&self, generation: u64) -> String {
        let parts: Vec<String> = self
            .worker
            .history()
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

    /// A versus B, when B is complete: the pixels that differ.
    pub fn compare_stats(&self) -> Option<DiffStats> {
        let c = self.inspect.compare.as_ref()?;
        let generation = self.worker.generation();
        let cached = c.stats.get();
        let result = self.worker.with_buffer(|b| {
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
    pub(crate) fn compare_image_ui(
        &mut self,
        ui: &mut egui::Ui,
        image_rect: Rect,
        live: Option<&TextureHandle>,
    ) -> bool {
        let Some(c) = &mut self.inspect.compare else {
            return false;
        };
        let (w, h) = self
            .worker
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
                let _ = full;
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
                for (text, pos, align) in [
                    ("A", image_rect.left_top(), egui::Align2::LEFT_TOP),
                    ("B", image_rect.right_top(), egui::Align2::RIGHT_TOP),
                ] {
                    let r = painter.text(
                        pos + egui::vec2(
                            if align == egui::Align2::LEFT_TOP {
                                6.0
                            } else {
                                -6.0
                            },
                            4.0,
                        ),
                        align,
                        text,
                        egui::FontId::proportional(18.0),
                        Color32::WHITE,
                    );
                    let _ = r;
                }
            }
            CompareMode::Difference => {
                // Size and pixels under one lock, copied only when they
                // changed; a busy buffer is simply tried again next frame.
                let gain_key = c.gain.to_bits();
                let cached = c.diff_texture.as_ref().map(|(v, g, _)| (*v, *g));
                let fresh = self
                    .worker
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
    pub(crate) fn overlays_ui(&mut self, ui: &mut egui::Ui, image_rect: Rect) {
        let (w, h) = (self.settings.width, self.settings.height);
        let Ok(camera) = Camera::new(&self.camera, w, h) else {
            return;
        };
        let painter = ui.painter_at(image_rect);
        if let Some(depth) = self.inspect.overlay_depth {
            let cells = self.overlay_cells(depth);
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
        if let Some(ins) = &self.inspect.inspection {
            let extent = self.scene.extent_bounds().extent().length().max(1e-9);
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
                "lit" => Color32::from_rgb(255, 230, 80),
                "attenuated" => Color32::from_rgb(200, 160, 60),
                "blocked" => Color32::from_rgb(200, 40, 40),
                _ => continue,
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
pub fn ray_tree_ui(app: &mut GlintApp, ui: &mut egui::Ui) {
    let Some(ins) = &app.inspect.inspection else {
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
            h.kind, h.object, h.material, h.distance
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
                s.verdict,
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

/// The overlay, inspect and A/B controls.
pub fn inspect_controls_ui(app: &mut GlintApp, ui: &mut egui::Ui) {
    let mut overlay = app.inspect.overlay_depth.is_some();
    ui.horizontal(|ui| {
        ui.checkbox(&mut overlay, "Octree overlay");
        let mut depth = app.inspect.overlay_depth.unwrap_or(3);
        ui.label("to depth");
        ui.add(egui::DragValue::new(&mut depth).range(0..=crate::accel::MAX_OCTREE_DEPTH));
        app.inspect.overlay_depth = overlay.then_some(depth);
    });
    ui.checkbox(
        &mut app.inspect.inspect_mode,
        "Inspect: click picks a pixel",
    );
    if app.inspect.inspection.is_some() && ui.button("Clear inspected pixel").clicked() {
        app.inspect.inspection = None;
    }
    ui.separator();
    ui.horizontal(|ui| {
        if ui.button("Pin as A").clicked() {
            app.pin_as_a();
        }
        if app.inspect.compare.is_some() && ui.button("Unpin").clicked() {
            app.inspect.compare = None;
        }
    });
    let stats = app.compare_stats();
    let label = app.settings_label();
    let b_timing = app.timing_label(app.worker.generation());
    if let Some(c) = &mut app.inspect.compare {
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
}
