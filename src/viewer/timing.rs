//! The timing panel: the passes of the image on screen (times, their
//! ratio, the error anti-aliasing removes, rays, the octree's figures), the
//! plot of every pass this session, and the view's colour scale.

use egui::{Color32, RichText};
use egui_plot::{Legend, Line, Plot, Points};

use super::inspect::InspectState;
use super::panels::RenderInfo;
use super::state::EditState;
use super::worker::{PassRecord, ShownPass, Worker};
use crate::render::PassKind as Engine;
use crate::settings::{Accel, ViewMode};

/// Pass times and ray counts, the octree's figures, the view's legend and
/// the inspected pixel's ray tree.
pub fn timing_ui(
    edit: &EditState,
    info: &RenderInfo,
    inspect: &mut InspectState,
    ui: &mut egui::Ui,
) {
    // Scrolls down only: every line wraps at the fixed-width panel (a line
    // that ran off it would need a scroll bar at the bottom of a long
    // panel, out of sight).
    egui::ScrollArea::vertical().show(ui, |ui| {
        timing_grid_ui(edit, info, ui);
        legend_ui(info.worker, ui);
        ui.separator();
        ui.heading("Pixel");
        // The walk first once a ray is picked: the tree can be long.
        if inspect.inspection.is_some() && inspect.walk.target.is_some() {
            ui.label(egui::RichText::new("Octree walk").strong());
            super::walk_view::walk_ui(inspect.inspection.as_ref(), &mut inspect.walk, ui);
            ui.separator();
        }
        let picked = super::pixel::ray_tree_ui(inspect.inspection.as_ref(), ui);
        if let Some(target) = picked {
            inspect.walk.target = Some(target);
            inspect.walk.shown = 0;
            inspect.walk.playing = false;
        }
    });
}

/// The colour scale of the cost and aa-need views, from the shown frame.
fn legend_ui(worker: &Worker, ui: &mut egui::Ui) {
    let legend = worker
        .try_with_buffer(|b| b.last_frame.as_ref().and_then(|f| f.legend()))
        .flatten();
    let Some(legend) = legend else { return };
    ui.separator();
    ui.label(RichText::new(&legend.caption).strong());
    let (rect, _) =
        ui.allocate_exact_size(egui::vec2(ui.available_width(), 14.0), egui::Sense::hover());
    let n = 64;
    for k in 0..n {
        let t = k as f64 / (n - 1) as f64;
        let c = legend.ramp.color(t);
        let x0 = rect.min.x + rect.width() * k as f32 / n as f32;
        let x1 = rect.min.x + rect.width() * (k + 1) as f32 / n as f32;
        ui.painter().rect_filled(
            egui::Rect::from_min_max(egui::pos2(x0, rect.min.y), egui::pos2(x1 + 0.5, rect.max.y)),
            0.0,
            Color32::from_rgb(c[0], c[1], c[2]),
        );
    }
    ui.horizontal(|ui| {
        ui.label(&legend.low);
        ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
            ui.label(&legend.high);
        });
    });
}

/// A pass's time; one shown again from the worker's cache says so (its
/// time is what it took when it was rendered).
fn pass_time(r: &PassRecord) -> String {
    if r.from_cache {
        format!("{:.3} s (kept: not rendered again)", r.seconds)
    } else {
        format!("{:.3} s", r.seconds)
    }
}

fn timing_grid_ui(edit: &EditState, info: &RenderInfo, ui: &mut egui::Ui) {
    let history = info.worker.history();
    ui.heading("Timing");
    // Figures compare passes of one image only: those of the newest
    // generation that has a full pass (a preview is not one), so a toggle
    // never shows a new 1-sample time against an old 16-sample time.
    // The newest full job's image: while it renders, its rows read
    // "rendering…" rather than the figures of the image before (an octree
    // toggle must never show the old tree's time beside the new setting).
    let newest_record = history
        .iter()
        .rev()
        .find(|r| r.kind.preview.is_none())
        .map(|r| r.generation);
    let submitted = info.worker.full_generation();
    let shown = match newest_record {
        Some(g) if g >= submitted => Some(g),
        _ if submitted > 0 => Some(submitted),
        other => other,
    };
    let of_shown = |kind: fn(ShownPass) -> bool| {
        history
            .iter()
            .rev()
            .find(|r| Some(r.generation) == shown && kind(r.kind))
    };
    let (stopped, finished) = info
        .worker
        .try_with_buffer(|b| (b.stopped, b.generation == shown.unwrap_or(0) && b.finished))
        .unwrap_or((false, false));
    let rendering = !finished && !stopped;
    egui::Grid::new("timing-grid")
        .num_columns(2)
        .max_col_width(170.0)
        .striped(true)
        .show(ui, |ui| {
            // Values wrap rather than widen the (fixed-width) panel.
            let mut row = |label: &str, value: String| {
                ui.label(label);
                ui.add(egui::Label::new(value).wrap());
                ui.end_row();
            };
            let pending = if rendering {
                "rendering…"
            } else if stopped {
                "stopped"
            } else {
                "–"
            };
            if let Some(r) = of_shown(|k| k == ShownPass::full(Engine::Corners)) {
                row("SPD corner pass", pass_time(r));
            } else {
                let one = of_shown(|k| k == ShownPass::full(Engine::OneSample));
                let sixteen = of_shown(ShownPass::is_grid);
                row("1-sample pass", one.map_or(pending.into(), pass_time));
                if edit.settings.samples > 1 || sixteen.is_some() {
                    // Which 16-sample pass ran: the two differ in time
                    // far more than in the picture (docs/speed-and-accuracy.md,
                    // "Adaptive anti-aliasing").
                    let adaptive =
                        sixteen.map_or(edit.settings.adaptive, |r| r.refined_pixels.is_some());
                    let label = if adaptive {
                        "16-sample pass (adaptive)"
                    } else {
                        "16-sample pass (full 4x4 grid)"
                    };
                    row(label, sixteen.map_or(pending.into(), pass_time));
                }
                if let Some(r) = sixteen
                    && let Some(refined) = r.refined_pixels
                {
                    row(
                        "refined (adaptive)",
                        format!(
                            "{:.1}% of pixels",
                            100.0 * refined as f64 / (r.width as f64 * r.height as f64).max(1.0)
                        ),
                    );
                }
                if let (Some(a), Some(b)) = (one, sixteen) {
                    row(
                        "16 / 1 time ratio",
                        format!("{:.1}x", b.seconds / a.seconds.max(1e-9)),
                    );
                    // An error of pictures: not of depth, normals or costs.
                    if b.view == ViewMode::Shaded
                        && let Some(e) = b.one_sample_error
                    {
                        row(
                            "1-sample error vs 16",
                            format!("RMSE {:.4}, {:.1} dB", e.rmse_display, e.psnr_display),
                        );
                        row(
                            "pixels AA changes",
                            format!("{:.1}% (> 1/255)", 100.0 * e.visible_fraction),
                        );
                    }
                }
            }
            if let Some((p, estimate)) = info.last_preview {
                let measured = history.iter().rev().find(|r| r.kind.preview == Some(p));
                row(
                    "while moving",
                    match measured {
                        Some(r) => format!(
                            "{} ({:.0} ms; est. {:.0} of {:.0})",
                            p.describe(),
                            1000.0 * r.seconds,
                            1000.0 * estimate,
                            edit.frame_budget_ms
                        ),
                        None => format!("{} (est. {:.0} ms)", p.describe(), 1000.0 * estimate),
                    },
                );
            }
            if let Some(r) = history.iter().rev().find(|r| Some(r.generation) == shown) {
                row(
                    "Mrays/s (last pass)",
                    format!("{:.2}", r.rays.total() as f64 / r.seconds.max(1e-9) / 1e6),
                );
                row("rays: primary", format!("{}", r.rays.primary));
                row("rays: shadow", format!("{}", r.rays.shadow));
                row("rays: reflection", format!("{}", r.rays.reflection));
                row("rays: refraction", format!("{}", r.rays.refraction));
            }
            // The accelerator's build: (name, seconds, nodes, leaves, bytes).
            let built = match (edit.settings.accel, info.bvh) {
                (Accel::Bvh, Some((bvh, seconds))) => {
                    let s = bvh.stats();
                    Some(("BVH", seconds, s.nodes, s.leaves, s.memory_bytes))
                }
                (Accel::Octree, _) => {
                    let s = info.octree.stats();
                    Some((
                        "octree",
                        info.build_seconds,
                        s.nodes,
                        s.leaves,
                        s.memory_bytes,
                    ))
                }
                _ => None,
            };
            if let Some((name, seconds, nodes, leaves, bytes)) = built {
                row(&format!("{name} build"), format!("{seconds:.3} s"));
                row(
                    &format!("{name} nodes"),
                    format!("{nodes} ({leaves} leaves)"),
                );
                row(
                    &format!("{name} memory"),
                    format!("{:.1} KiB", bytes as f64 / 1024.0),
                );
            } else {
                row(
                    "octree",
                    format!(
                        "off: every ray tests all {} primitives",
                        edit.scene.shapes.len()
                    ),
                );
            }
            if let Some((stats, seconds)) = info.worker.light_buffer() {
                // Lights without a cube walk the accelerator.
                let lights = if stats.cubes == stats.lights {
                    format!("{} lights", stats.lights)
                } else {
                    format!("{} of {} lights", stats.cubes, stats.lights)
                };
                let kib = stats.memory_bytes as f64 / 1024.0;
                row(
                    "light buffer",
                    format!("{seconds:.3} s, {lights}, {kib:.0} KiB"),
                );
            }
            row("shapes", format!("{}", edit.scene.shapes.len()));
        });
    ui.separator();
    pass_plot_ui(&history, ui);
}

/// The round number (1, 2 or 5 times a power of ten) nearest above `x`.
fn round_step(x: f64) -> f64 {
    if !(x > 0.0) {
        return 1.0;
    }
    let power = 10f64.powf(x.log10().floor());
    [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * power)
        .find(|&s| s >= x)
        .unwrap_or(10.0 * power)
}

/// A session-time tick: blank left of 0 (the legend's room) and within
/// half a label's width of the right edge (where it would be cut), with as
/// many decimals as the step needs so that neighbouring ticks never read
/// alike.
fn time_tick_label(value: f64, step: f64, right_edge: f64) -> String {
    if value < -0.5 * step || value > right_edge - 0.25 * step {
        return String::new();
    }
    let decimals = if step >= 1.0 {
        0
    } else {
        (-step.log10()).ceil() as usize
    };
    // Grid values carry rounding error: the tick at 0 may be -1e-17.
    let value = if value.abs() < 0.5 * step { 0.0 } else { value };
    format!("{value:.decimals$}")
}

/// Which series of the plot a pass belongs to: passes of one kind (1 or
/// 16 samples, SPD corners), octree setting and view are comparable.
#[derive(Clone, Copy, PartialEq)]
struct SeriesKey {
    accel: Accel,
    /// The full pass (adaptive refinement counted with the full grid: the
    /// same anti-aliasing, as a user sees it).
    kind: Engine,
    view: ViewMode,
}

impl SeriesKey {
    fn of(r: &PassRecord) -> Self {
        Self {
            accel: r.accel,
            kind: if r.kind.is_grid() {
                Engine::Grid
            } else {
                r.kind.pass
            },
            view: r.view,
        }
    }

    /// E.g. "octree on, 16 spp" or "octree off, 1 spp, cost view".
    fn name(&self) -> String {
        let kind = match self.kind {
            Engine::Grid | Engine::Refine => "16 spp",
            Engine::Corners => "SPD corners",
            Engine::OneSample => "1 spp",
        };
        let accel = match self.accel {
            Accel::Octree => "octree on",
            Accel::Bvh => "BVH",
            Accel::BruteForce => "octree off",
        };
        let mut name = format!("{accel}, {kind}");
        if self.view != ViewMode::Shaded {
            name += &format!(", {} view", self.view.name());
        }
        name
    }
}

/// Every full pass of the session, one series per octree setting, pass
/// kind and view, so each toggle shows as a jump between series, on a
/// logarithmic time axis (a 100 s pass with the octree off must not
/// flatten the rest).
fn pass_plot_ui(history: &[PassRecord], ui: &mut egui::Ui) {
    ui.label("Pass times this session (log scale)");
    const COLORS: [Color32; 8] = [
        Color32::from_rgb(80, 160, 255),
        Color32::from_rgb(60, 200, 120),
        Color32::from_rgb(255, 120, 80),
        Color32::from_rgb(230, 190, 60),
        Color32::from_rgb(200, 110, 230),
        Color32::from_rgb(90, 210, 220),
        Color32::from_rgb(240, 110, 160),
        Color32::from_rgb(170, 170, 170),
    ];
    // Passes shown again from the cache took no time now.
    let full: Vec<_> = history
        .iter()
        .filter(|r| r.kind.preview.is_none() && !r.from_cache)
        .collect();
    // Series in order of first appearance, each keeping its colour.
    let mut keys: Vec<SeriesKey> = Vec::new();
    for r in &full {
        let key = SeriesKey::of(r);
        if !keys.contains(&key) {
            keys.push(key);
        }
    }
    let log = |s: f64| s.max(1e-4).log10();
    // Whole decades around the data, so the axis always shows at least two
    // labelled ticks; the time axis starts at 0 and reaches past the newest
    // point, leaving room on the left for the legend.
    let (lo, hi) = full
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), r| {
            (lo.min(log(r.seconds)), hi.max(log(r.seconds)))
        });
    let (lo, hi) = if lo.is_finite() {
        (lo.floor(), hi.ceil().max(lo.floor() + 1.0))
    } else {
        (-2.0, 0.0)
    };
    let newest = full.iter().map(|r| r.finished_at).fold(1.0f64, f64::max);
    Plot::new("pass-times")
        .height(190.0)
        .legend(Legend::default().position(egui_plot::Corner::LeftTop))
        .allow_drag(false)
        .allow_zoom(false)
        .allow_scroll(false)
        .include_y(lo)
        // Room above the data for the legend, a row per series.
        .include_y(hi + 0.3 * keys.len().max(2) as f64)
        .include_x(-0.35 * newest)
        .include_x(newest * 1.05)
        .x_axis_label("session time (s)")
        // Labelled ticks at a round step, about three across the axis:
        // egui_plot hides labels closer than 60 points, and the plot is
        // about 250 points wide.
        .x_grid_spacer(egui_plot::uniform_grid_spacer(|input| {
            let step = round_step((input.bounds.1 - input.bounds.0) / 3.0);
            [step, step, step]
        }))
        .y_grid_spacer(egui_plot::uniform_grid_spacer(|_| [1.0, 1.0, 1.0]))
        .y_axis_formatter(|mark, _| {
            let seconds = 10f64.powf(mark.value);
            if seconds < 1.0 {
                format!("{:.0} ms", seconds * 1000.0)
            } else {
                format!("{seconds:.0} s")
            }
        })
        .x_axis_formatter(|mark, range| time_tick_label(mark.value, mark.step_size, *range.end()))
        .show(ui, |plot| {
            for (k, key) in keys.iter().enumerate() {
                let color = COLORS[k % COLORS.len()];
                let name = key.name();
                let points: Vec<[f64; 2]> = full
                    .iter()
                    .filter(|r| SeriesKey::of(r) == *key)
                    .map(|r| [r.finished_at, log(r.seconds)])
                    .collect();
                plot.line(Line::new(name.clone(), points.clone()).color(color));
                plot.points(Points::new(name, points).color(color).radius(3.0));
            }
        });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_steps_are_one_two_or_five_times_a_power_of_ten() {
        assert_eq!(round_step(0.28), 0.5);
        assert_eq!(round_step(8.1), 10.0);
        assert_eq!(round_step(13.0), 20.0);
        assert_eq!(round_step(2.0), 2.0);
        assert_eq!(round_step(0.0), 1.0);
        assert_eq!(round_step(f64::NAN), 1.0);
    }

    #[test]
    fn neighbouring_time_ticks_never_read_alike() {
        // A session under a second: steps of 0.5 once printed "0 0 1".
        let labels: Vec<_> = [-0.5, -1e-17, 0.5, 1.0]
            .iter()
            .map(|&v| time_tick_label(v, 0.5, 10.0))
            .collect();
        assert_eq!(labels, ["", "0.0", "0.5", "1.0"]);
        assert_eq!(time_tick_label(0.2, 0.1, 10.0), "0.2");
        assert_eq!(time_tick_label(0.05, 0.05, 10.0), "0.05");
        assert_eq!(time_tick_label(30.0, 10.0, 100.0), "30");
        assert_eq!(time_tick_label(-10.0, 10.0, 100.0), "");
        // A tick at the plot's right edge would be cut in half: blank.
        assert_eq!(time_tick_label(40.0, 10.0, 41.0), "");
        assert_eq!(time_tick_label(30.0, 10.0, 41.0), "30");
    }

    #[test]
    fn series_say_what_their_passes_are() {
        let key = |accel, kind, view| SeriesKey { accel, kind, view };
        assert_eq!(
            key(Accel::Octree, Engine::OneSample, ViewMode::Shaded).name(),
            "octree on, 1 spp"
        );
        assert_eq!(
            key(Accel::BruteForce, Engine::Grid, ViewMode::Cost).name(),
            "octree off, 16 spp, cost view"
        );
        assert_eq!(
            key(Accel::Octree, Engine::Corners, ViewMode::Shaded).name(),
            "octree on, SPD corners"
        );
        assert_eq!(
            key(Accel::Bvh, Engine::Grid, ViewMode::Shaded).name(),
            "BVH, 16 spp"
        );
    }
}
