//! The A/B comparison: a frame pinned as "A" beside the live image ("B"),
//! split by a divider or as their difference, with the pixels that differ
//! counted.

use egui::{Color32, Pos2, Rect, Sense, Stroke, TextureHandle, TextureOptions};

use super::worker::{PassRecord, Worker};

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

/// The passes of generation `generation` that count (no previews), e.g.
/// "1 sample 0.120 s, 16 samples 1.530 s".
pub fn timing_label(history: &[PassRecord], generation: u64) -> String {
    let parts: Vec<String> = history
        .iter()
        .filter(|r| r.generation == generation && r.kind.preview.is_none())
        .map(|r| format!("{} {:.3} s", r.kind.label(), r.seconds))
        .collect();
    if parts.is_empty() {
        "not finished".into()
    } else {
        parts.join(", ")
    }
}

impl Compare {
    /// The frame on screen kept as "A", labelled with its settings; `None`
    /// before anything is on screen.
    pub fn pin(worker: &Worker, label: String) -> Option<Self> {
        let (width, height, rgba, generation) =
            worker.with_buffer(|b| (b.width, b.height, b.rgba.clone(), b.generation));
        if width == 0 {
            return None;
        }
        Some(Compare {
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
        })
    }

    /// A versus B, when B is complete: the pixels that differ.
    pub fn stats(&self, worker: &Worker) -> Option<DiffStats> {
        let c = self;
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
    pub fn image_ui(
        &mut self,
        ui: &mut egui::Ui,
        image_rect: Rect,
        live: Option<&TextureHandle>,
        worker: &Worker,
    ) -> bool {
        let c = self;
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

    /// Mode, divider or gain, what A and B are, and how many pixels differ.
    pub fn controls_ui(
        &mut self,
        stats: Option<DiffStats>,
        label: &str,
        worker: &Worker,
        ui: &mut egui::Ui,
    ) {
        let b_timing = timing_label(&worker.history(), worker.generation());
        let c = self;
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::render::PassKind as Engine;
    use crate::settings::ViewMode;
    use crate::stats::RayCounts;
    use crate::viewer::worker::ShownPass;

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
            accel: crate::settings::Accel::Octree,
            anti_aliasing: true,
            width: 8,
            height: 8,
            finished_at: 0.0,
            one_sample_error: None,
            refined_pixels: None,
            view: ViewMode::Shaded,
            max_depth: 5,
            protocol: crate::settings::Protocol::Glint,
            from_cache: false,
            reuse: None,
        };
        let preview = ShownPass::drag_preview(super::super::worker::Preview::Reduced(
            super::super::worker::Reduced {
                divisor: 2,
                reflections: super::super::worker::Reflections::All,
                shadows: true,
            },
        ));
        let history = [
            pass(1, ShownPass::full(Engine::OneSample), 0.5),
            pass(2, preview, 0.01),
            pass(2, ShownPass::full(Engine::OneSample), 0.125),
            pass(2, ShownPass::full(Engine::Grid), 1.5),
        ];
        assert_eq!(
            timing_label(&history, 2),
            "1 sample 0.125 s, 16 samples 1.500 s"
        );
        assert_eq!(timing_label(&history, 3), "not finished");
    }
}
