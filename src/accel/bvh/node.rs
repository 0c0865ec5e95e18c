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

/// A node is skipped only when the ray enters it this far (relative)
/// beyond the best hit or the end of the ray: far above the rounding of
/// the slab test and of hit distances, so a hit that ties with the best
/// is never skipped.
const SLACK: f64 = 1e-9;

/// `t` grown by [`SLACK`].
#[inline(always)]
pub(super) fn widen(t: f64) -> f64 {
    t + t.abs() * SLACK
}
