//! A node of the binary tree, as the build lays it out.

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
