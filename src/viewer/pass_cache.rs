//! The worker's pass cache: the last few finished passes, found again by
//! what decides them, so switching back to an image already rendered shows
//! it at once.

use crate::settings::Accel;
use std::sync::{Arc, Weak};

use crate::accel::Octree;
use crate::camera::CameraSpec;
use crate::image::frame::Frame;
use crate::scene::Scene;
use crate::settings::RenderSettings;

/// What decides a pass: the scene (by identity: an edit makes a new one),
/// the camera, the settings as the pass traces them (its own sampling, the
/// shaded view for aa-need) and, for the cost views and whenever the
/// octree is on, the octree itself (its tests are what the cost views
/// show; its times are what a user rebuilds it to see). The octree switch
/// is part of the settings although the pixels do not depend on it: its
/// time is what a user toggles it to see.
///
/// Scene and octree are held weakly: the cache does not keep an edited-away
/// scene alive, and the allocation a weak pointer holds cannot be reused by
/// another scene, so equal pointers are the same scene.
#[derive(Clone)]
pub(super) struct PassKey {
    scene: Weak<Scene>,
    octree: Option<Weak<Octree>>,
    camera: CameraSpec,
    settings: RenderSettings,
    pass: crate::render::PassKind,
}

impl PassKey {
    /// The key of pass `pass` of a job that renders `scene` through
    /// `octree` from `camera` with `job_settings`: what the engine says the
    /// pass traces ([`crate::render::pass_settings`]).
    pub(super) fn of(
        (scene, octree): (&Arc<Scene>, &Arc<Octree>),
        camera: CameraSpec,
        job_settings: RenderSettings,
        pass: crate::render::PassKind,
    ) -> Self {
        use crate::settings::ViewMode;
        let settings = crate::render::pass_settings(job_settings, pass);
        let counts_tests = matches!(settings.view, ViewMode::Cost | ViewMode::CostSteps);
        PassKey {
            scene: Arc::downgrade(scene),
            octree: (counts_tests || settings.accel == Accel::Octree)
                .then(|| Arc::downgrade(octree)),
            camera,
            settings,
            pass,
        }
    }

    fn matches(&self, other: &PassKey) -> bool {
        Weak::ptr_eq(&self.scene, &other.scene)
            && match (&self.octree, &other.octree) {
                (Some(a), Some(b)) => Weak::ptr_eq(a, b),
                (None, None) => true,
                _ => false,
            }
            && self.camera == other.camera
            && self.settings == other.settings
            && self.pass == other.pass
    }
}

pub(super) struct CachedPass<R> {
    pub key: PassKey,
    pub frame: Frame,
    /// The worker's record of the pass.
    pub record: R,
}

/// The last few finished passes, newest last, within a memory bound: a
/// view or anti-aliasing switch back to an image already rendered shows
/// it at once.
pub(super) struct PassCache<R> {
    entries: Vec<CachedPass<R>>,
}

impl<R> Default for PassCache<R> {
    fn default() -> Self {
        Self {
            entries: Vec::new(),
        }
    }
}

impl<R> PassCache<R> {
    /// At most this many frames of f64 pixels are kept (a 4x4-inch image
    /// at 800x600 is 11 MiB).
    const MAX_BYTES: usize = 256 << 20;

    fn bytes(frame: &Frame) -> usize {
        frame.pixels.len() * std::mem::size_of_val(&crate::math::DVec3::ZERO)
    }

    pub(super) fn insert(&mut self, pass: CachedPass<R>) {
        if Self::bytes(&pass.frame) > Self::MAX_BYTES / 2 {
            return;
        }
        // Passes of scenes nobody holds any more can never be asked for.
        self.entries
            .retain(|e| !e.key.matches(&pass.key) && e.key.scene.strong_count() > 0);
        self.entries.push(pass);
        let mut total: usize = self.entries.iter().map(|e| Self::bytes(&e.frame)).sum();
        while total > Self::MAX_BYTES {
            total -= Self::bytes(&self.entries.remove(0).frame);
        }
    }

    pub(super) fn find(&self, key: &PassKey) -> Option<&CachedPass<R>> {
        self.entries.iter().rev().find(|e| e.key.matches(key))
    }
}
