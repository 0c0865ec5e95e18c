//! The octree's layout: 8-byte nodes that store only their non-empty
//! children, and the cubic cells the build and the traversal derive with
//! the same arithmetic.

use crate::limits::MAX_OCTREE_DEPTH;
use crate::math::{Aabb, DVec3};

/// Levels the side table holds, less one: a power of two less one, so
/// a level is masked into it instead of bounds-checked.
pub(super) const LEVEL_MASK: usize = (MAX_OCTREE_DEPTH as usize + 2).next_power_of_two() - 1;

/// Leaf: `refs[first .. first + count]`. Interior: a mask of the octants
/// holding anything (octant bit 0 = upper x, bit 1 = upper y, bit 2 =
/// upper z), whose nodes alone are stored, consecutively from `first` in
/// octant order: empty octants cost neither memory nor a load. 8 bytes.
#[derive(Clone, Copy, Debug)]
pub(super) struct Node {
    pub(super) first: u32,
    /// Leaf: the reference count. Interior: [`INTERIOR`] | the octant mask.
    pub(super) meta: u32,
}

pub(super) const INTERIOR: u32 = 1 << 31;

impl Node {
    pub(super) const EMPTY: Node = Node { first: 0, meta: 0 };

    #[inline(always)]
    pub(super) fn is_leaf(self) -> bool {
        self.meta & INTERIOR == 0
    }

    #[inline(always)]
    pub(super) fn count(self) -> u32 {
        self.meta
    }

    #[inline(always)]
    pub(super) fn mask(self) -> u32 {
        self.meta & 0xff
    }

    /// Index of the node of octant `c`, which must be in the mask.
    #[inline(always)]
    pub(super) fn child(self, c: usize) -> u32 {
        self.first + (self.mask() & ((1 << c) - 1)).count_ones()
    }
}

/// A cubic cell: its lowest corner and side. Children are formed by the
/// same arithmetic in the build and the traversal, so their cells agree to
/// the bit.
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Cell {
    pub(super) min: DVec3,
    pub(super) side: f64,
}

impl Cell {
    #[inline(always)]
    pub(super) fn half(&self) -> f64 {
        0.5 * self.side
    }

    #[cfg(test)]
    pub(super) fn mid(&self) -> DVec3 {
        self.min + DVec3::splat(self.half())
    }

    #[inline(always)]
    pub(super) fn child(&self, c: usize) -> Cell {
        let h = self.half();
        let pick = |k: usize| if c >> k & 1 == 1 { h } else { 0.0 };
        Cell {
            min: self.min + DVec3::new(pick(0), pick(1), pick(2)),
            side: h,
        }
    }

    pub(super) fn aabb(&self) -> Aabb {
        Aabb::new(self.min, self.min + DVec3::splat(self.side))
    }
}

/// The lowest corner of child `c` of the cell whose lowest corner is
/// `min` and whose mid-planes are at `mid`: the mid-plane along each axis
/// where bit k of `c` is set (the upper half), the parent's corner
/// elsewhere. The same values as `min + h * bit` (up to the sign of a zero
/// corner), without a multiply and three conversions per child.
#[inline(always)]
pub(super) fn child_corner(min: [f64; 3], mid: [f64; 3], c: usize) -> [f64; 3] {
    let pick = |k: usize| if c >> k & 1 == 1 { mid[k] } else { min[k] };
    [pick(0), pick(1), pick(2)]
}
