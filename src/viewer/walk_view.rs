//! Stepping through one ray's walk of the octree: any ray of the
//! inspected pixel's tree (eye, reflection, refraction, shadow), step by
//! step or played at a pace, its cells drawn over the image and the
//! primitives each leaf tested listed beside it.

use egui::{Color32, Rect, Stroke};

use super::pixel::{Inspection, WalkTarget, to_screen};
use crate::accel::{QueryRecord, StepKind, WalkEnd, WalkStep};
use crate::camera::Camera;
use crate::math::DVec3;
use crate::render::ray_tree::RayNode;

/// The walk being stepped through.
#[derive(Clone, Debug)]
pub struct WalkView {
    pub target: Option<WalkTarget>,
    /// Steps shown so far (0: none yet).
    pub shown: usize,
    pub playing: bool,
    pub steps_per_second: f64,
    /// When the last step was taken while playing (seconds, egui's clock).
    last_step_at: f64,
}

impl Default for WalkView {
    fn default() -> Self {
        Self {
            target: None,
            shown: 0,
            playing: false,
            steps_per_second: 4.0,
            last_step_at: 0.0,
        }
    }
}

/// The ray a target names, and the query it ran (the shadow ray's when
/// the target is one), with where the ray starts and where it points.
pub struct WalkedRay<'a> {
    pub query: Option<&'a QueryRecord>,
    pub origin: DVec3,
    pub direction: DVec3,
    pub label: String,
}

/// Every ray of the inspected pixel's tree, as `--walk` names them
/// (`eye`, `eye/0`, `eye/0/shadow/1`, ...), eye ray first.
pub fn ray_names(inspection: &Inspection) -> Vec<String> {
    fn visit(node: &RayNode, name: String, out: &mut Vec<String>) {
        out.push(name.clone());
        for s in &node.shadows {
            out.push(format!("{name}/shadow/{}", s.light));
        }
        for (k, child) in node.children.iter().enumerate() {
            visit(child, format!("{name}/{k}"), out);
        }
    }
    let mut out = Vec::new();
    visit(&inspection.tree, "eye".into(), &mut out);
    out
}

pub fn walked_ray<'a>(inspection: &'a Inspection, target: &WalkTarget) -> Option<WalkedRay<'a>> {
    let mut node: &RayNode = &inspection.tree;
    for &k in &target.path {
        node = node.children.get(k)?;
    }
    let kind = format!("{:?} ray, depth {}", node.kind, node.depth).to_lowercase();
    match target.shadow {
        None => Some(WalkedRay {
            query: node.query.as_ref(),
            origin: DVec3::from_array(node.origin),
            direction: DVec3::from_array(node.direction),
            label: kind,
        }),
        Some(light) => {
            let record = node.shadows.iter().find(|s| s.light == light)?;
            let from = DVec3::from_array(node.hit.as_ref()?.point);
            let to = *inspection.lights.get(light)?;
            Some(WalkedRay {
                query: record.query.as_ref(),
                origin: from,
                direction: (to - from).normalize_or_zero(),
                label: format!("shadow ray to light {light} from the {kind}"),
            })
        }
    }
}

fn step_kind_name(kind: StepKind) -> &'static str {
    match kind {
        StepKind::Inner => "inner node",
        StepKind::Leaf => "leaf",
        StepKind::Empty => "empty octant",
        StepKind::Missed => "leaf, its shapes' box missed",
        StepKind::Unbounded => "unbounded shapes",
    }
}

fn end_text(end: WalkEnd) -> &'static str {
    match end {
        WalkEnd::HitInCell => "a hit nearer than this cell's exit: nothing beyond can be nearer",
        WalkEnd::CellsBeyondHit => "the cells left all start beyond the nearest hit",
        WalkEnd::Blocked => "an opaque surface blocks the light",
        WalkEnd::CellsBeyondLight => "the cells left all start beyond the light",
        WalkEnd::LeftOctree => "the ray left the octree",
        WalkEnd::MissedOctree => "the ray never enters the octree",
    }
}

/// The walk controls and the current step, under the ray tree.
pub fn walk_ui(inspection: Option<&Inspection>, view: &mut WalkView, ui: &mut egui::Ui) {
    let (Some(ins), Some(target)) = (inspection, view.target.clone()) else {
        ui.label("Click \"walk\" beside a ray to step through its octree walk.");
        return;
    };
    let Some(ray) = walked_ray(ins, &target) else {
        view.target = None;
        return;
    };
    ui.label(format!("Walk of the {}", ray.label));
    let Some(query) = ray.query else {
        ui.label("no query recorded for this ray");
        return;
    };
    let Some(steps) = &query.walk else {
        ui.label(format!(
            "Octree off: every primitive was tested, in index order ({} tests).",
            query.intersection_tests
        ));
        return;
    };
    let total = steps.len();
    view.shown = view.shown.min(total);
    ui.horizontal(|ui| {
        if ui.button("|<").on_hover_text("back to the start").clicked() {
            view.shown = 0;
            view.playing = false;
        }
        if ui.button("<").on_hover_text("previous step").clicked() {
            view.shown = view.shown.saturating_sub(1);
            view.playing = false;
        }
        let play = if view.playing { "Pause" } else { "Play" };
        if ui.button(play).clicked() {
            view.playing = !view.playing;
            if view.playing && view.shown == total {
                view.shown = 0;
            }
        }
        if ui.button(">").on_hover_text("next step").clicked() {
            view.shown = (view.shown + 1).min(total);
            view.playing = false;
        }
        ui.add(
            egui::DragValue::new(&mut view.steps_per_second)
                .range(0.5..=60.0)
                .speed(0.1)
                .suffix(" steps/s"),
        );
    });
    ui.add(egui::Slider::new(&mut view.shown, 0..=total).text(format!("of {total} steps")));
    if view.playing {
        let now = ui.input(|i| i.time);
        if now - view.last_step_at >= 1.0 / view.steps_per_second {
            view.last_step_at = now;
            view.shown += 1;
            if view.shown >= total {
                view.shown = total;
                view.playing = false;
            }
        }
        ui.ctx().request_repaint();
    }
    ui.label(format!(
        "traversal steps {}, intersection tests {}, leaves entered {}",
        query.traversal_steps, query.intersection_tests, query.leaves_visited
    ));
    if view.shown == 0 {
        return;
    }
    let step = &steps[view.shown - 1];
    step_ui(step, ui);
    if view.shown == total
        && let Some(end) = query.walk_end
    {
        ui.colored_label(
            Color32::from_rgb(255, 200, 120),
            format!("stops: {}", end_text(end)),
        );
    }
}

fn step_ui(step: &WalkStep, ui: &mut egui::Ui) {
    match (step.depth, step.t_enter, step.t_exit) {
        (Some(depth), Some(t0), Some(t1)) => ui.label(format!(
            "{} at depth {depth}: the ray is inside for t in [{t0:.4}, {t1:.4}]",
            step_kind_name(step.kind)
        )),
        _ => ui.label(format!(
            "{}, tested before the walk",
            step_kind_name(step.kind)
        )),
    };
    if let Some(tested) = &step.tested {
        if tested.is_empty() {
            ui.label("nothing new to test (every reference was tested before)");
        }
        for t in tested {
            let text = match t.t {
                Some(d) => format!("#{}: hit at t = {d:.4}", t.object),
                None => format!("#{}: miss", t.object),
            };
            let color = if t.hit {
                Color32::from_rgb(120, 230, 120)
            } else {
                Color32::GRAY
            };
            ui.colored_label(color, text);
        }
    }
}

/// The walk's cells so far over the image: cells entered in blue, empty
/// octants in grey, the current cell bright, and the ray's part inside it.
pub fn draw_walk(
    inspection: &Inspection,
    view: &WalkView,
    painter: &egui::Painter,
    camera: &Camera,
    image_rect: Rect,
) {
    let Some(ray) = view.target.as_ref().and_then(|t| walked_ray(inspection, t)) else {
        return;
    };
    let Some(steps) = ray.query.and_then(|q| q.walk.as_ref()) else {
        return;
    };
    let shown = &steps[..view.shown.min(steps.len())];
    let (w, h) = (camera.width(), camera.height());
    let line = |a: (f64, f64), b: (f64, f64), stroke: Stroke| {
        painter.line_segment(
            [
                to_screen(image_rect, w, h, a),
                to_screen(image_rect, w, h, b),
            ],
            stroke,
        );
    };
    for (k, step) in shown.iter().enumerate() {
        let (Some(min), Some(max)) = (step.min, step.max) else {
            continue;
        };
        let current = k + 1 == shown.len();
        let stroke = match (current, step.kind) {
            (true, _) => Stroke::new(2.5, Color32::from_rgb(255, 240, 60)),
            (false, StepKind::Empty | StepKind::Missed) => {
                Stroke::new(1.0, Color32::from_gray(110))
            }
            (false, StepKind::Leaf) => Stroke::new(1.0, Color32::from_rgb(90, 160, 255)),
            (false, _) => Stroke::new(1.0, Color32::from_rgb(60, 90, 170)),
        };
        let cell = crate::accel::OctreeCell {
            bounds: crate::math::Aabb::new(DVec3::from_array(min), DVec3::from_array(max)),
            depth: step.depth.unwrap_or(0),
            references: 0,
        };
        for (a, b) in crate::image::overlay::cell_segments(camera, &cell) {
            line(a, b, stroke);
        }
        if current
            && let (Some(t0), Some(t1)) = (step.t_enter, step.t_exit)
            && let Some((a, b)) = crate::image::overlay::project_segment(
                camera,
                ray.origin + t0 * ray.direction,
                ray.origin + t1 * ray.direction,
            )
        {
            line(a, b, Stroke::new(3.0, Color32::from_rgb(255, 80, 200)));
        }
    }
}
