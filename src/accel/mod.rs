//! Ray queries over a scene's shapes: brute force over every shape, or
//! through the [`Octree`] or a [`Bvh`]. All answer exactly the same: ties
//! between equal distances go to the lower shape index in each.

mod bvh;
mod leaf_visit;
mod light_buffer;
mod octree;
mod planes;
mod primitives;
mod walk_log;
mod wide_walk;

pub use crate::stats::walk_record::{CellVisit, QueryRecord, StepKind, Tested, WalkEnd, WalkStep};
pub use bvh::{Bvh, BvhStack, BvhStats};
pub use light_buffer::{Candidates, LightBuffer, LightBufferStats};
pub use octree::{
    Baseline, BoxLanes, DEFAULT_MEMORY_BUDGET_MIB, Octree, OctreeCell, OctreeError, OctreeParams,
    OctreeStats, PacketStack, PredictedCost, WalkStack,
};
pub(crate) use octree::{OneByOne, SkippingPlanes};
pub use planes::{PlaneGroups, ShapeRange};
pub(crate) use primitives::occlusion_among_in_lanes;
pub use primitives::{
    ClosestHit, MAX_SHADOW_CROSSINGS, Primitives, ShadowCrossings, closest_brute_force,
    occlusion_among, occlusion_brute_force,
};
pub use walk_log::WalkLog;

/// `n`^3 spheres of radius `radius` one unit apart, the first at the
/// origin: what the accelerators' tests build over.
#[cfg(test)]
pub(crate) fn sphere_grid(n: u32, radius: f64) -> Vec<crate::shapes::Shape> {
    let mut shapes = Vec::new();
    for i in 0..n {
        for j in 0..n {
            for k in 0..n {
                let c = crate::math::DVec3::new(i as f64, j as f64, k as f64);
                shapes.push(crate::shapes::Shape::Sphere(crate::shapes::Sphere::new(
                    c, radius,
                )));
            }
        }
    }
    shapes
}
