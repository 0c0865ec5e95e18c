//! The octree's parameters, what the tree they build is predicted to cost
//! (before any render: the tree is rebuilt, nothing is rendered), and a
//! suggested setting worked out in the background, applied with a click.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

use egui::DragValue;

use super::command::Command;
use super::worker::PassRecord;
use crate::accel::{Octree, OctreeParams};
use crate::camera::CameraSpec;
use crate::limits::MAX_OCTREE_DEPTH;
use crate::render::PassKind as Engine;
use crate::render::{
    OctreeCandidate, Prediction, RaySample, Renderer, UnitCosts, sample_rays, suggest_octree,
};
use crate::scene::Scene;
use crate::settings::RenderSettings;

/// A suggestion being worked out on its own thread, for one scene version.
pub struct SuggestionJob {
    pub scene_version: u64,
    /// `None` while it runs; then the suggested candidate (`None` if no
    /// setting fitted the memory budget).
    result: Arc<Mutex<Option<Option<OctreeCandidate>>>>,
    cancel: Arc<AtomicBool>,
}

impl SuggestionJob {
    /// Builds the suggestion grid's trees and traces a thumbnail of the
    /// view through each (renders nothing else), predicting a render of
    /// `rays` rays on `threads` threads.
    pub fn start(
        view: SuggestionView,
        costs: UnitCosts,
        rays: u64,
        threads: usize,
        scene_version: u64,
    ) -> Self {
        let result = Arc::new(Mutex::new(None));
        let cancel = Arc::new(AtomicBool::new(false));
        let (out, stop) = (Arc::clone(&result), Arc::clone(&cancel));
        std::thread::spawn(move || {
            let keep_going = || !stop.load(Ordering::Relaxed);
            let found = view.accelerator().and_then(|accel| {
                let renderer =
                    Renderer::with_camera(&view.scene, &accel, view.settings, &view.camera).ok()?;
                suggest_octree(&renderer, &costs, rays, threads, &keep_going)
            });
            if let Ok(mut slot) = out.lock() {
                *slot = Some(found.map(|(candidates, best)| candidates[best]));
            }
        });
        Self {
            scene_version,
            result,
            cancel,
        }
    }

    /// `None` while it runs.
    pub fn result(&self) -> Option<Option<OctreeCandidate>> {
        self.result.lock().ok().and_then(|r| *r)
    }
}

impl Drop for SuggestionJob {
    fn drop(&mut self) {
        self.cancel.store(true, Ordering::Relaxed);
    }
}

/// The current tree's [`RaySample`], taken on its own thread (a thumbnail
/// of the view traced four times: up to a few tenths of a second on the
/// heaviest bundled scenes, too long for the frame it would stall).
pub struct RaySampleJob {
    pub octree: Arc<Octree>,
    /// `None` while it runs; then the sample (`None` if the view could not
    /// be rendered).
    result: Arc<Mutex<Option<Option<RaySample>>>>,
}

impl RaySampleJob {
    pub fn start(view: SuggestionView) -> Self {
        let result = Arc::new(Mutex::new(None));
        let out = Arc::clone(&result);
        let octree = Arc::clone(&view.octree);
        std::thread::spawn(move || {
            let sample = view.accelerator().and_then(|accel| {
                let renderer =
                    Renderer::with_camera(&view.scene, &accel, view.settings, &view.camera).ok()?;
                sample_rays(&renderer, &view.octree).ok()
            });
            if let Ok(mut slot) = out.lock() {
                *slot = Some(sample);
            }
        });
        Self { octree, result }
    }

    /// `None` while it runs or if the view could not be rendered.
    pub fn result(&self) -> Option<RaySample> {
        self.result.lock().ok().and_then(|r| r.flatten())
    }

    pub fn is_running(&self) -> bool {
        self.result.lock().is_ok_and(|r| r.is_none())
    }
}

/// The view a suggestion or a ray sample is worked out for: its
/// thumbnails are of it.
pub struct SuggestionView {
    pub scene: Arc<Scene>,
    pub octree: Arc<Octree>,
    pub settings: RenderSettings,
    pub camera: CameraSpec,
}

impl SuggestionView {
    /// The view's octree as its thumbnails' accelerator (`settings` ask
    /// for the octree).
    fn accelerator(&self) -> Option<crate::render::Accelerator> {
        let reuse = crate::render::Reuse::octree_alone(&self.octree);
        crate::render::Accelerator::build(&self.scene, &self.settings, reuse).ok()
    }
}

/// What the panel shows besides the parameters.
pub struct OctreeInfo<'a> {
    pub octree: &'a Octree,
    pub build_seconds: f64,
    pub unit_costs: Option<UnitCosts>,
    /// The last full pass: its rays are what a render will cast again (the
    /// octree changes the time, never the rays).
    pub last_pass: Option<&'a PassRecord>,
    pub threads: usize,
    pub suggestion: Option<&'a SuggestionJob>,
    /// The current tree's work per ray on a thumbnail of the view as it
    /// was when the tree was built (`None` until measured).
    pub ray_sample: Option<RaySample>,
    /// Whether the current tree's sample is taken or being taken.
    pub ray_sample_taken: bool,
}

/// The last pass that was not a drag preview.
pub fn last_full_pass(history: &[PassRecord]) -> Option<&PassRecord> {
    history.iter().rev().find(|r| r.kind.preview.is_none())
}

/// The predictions for the current tree and the last pass's rays, from
/// the tree alone and (once measured) from the sample of rays.
pub fn prediction(info: &OctreeInfo) -> Option<(Prediction, Option<Prediction>, &'static str)> {
    let costs = info.unit_costs?;
    let pass = info.last_pass?;
    let kind = match pass.kind.pass {
        Engine::Grid | Engine::Refine => "16-sample pass",
        Engine::Corners => "SPD pass",
        Engine::OneSample => "1-sample pass",
    };
    let rays = pass.rays.total();
    Some((
        costs.predict(info.octree.predicted_cost(), rays, info.threads),
        info.ray_sample
            .map(|sample| sample.predict(rays, info.threads)),
        kind,
    ))
}

pub fn octree_ui(params: OctreeParams, info: &OctreeInfo, ui: &mut egui::Ui) -> Vec<Command> {
    let mut commands = Vec::new();
    let mut edited = params;
    egui::Grid::new("octree parameters")
        .num_columns(2)
        .show(ui, |ui| {
            ui.label("Max depth");
            ui.add(
                DragValue::new(&mut edited.max_depth)
                    .update_while_editing(false)
                    .range(0..=MAX_OCTREE_DEPTH),
            )
            .on_hover_text("deepest level a cell is split to (root = 0)");
            ui.end_row();
            ui.label("Leaf size");
            ui.add(
                DragValue::new(&mut edited.leaf_size)
                    .update_while_editing(false)
                    .range(1..=1024),
            )
            .on_hover_text("references up to which a node stays a leaf");
            ui.end_row();
            ui.label("Max duplication");
            ui.add(
                DragValue::new(&mut edited.max_duplication)
                    .update_while_editing(false)
                    .range(1..=8),
            )
            .on_hover_text(
                "keep a node a leaf when its children would hold more than this many times \
                 its references (8 never stops a split)",
            );
            ui.end_row();
            ui.label("Cost-driven");
            ui.checkbox(&mut edited.cost_driven, "")
                .on_hover_text("let the surface-area cost estimate stop subdivision early");
            ui.end_row();
        });
    if edited != params {
        commands.push(Command::SetOctreeParams(edited));
    }
    let stats = info.octree.stats();
    ui.label(format!(
        "{} nodes ({} leaves, {} empty), {:.1} KiB, built in {:.3} s",
        stats.nodes,
        stats.leaves,
        stats.empty_leaves,
        stats.memory_bytes as f64 / 1024.0,
        info.build_seconds
    ));
    let cost = info.octree.predicted_cost();
    ui.label(format!(
        "Predicted per ray from the tree: {:.1} traversal steps, {:.1} intersection tests",
        cost.traversal_steps_per_ray, cost.intersection_tests_per_ray
    ))
    .on_hover_text(
        "from the tree alone (surface areas: a ray crossing a cell crosses each octant with \
         chance 1/4), for rays that cross the scene's box, ignoring that rays stop at their \
         first hit: an upper bound, good for comparing settings of one scene",
    );
    // Sampled only while the panel is open: nobody else reads it, and it
    // would compete with the passes for the cores.
    if !info.ray_sample_taken && info.last_pass.is_some() {
        commands.push(Command::SampleRays);
    }
    let sample_text = match info.ray_sample {
        Some(sample) => format!(
            "From a sample of the view's rays: {:.1} traversal steps, {:.1} intersection tests",
            sample.traversal_steps_per_ray, sample.intersection_tests_per_ray
        ),
        // The line is there from the start, so the button below does not
        // move under the pointer when the sample comes in.
        None => "From a sample of the view's rays: tracing a thumbnail…".to_owned(),
    };
    ui.label(sample_text).on_hover_text(
        "a 64-pixel thumbnail of the view when the tree was built, its shadow and secondary \
         rays included, traced through this tree with the walk's counters and timed: what \
         the view's rays actually do, so it holds across scenes \
         (docs/speed-and-accuracy.md)",
    );
    if let Some((p, from_rays, kind)) = prediction(info) {
        let total = |p: Prediction| info.build_seconds + p.render_s;
        ui.label(match from_rays {
            Some(q) => format!(
                "Predicted {kind}: {:.2} s from the rays, {:.2} s from the tree \
                 (build + render {:.2} s)",
                q.render_s,
                p.render_s,
                total(q)
            ),
            None => format!(
                "Predicted {kind}: {:.2} s (build + render {:.2} s)",
                p.render_s,
                total(p)
            ),
        });
        if let Some(pass) = info
            .last_pass
            .filter(|p| p.accel == crate::settings::Accel::Octree && !p.from_cache)
        {
            ui.label(format!("Measured, the last {kind}: {:.2} s", pass.seconds));
        }
    }
    ui.horizontal(|ui| {
        let running = info.suggestion.is_some_and(|s| s.result().is_none());
        let can_suggest = info.unit_costs.is_some() && info.last_pass.is_some() && !running;
        if ui
            .add_enabled(can_suggest, egui::Button::new("Suggest a setting"))
            .on_hover_text(
                "build the tree at max depths 4-12 and leaf sizes 1-16, trace a thumbnail of the \
                 view through each, and pick the least build + predicted render time",
            )
            .clicked()
        {
            commands.push(Command::SuggestOctree);
        }
        if running {
            ui.spinner();
            ui.label("building 25 trees");
        }
    });
    if let Some(Some(best)) = info.suggestion.and_then(|s| s.result()) {
        let p = best.params;
        // The button on a line of its own: beside the label, the fixed-width
        // panel clipped it to a sliver.
        ui.label(format!(
            "Suggested: depth {}, leaf size {} ({:.2} s predicted)",
            p.max_depth,
            p.leaf_size,
            best.predicted_total_s()
        ));
        if ui
            .add_enabled(p != params, egui::Button::new("Apply"))
            .clicked()
        {
            commands.push(Command::SetOctreeParams(p));
        }
    } else if let Some(None) = info.suggestion.and_then(|s| s.result()) {
        ui.label("No setting of the grid fits the octree's memory budget.");
    }
    commands
}
