//! What the worker renders.

use std::sync::Arc;

use super::Preview;
use super::pass_cache::PassKey;
use crate::accel::{Bvh, Octree};
use crate::camera::CameraSpec;
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
    /// Render only a quick 1-sample pass (while the user drags), at
    /// 1/`divisor` of the resolution and as simplified as the frame budget
    /// chose; `None`: the full progressive sequence.
    pub preview: Option<Preview>,
    /// The caller's number for the input this job reflects (the viewer
    /// counts pointer events), carried to the display buffer so the UI
    /// can tell how new a shown frame is.
    pub serial: u64,
}

impl Job {
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
