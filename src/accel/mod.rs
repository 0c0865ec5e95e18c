//! Ray queries over a scene's shapes: brute force over every shape, or
//! through the [`Octree`] or a [`Bvh`]. All answer exactly the same: ties
//! between equal distances go to the lower shape index in each.

mod bvh;
mod octree;
mod primitives;
mod walk_log;

pub use crate::stats::walk_record::{CellVisit, QueryRecord, StepKind, Tested, WalkEnd, WalkStep};
pub use bvh::{Bvh, BvhStack, BvhStats};
pub use octree::{
    Baseline, BoxLanes, DEFAULT_MEMORY_BUDGET_MIB, Octree, OctreeCell, OctreeError, OctreeParams,
    OctreeStats, PacketStack, PredictedCost, WalkStack,
};
pub use primitives::{
    ClosestHit, MAX_SHADOW_CROSSINGS, Primitives, ShadowCrossings, closest_brute_force,
    occlusion_brute_force,
};
pub use walk_log::WalkLog;
