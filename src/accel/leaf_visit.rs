//! What a walk does at a leaf, written once for the octree's walks and
//! the BVH's: a closest-hit query and a shadow query are visitors (the
//! query kind is the type), as one traversal serves both kinds of ray in
//! Mitsuba's kd-tree. A visitor tells the walk its limit (cells or nodes
//! entered beyond it cannot change the answer), tests a leaf's shapes
//! (triangles four at a time where the SIMD level can, a shadow ray
//! skipping the plane it leaves) and says when to stop. The mailbox tests
//! a shape referenced from several octree leaves once per ray.

use crate::accel::primitives::{
    ClosestHit, Primitives, ShadowCrossings, TriangleBatch, shadow_tests, test_closest,
};
use crate::shapes::{PreparedRay, TriangleLanes};
use crate::stats::Counter;
use crate::stats::walk_record::WalkEnd;

/// Remembers, for the last shapes tested, the lanes they were tested in
/// (direct-mapped, 16 entries), so a shape referenced from several leaves
/// is tested once per ray. A single ray is lane 0.
pub(crate) struct Mailbox([(u32, u32); 16]);

impl Mailbox {
    pub(crate) fn new() -> Self {
        Self([(u32::MAX, 0); 16])
    }

    /// For a single ray: `true` if `index` was tested already; records it
    /// otherwise.
    #[inline(always)]
    pub(crate) fn seen(&mut self, index: u32) -> bool {
        let slot = &mut self.0[(index & 15) as usize];
        if slot.0 == index {
            return true;
        }
        *slot = (index, 1);
        false
    }

    /// For a packet: the lanes of `lanes` in which `index` is not yet
    /// tested; records them.
    #[inline(always)]
    pub(crate) fn untested(&mut self, index: u32, lanes: u32) -> u32 {
        let slot = &mut self.0[(index & 15) as usize];
        if slot.0 == index {
            let fresh = lanes & !slot.1;
            slot.1 |= fresh;
            fresh
        } else {
            *slot = (index, lanes);
            lanes
        }
    }
}

/// What a walk asks of the query it runs for, whatever it does at leaves.
pub(crate) trait Visitor {
    /// The limit's form: `f64` for one ray, per lane for a packet.
    type Limit;
    type C: Counter;
    /// Cells starting beyond the limit cannot change the answer.
    fn limit(&self) -> Self::Limit;
    fn counter(&mut self) -> &mut Self::C;
}

/// What a single ray's walk does at its leaves.
pub(crate) trait LeafVisitor: Visitor<Limit = f64> {
    /// Tests the shapes of a leaf the ray leaves at `t_exit`; `true` to stop.
    /// `lanes` test triangles four at a time where the level can.
    fn visit_leaf<L: TriangleLanes>(&mut self, refs: &[u32], t_exit: f64, lanes: L) -> bool;
    /// Why the walk ends when `visit_leaf` says stop, and when the next
    /// cell starts beyond the limit.
    const STOPPED: WalkEnd;
    const BEYOND_LIMIT: WalkEnd;
    /// Whether the wide walk enters the children it meets nearest first.
    /// Either way the answer is the same (a child entered past the limit
    /// is skipped, and a shadow ray's answer does not depend on the
    /// order); a closest-hit query finds its best hit sooner so, and cuts
    /// off more of what lies beyond it.
    const NEAREST_FIRST: bool = true;
}

pub(crate) struct ClosestVisitor<'a, C> {
    prims: &'a Primitives<'a>,
    ray: &'a PreparedRay,
    best: Option<ClosestHit>,
    t_max: f64,
    mailbox: Mailbox,
    counter: &'a mut C,
}

impl<'a, C: Counter> ClosestVisitor<'a, C> {
    pub(crate) fn new(
        prims: &'a Primitives<'a>,
        ray: &'a PreparedRay,
        t_max: f64,
        counter: &'a mut C,
    ) -> Self {
        Self {
            prims,
            ray,
            best: None,
            t_max,
            mailbox: Mailbox::new(),
            counter,
        }
    }

    /// The closest hit found so far (the answer, once the walk ends).
    pub(crate) fn best(&self) -> Option<ClosestHit> {
        self.best
    }

    /// Tests shape `index` (one the walk does not reach, such as an
    /// unbounded plane) as a leaf's shape is tested.
    #[inline(always)]
    pub(crate) fn test(&mut self, index: u32) {
        test_closest(
            self.prims,
            index,
            self.ray,
            &mut self.best,
            self.t_max,
            self.counter,
        );
    }
}

impl<C: Counter> Visitor for ClosestVisitor<'_, C> {
    type Limit = f64;
    type C = C;
    fn counter(&mut self) -> &mut C {
        self.counter
    }

    fn limit(&self) -> f64 {
        self.best.map_or(self.t_max, |b| b.hit.t)
    }
}

impl<C: Counter> LeafVisitor for ClosestVisitor<'_, C> {
    const STOPPED: WalkEnd = WalkEnd::HitInCell;
    const BEYOND_LIMIT: WalkEnd = WalkEnd::CellsBeyondHit;

    #[inline(always)]
    fn visit_leaf<L: TriangleLanes>(&mut self, refs: &[u32], t_exit: f64, lanes: L) -> bool {
        // Uncounted, where the lanes can (triangles are most shapes):
        // triangles four at a time, the rest one by one, in a loop for
        // each way (docs/notes/experiments.md compares the forms).
        if C::COUNTS || !L::FOUR_AT_ONCE {
            for &i in refs {
                if !self.mailbox.seen(i) {
                    self.test(i);
                }
            }
            return self.best.is_some_and(|b| b.hit.t < t_exit);
        }
        let mut batch = TriangleBatch::new();
        for &i in refs {
            if self.mailbox.seen(i) {
                continue;
            }
            if let Some(triangle) = self.prims.lane_triangle(i) {
                if batch.push(i, triangle, false) {
                    batch.closest(self.prims, self.ray, &mut self.best, self.t_max, lanes);
                }
            } else {
                self.test(i);
            }
        }
        batch.closest(self.prims, self.ray, &mut self.best, self.t_max, lanes);
        // A hit exactly on the exit face may tie with one in the next cell:
        // only a hit strictly inside this cell ends the walk.
        self.best.is_some_and(|b| b.hit.t < t_exit)
    }
}

pub(crate) struct OcclusionVisitor<'a, C> {
    prims: &'a Primitives<'a>,
    ray: &'a PreparedRay,
    t_max: f64,
    found: &'a mut ShadowCrossings,
    mailbox: Mailbox,
    counter: &'a mut C,
}

impl<'a, C: Counter> OcclusionVisitor<'a, C> {
    pub(crate) fn new(
        prims: &'a Primitives<'a>,
        ray: &'a PreparedRay,
        t_max: f64,
        found: &'a mut ShadowCrossings,
        counter: &'a mut C,
    ) -> Self {
        Self {
            prims,
            ray,
            t_max,
            found,
            mailbox: Mailbox::new(),
            counter,
        }
    }
}

impl<C: Counter> Visitor for OcclusionVisitor<'_, C> {
    type Limit = f64;
    type C = C;
    fn counter(&mut self) -> &mut C {
        self.counter
    }

    fn limit(&self) -> f64 {
        self.t_max
    }
}

impl<C: Counter> LeafVisitor for OcclusionVisitor<'_, C> {
    const STOPPED: WalkEnd = WalkEnd::Blocked;
    // Any blocker ends the walk, and the crossings are kept sorted
    // whatever order they are found in.
    const NEAREST_FIRST: bool = false;
    const BEYOND_LIMIT: WalkEnd = WalkEnd::CellsBeyondLight;

    #[inline(always)]
    fn visit_leaf<L: TriangleLanes>(&mut self, refs: &[u32], _t_exit: f64, lanes: L) -> bool {
        // Whichever shape blocks first, the ray is blocked.
        let mut batch = TriangleBatch::new();
        let mailbox = &mut self.mailbox;
        shadow_tests(
            self.prims,
            self.ray,
            self.t_max,
            self.found,
            self.counter,
            &mut batch,
            refs,
            |i| mailbox.seen(i),
            lanes,
        ) || batch.blocks(self.prims, self.ray, self.t_max, self.found, lanes)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_mailbox_tests_a_shape_once_per_lane() {
        let mut mailbox = Mailbox::new();
        assert!(!mailbox.seen(3));
        assert!(mailbox.seen(3));
        // 19 shares 3's slot: it evicts it.
        assert!(!mailbox.seen(19));
        assert!(!mailbox.seen(3));
        let mut mailbox = Mailbox::new();
        assert_eq!(mailbox.untested(5, 0b0011), 0b0011);
        assert_eq!(mailbox.untested(5, 0b0110), 0b0100);
        assert_eq!(mailbox.untested(5, 0b0111), 0);
        assert_eq!(mailbox.untested(21, 0b0001), 0b0001);
        assert_eq!(mailbox.untested(5, 0b0001), 0b0001);
    }
}
