//! The light buffer the worker keeps between jobs.

use std::sync::Arc;
use std::time::Instant;

use crate::accel::LightBuffer;
use crate::scene::Scene;

/// The light buffer of the newest scene's shapes and lights, kept from
/// job to job: a new camera reuses it; moving a light or loading another
/// scene builds it again, before that job's first tile.
#[derive(Default)]
pub(super) struct LightBufferCache {
    /// The geometry it was built over (a scene's clone shares it).
    pub(super) shapes: Option<Arc<Vec<crate::shapes::Shape>>>,
    pub(super) buffer: Option<LightBuffer>,
    /// Its build's seconds.
    seconds: f64,
}

impl LightBufferCache {
    /// The kept buffer, if it is of `scene`'s shapes and lights.
    pub(super) fn kept(&self, scene: &Scene) -> Option<&LightBuffer> {
        let lights: Vec<_> = scene.lights.iter().map(|l| l.position).collect();
        let same_shapes = self
            .shapes
            .as_ref()
            .is_some_and(|s| Arc::ptr_eq(s, &scene.shapes));
        self.buffer
            .as_ref()
            .filter(|b| same_shapes && b.fits(scene.shapes.len(), &lights))
    }

    /// The buffer of `scene`'s shapes and lights, built now if the kept
    /// one is of others, and its build's seconds.
    pub(super) fn get(&mut self, scene: &Scene) -> Option<(&LightBuffer, f64)> {
        let lights: Vec<_> = scene.lights.iter().map(|l| l.position).collect();
        let same_shapes = self
            .shapes
            .as_ref()
            .is_some_and(|s| Arc::ptr_eq(s, &scene.shapes));
        let fits = |b: &LightBuffer| b.fits(scene.shapes.len(), &lights);
        if !same_shapes || !self.buffer.as_ref().is_some_and(fits) {
            let start = Instant::now();
            self.buffer = scene.build_light_buffer();
            self.seconds = start.elapsed().as_secs_f64();
            self.shapes = Some(Arc::clone(&scene.shapes));
        }
        self.buffer.as_ref().map(|b| (b, self.seconds))
    }
}
