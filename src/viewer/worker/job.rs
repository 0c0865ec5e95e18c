//! What the worker renders.

use std::sync::Arc;

use super::Preview;
use super::pass_cache::PassKey;
use crate::accel::{Bvh, Octree};
use crate::camera::CameraSpec;
use crate::render::{Accelerator, LightBufferSource, Reuse};
use crate::scene::Scene;
use crate::settings::RenderSettings;

/// What to render: the frame of `settings` (with anti-aliasing, its
/// 1-sample pass first, then the 16-sample pass).
#[derive(Clone)]
pub struct Job {
    pub scene: Arc<Scene>,
    pub octree: Arc<Octree>,
    /// The BVH over the scene's shapes when the settings ask for one.
    pub bvh: Option<Arc<Bvh>>,
    pub camera: CameraSpec,
    pub settings: RenderSettings,
    /// A preview while the user moves the camera, a light or a material:
    /// the render cache's, or a quick reduced 1-sample pass as simplified
    /// as the frame budget chose; `None`: the full progressive sequence.
    pub preview: Option<Preview>,
    /// The frame budget while moving (the viewer's setting): a
    /// render-cache preview aims at three quarters of it.
    pub frame_budget_ms: f64,
    /// Show a render-cache preview coloured by where each pixel came from
    /// (fresh ray, reused point by age, filled) instead of the picture.
    pub show_sources: bool,
    /// The caller's number for the input this job reflects (the viewer
    /// counts pointer events), carried to the display buffer so the UI
    /// can tell how new a shown frame is.
    pub serial: u64,
}

impl Job {
    /// The accelerator of this job's octree or BVH over `scene` (this
    /// job's, or an earlier version of it with the same shapes) at
    /// `settings`, with the light buffer `light_buffer` gives.
    pub(super) fn accelerator(
        &self,
        scene: &Scene,
        settings: &RenderSettings,
        light_buffer: LightBufferSource,
    ) -> Result<Accelerator, crate::accel::OctreeError> {
        let reuse = Reuse {
            octree: Some(Arc::clone(&self.octree)),
            bvh: self.bvh.clone(),
            light_buffer,
        };
        Accelerator::build(scene, settings, reuse)
    }

    /// What decides pass `pass` of this job, for the pass cache.
    pub(super) fn pass_key(&self, pass: crate::render::PassKind) -> PassKey {
        PassKey::of(
            (&self.scene, &self.octree),
            self.camera,
            self.settings,
            pass,
        )
    }
}
