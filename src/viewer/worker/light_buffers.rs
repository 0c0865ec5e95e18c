//! The light buffer the worker keeps between jobs.

use std::sync::Arc;

use crate::accel::LightBuffer;
use crate::render::{Accelerator, LightBufferSource};
use crate::scene::Scene;

/// The light buffer of the newest scene's shapes and lights, kept from
/// job to job: a new camera reuses it; moving a light or loading another
/// scene builds it again, before that job's first tile.
#[derive(Default)]
pub(super) struct LightBufferCache {
    /// The geometry it was built over (a scene's clone shares it).
    pub(super) shapes: Option<Arc<Vec<crate::shapes::Shape>>>,
    pub(super) buffer: Option<Arc<LightBuffer>>,
    /// Its build's seconds.
    seconds: f64,
}

impl LightBufferCache {
    /// The kept buffer, if it is of `scene`'s shapes (the accelerator
    /// checks the lights).
    fn of_shapes(&self, scene: &Scene) -> Option<Arc<LightBuffer>> {
        let same_shapes = self
            .shapes
            .as_ref()
            .is_some_and(|s| Arc::ptr_eq(s, &scene.shapes));
        self.buffer.clone().filter(|_| same_shapes)
    }

    /// The kept buffer and nothing else: while a light is dragged, its
    /// build would take a preview's time every frame.
    pub(super) fn kept(&self, scene: &Scene) -> LightBufferSource {
        LightBufferSource::Given(self.of_shapes(scene))
    }

    /// The kept buffer where it is of `scene`'s shapes and lights, built
    /// again otherwise.
    pub(super) fn current(&self, scene: &Scene) -> LightBufferSource {
        let lights: Vec<_> = scene.lights.iter().map(|l| l.position).collect();
        match self.of_shapes(scene) {
            Some(b) if b.fits(scene.shapes.len(), &lights) => LightBufferSource::Given(Some(b)),
            _ => LightBufferSource::Build,
        }
    }

    /// Keeps the buffer `accel` was built with, if it built one, and
    /// returns the seconds of the kept buffer's build.
    pub(super) fn keep(&mut self, scene: &Scene, accel: &Accelerator) -> f64 {
        if let Some(b) = accel.shared_light_buffer()
            && !self
                .buffer
                .as_ref()
                .is_some_and(|kept| Arc::ptr_eq(kept, b))
        {
            self.buffer = Some(Arc::clone(b));
            self.seconds = accel.build_seconds().1;
            self.shapes = Some(Arc::clone(&scene.shapes));
        }
        self.seconds
    }
}
