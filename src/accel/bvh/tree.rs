//! The built hierarchy: its flattened nodes and references, and what it
//! says of itself. Building is `build.rs`'s, the traversal `walk.rs`'s.

use crate::math::Aabb;

/// A node of the flattened tree, in depth-first order: an interior node's
/// first child follows it, its second is at `first_or_second`.
#[derive(Clone, Copy, Debug)]
pub(super) struct BvhNode {
    pub(super) bounds: Aabb,
    /// Leaf: index of its first reference. Interior: index of the second child.
    pub(super) first_or_second: u32,
    /// References of a leaf; 0 for an interior node.
    pub(super) count: u32,
}

/// The built hierarchy.
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    pub(super) nodes: Vec<BvhNode>,
    pub(super) refs: Vec<u32>,
    /// Shapes without bounds (planes, unclipped quadrics), tested for every ray.
    pub(super) unbounded: Vec<u32>,
    pub(super) stats: BvhStats,
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
}
