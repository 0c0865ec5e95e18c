//! Seeing inside the render in the viewer: the octree overlay, and the
//! state of the inspection tools (the inspected pixel, `pixel.rs`; the A/B
//! comparison, `compare.rs`). The core computes (octree cells, ray trees,
//! projections); this module only shows.

use std::sync::Arc;

use egui::{Color32, Rect, Stroke, TextureHandle};

use super::command::Command;
use super::compare::{Compare, DiffStats};
use super::pixel::{Inspection, to_screen};
use super::state::EditState;
use super::worker::Worker;
use crate::accel::{Octree, OctreeCell};
use crate::camera::Camera;
use crate::render::RenderError;

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
    /// One of the inspected pixel's rays stepping through the octree.
    pub walk: super::walk_view::WalkView,
    pub compare: Option<Compare>,
}

fn color32(c: [u8; 3]) -> Color32 {
    Color32::from_rgb(c[0], c[1], c[2])
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
        reuse: crate::render::Reuse,
        pixel: (u32, u32),
    ) -> Result<(), RenderError> {
        if let Some(inspection) = Inspection::trace(edit, reuse, pixel)? {
            self.inspection = Some(inspection);
        }
        Ok(())
    }

    /// Keeps the frame on screen as "A", labelled with its settings.
    pub fn pin_as_a(&mut self, worker: &Worker, label: String) {
        if let Some(c) = Compare::pin(worker, label) {
            self.compare = Some(c);
        }
    }

    /// A versus B, when B is complete: the pixels that differ.
    pub fn compare_stats(&self, worker: &Worker) -> Option<DiffStats> {
        self.compare.as_ref()?.stats(worker)
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
        match &mut self.compare {
            Some(c) => c.image_ui(ui, image_rect, live, worker),
            None => false,
        }
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
            for (cell, color) in crate::image::overlay::styled_cells(&cells) {
                let color = color32(color);
                for (a, b) in crate::image::overlay::cell_segments(&camera, cell) {
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
                if let Some(cell) =
                    crate::image::overlay::cell_at(&camera, &cells, x as f64, y as f64)
                {
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
            ins.draw(&painter, &camera, image_rect, extent);
            super::walk_view::draw_walk(ins, &self.walk, &painter, &camera, image_rect);
        }
    }
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
        let mut depth = inspect
            .overlay_depth
            .unwrap_or(crate::limits::DEFAULT_OVERLAY_DEPTH);
        ui.label("to depth");
        ui.add(
            egui::DragValue::new(&mut depth)
                .update_while_editing(false)
                .range(0..=crate::limits::MAX_OCTREE_DEPTH),
        );
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
    if let Some(c) = &mut inspect.compare {
        c.controls_ui(stats, label, worker, ui);
    }
    commands
}
