//! The viewer's octree tuning: the edited parameters, the tree built from
//! them, the unit costs a prediction needs and the "Suggest a setting" job.

use std::sync::Arc;
use std::time::Instant;

use super::GlintApp;
use crate::accel::{Bvh, Octree, OctreeParams};
use crate::render::{Renderer, UnitCosts};
use crate::scene::Scene;
use crate::settings::{Accel, RenderSettings};
use crate::shapes::Shape;
use crate::viewer::octree_panel::{RaySampleJob, SuggestionJob, SuggestionView, last_full_pass};

/// A BVH and what it was built over.
pub(super) struct BuiltBvh {
    shapes: Arc<Vec<Shape>>,
    pub tree: Arc<Bvh>,
    pub seconds: f64,
}

impl GlintApp {
    /// The BVH over the edited scene's shapes when the settings ask for
    /// one, built here the first time, as the octree is (it builds far
    /// faster than the octree).
    pub(super) fn bvh_if_chosen(&mut self) -> Option<Arc<Bvh>> {
        if self.edit.settings.accel != Accel::Bvh {
            return None;
        }
        let shapes = &self.edit.scene.shapes;
        if !self
            .bvh
            .as_ref()
            .is_some_and(|b| Arc::ptr_eq(&b.shapes, shapes))
        {
            let start = Instant::now();
            let tree = Bvh::build(shapes);
            self.bvh = Some(BuiltBvh {
                shapes: Arc::clone(shapes),
                tree: Arc::new(tree),
                seconds: start.elapsed().as_secs_f64(),
            });
        }
        self.bvh.as_ref().map(|b| Arc::clone(&b.tree))
    }

    /// Edits the octree parameters (an edit like any other: undone,
    /// saved, marked unsaved) and rebuilds the tree; the passes render
    /// again with it, so the times shown are the new tree's.
    pub fn set_octree_params(&mut self, params: OctreeParams) {
        Arc::make_mut(&mut self.edit.scene).octree_params = params;
        self.sync_octree();
    }

    /// Rebuilds the octree when the edited parameters (changed by the
    /// panel, undo or redo) are not the built tree's; a build that fails
    /// puts the built tree's parameters back, with the reason.
    pub(super) fn sync_octree(&mut self) {
        let wanted = self.edit.scene.octree_params;
        if self.octree.params() == wanted {
            return;
        }
        match build_octree(&self.edit.scene) {
            Ok((octree, seconds)) => {
                self.octree = Arc::new(octree);
                self.build_seconds = seconds;
            }
            Err(e) => {
                Arc::make_mut(&mut self.edit.scene).octree_params = self.octree.params();
                self.say(format!("octree not rebuilt: {e:#}"), true);
            }
        }
    }

    /// Starts working out a suggested octree setting in the background,
    /// for the last full pass's rays.
    pub(super) fn suggest_octree(&mut self) {
        let history = self.worker.history();
        let (Some(costs), Some(pass)) = (self.unit_costs, last_full_pass(&history)) else {
            return;
        };
        self.suggestion = Some(SuggestionJob::start(
            self.view_for_octree(),
            costs,
            pass.rays.total(),
            self.worker.threads(),
            self.edit.scene_version,
        ));
    }

    /// Samples the view's rays through the current tree on a thread of its
    /// own, once per tree (not again as the camera moves).
    pub(super) fn sample_rays(&mut self) {
        let taken = self
            .ray_sample
            .as_ref()
            .is_some_and(|job| Arc::ptr_eq(&job.octree, &self.octree));
        if !taken {
            self.ray_sample = Some(RaySampleJob::start(self.view_for_octree()));
        }
    }

    /// The scene, tree and view as they are now, for work on other threads.
    fn view_for_octree(&self) -> SuggestionView {
        SuggestionView {
            scene: Arc::clone(&self.edit.scene),
            octree: Arc::clone(&self.octree),
            settings: RenderSettings {
                accel: Accel::Octree,
                ..self.edit.settings
            },
            camera: self.edit.camera,
        }
    }

    /// Measures the unit costs of the installed scene once its first pass
    /// has shown it renders (a thumbnail render, some tens of milliseconds),
    /// and drops a suggestion made for another scene.
    pub(super) fn octree_tuning_logic(&mut self, ctx: &egui::Context) {
        if self
            .suggestion
            .as_ref()
            .is_some_and(|s| s.scene_version != self.edit.scene_version)
        {
            self.suggestion = None;
        }
        if self
            .suggestion
            .as_ref()
            .is_some_and(|s| s.result().is_none())
        {
            ctx.request_repaint_after(std::time::Duration::from_millis(100));
        }
        if self.unit_costs.is_none() && !self.worker.history().is_empty() {
            let settings = RenderSettings {
                accel: Accel::Octree,
                ..self.edit.settings
            };
            let reuse = crate::render::Reuse::octree_alone(&self.octree);
            if let Ok(accel) = crate::render::Accelerator::build(&self.edit.scene, &settings, reuse)
                && let Ok(renderer) =
                    Renderer::with_camera(&self.edit.scene, &accel, settings, &self.edit.camera)
            {
                self.unit_costs = UnitCosts::measure(&renderer, &self.octree).ok();
            }
        }
        if self
            .ray_sample
            .as_ref()
            .is_some_and(RaySampleJob::is_running)
        {
            ctx.request_repaint_after(std::time::Duration::from_millis(100));
        }
    }
}

pub(super) fn build_octree(scene: &Scene) -> anyhow::Result<(Octree, f64)> {
    let start = Instant::now();
    let octree = scene
        .build_octree()
        .map_err(|e| anyhow::anyhow!("{}: {e}", scene.name))?;
    Ok((octree, start.elapsed().as_secs_f64()))
}
