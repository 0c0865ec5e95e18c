//! Rays cast into a model before it has a camera, to decide where one
//! stands: a shallow octree of the model's own (no deeper than 6 levels, a
//! fraction of the render's build) answering closest-hit queries.

use crate::accel::{Octree, OctreeParams, Primitives, WalkStack};
use crate::math::{DVec3, Ray};
use crate::shapes::{PreparedRay, Shape};
use crate::stats::NoCounts;

/// A surface a probe ray met.
#[derive(Clone, Copy, Debug)]
pub(super) struct ProbeHit {
    pub t: f64,
    pub point: DVec3,
    /// Unit normal turned towards the ray's origin.
    pub facing: DVec3,
    /// Whether the surface's own outside (its vertex normals where the
    /// model gives them, else its winding) faces the ray's origin.
    pub front: bool,
}

pub(super) struct ModelProbe<'a> {
    shapes: &'a [Shape],
    vertex_normals: &'a [[DVec3; 3]],
    octree: Octree,
}

impl<'a> ModelProbe<'a> {
    /// Models with more shapes than this are not probed: the probe's
    /// octree would cost a noticeable part of the load.
    const MAX_SHAPES: usize = 1_000_000;

    pub fn new(shapes: &'a [Shape], vertex_normals: &'a [[DVec3; 3]]) -> Option<Self> {
        if shapes.len() > Self::MAX_SHAPES {
            return None;
        }
        let params = OctreeParams {
            max_depth: 6,
            ..OctreeParams::default()
        };
        let octree = Octree::build(shapes, params).ok()?;
        Some(Self {
            shapes,
            vertex_normals,
            octree,
        })
    }

    /// The nearest surface along `ray` closer than `t_max`.
    pub fn closest(&self, ray: Ray, t_max: f64, stack: &mut WalkStack) -> Option<ProbeHit> {
        let prims = Primitives::opaque(self.shapes);
        let prepared = PreparedRay::new(ray);
        let hit = self
            .octree
            .closest(&prims, &prepared, t_max, stack, &mut NoCounts)?;
        let surface = self.shapes[hit.shape as usize].surface(&ray, &hit.hit, self.vertex_normals);
        let normal = surface.geometric_normal;
        let facing = if normal.dot(ray.dir) < 0.0 {
            normal
        } else {
            -normal
        };
        if !(facing.is_finite() && surface.point.is_finite()) {
            return None;
        }
        Some(ProbeHit {
            t: hit.hit.t,
            point: surface.point,
            facing,
            front: surface.shading_normal.dot(ray.dir) < 0.0,
        })
    }
}
