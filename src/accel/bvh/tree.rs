//! The built hierarchy: its flattened nodes and references, and what it
//! says of itself. Building is `build.rs`'s, the traversal `walk.rs`'s.

use super::node::BvhNode;
use super::wide::WideNodes;

/// The built hierarchy.
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    pub(super) nodes: Vec<BvhNode>,
    pub(super) refs: Vec<u32>,
    /// Shapes without bounds (planes, unclipped quadrics), tested for every ray.
    pub(super) unbounded: Vec<u32>,
    pub(super) stats: BvhStats,
    /// The same tree in eight-wide nodes, for uncounted queries.
    pub(super) wide: WideNodes,
    /// The shapes grouped by the plane they lie in, for rays leaving one.
    pub(super) planes: crate::accel::planes::PlaneGroups,
}

/// What the build made, for the statistics a user compares with the
/// octree's.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct BvhStats {
    pub nodes: u64,
    pub leaves: u64,
    /// Shape references in the leaves: one per bounded shape.
    pub references: u64,
    /// Levels below the root of the deepest leaf.
    pub max_depth: u32,
    /// Nodes and references, in bytes.
    pub memory_bytes: u64,
}

impl Bvh {
    pub fn stats(&self) -> BvhStats {
        self.stats
    }

    /// The shapes grouped by the plane they lie in.
    pub fn planes(&self) -> &crate::accel::planes::PlaneGroups {
        &self.planes
    }

    /// Whether the uncounted queries can take the wide walk.
    pub(super) fn has_wide(&self) -> bool {
        !self.wide.is_empty()
    }
}
