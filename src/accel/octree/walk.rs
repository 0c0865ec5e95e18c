//! The traversal: front to back in the parametric manner of Revelles,
//! Ureña & Lastra (2000), iteratively on a per-thread stack, for the
//! closest hit and for shadow rays.

use super::bounds::{Baseline, BoxLanes, BoxRay, limit_f32};
use super::node::{LEVEL_MASK, child_corner};
use super::tree::Octree;
use super::visit::{CellEntry, CellStack};
use crate::accel::leaf_visit::{ClosestVisitor, LeafVisitor, OcclusionVisitor, Visitor};
use crate::accel::primitives::{ClosestHit, Primitives, ShadowCrossings, test_occlusion};
use crate::accel::wide_walk::{WideStack, walk_wide};
use crate::limits::MAX_OCTREE_DEPTH;
use crate::shapes::{PreparedRay, TriangleLanes};
use crate::stats::Counter;
use crate::stats::walk_record::{CellVisit, StepKind, WalkEnd};

impl Octree {
    /// Closest hit with `0 < t < t_max`; `stack` is the caller's scratch.
    pub fn closest<C: Counter>(
        &self,
        prims: &Primitives,
        ray: &PreparedRay,
        t_max: f64,
        stack: &mut WalkStack,
        counter: &mut C,
    ) -> Option<ClosestHit> {
        self.closest_inline(prims, ray, t_max, stack, counter, Baseline)
    }

    /// [`Octree::closest`], inlined into a caller compiled for a SIMD level
    /// whose `lanes` test a node's children.
    #[inline(always)]
    pub fn closest_inline<C: Counter, L: BoxLanes>(
        &self,
        prims: &Primitives,
        ray: &PreparedRay,
        t_max: f64,
        stack: &mut WalkStack,
        counter: &mut C,
        lanes: L,
    ) -> Option<ClosestHit> {
        let mut visitor = ClosestVisitor::new(prims, ray, t_max, counter);
        for &i in &self.unbounded {
            visitor.test(i);
        }
        if !C::COUNTS && self.has_boxes() {
            walk_wide(self, ray, &mut stack.wide, &mut visitor, lanes);
        } else {
            let limit = visitor.limit();
            self.walk(ray, limit, stack, &mut visitor, lanes);
        }
        visitor.best()
    }

    /// What a shadow ray meets over `(0, t_max)`, into `found` (cleared
    /// first; the caller keeps it, so no ray initialises the array).
    pub fn occlusion<C: Counter>(
        &self,
        prims: &Primitives,
        ray: &PreparedRay,
        t_max: f64,
        found: &mut ShadowCrossings,
        stack: &mut WalkStack,
        counter: &mut C,
    ) {
        self.occlusion_inline(prims, ray, t_max, found, stack, counter, Baseline);
    }

    /// [`Octree::occlusion`], inlined into a caller compiled for a SIMD
    /// level whose `lanes` test a node's children.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub fn occlusion_inline<C: Counter, L: BoxLanes>(
        &self,
        prims: &Primitives,
        ray: &PreparedRay,
        t_max: f64,
        found: &mut ShadowCrossings,
        stack: &mut WalkStack,
        counter: &mut C,
        lanes: L,
    ) {
        found.clear();
        for &i in &self.unbounded {
            if test_occlusion(prims, i, ray, t_max, found, counter) {
                counter.walk_end(WalkEnd::Blocked);
                return;
            }
        }
        let mut visitor = OcclusionVisitor::new(prims, ray, t_max, found, counter);
        if !C::COUNTS && self.has_boxes() {
            walk_wide(self, ray, &mut stack.wide, &mut visitor, lanes);
        } else {
            self.walk(ray, t_max, stack, &mut visitor, lanes);
        }
    }

    /// The traversal: pops cells front to back until the visitor stops or
    /// nothing further along the ray can matter.
    #[inline(always)]
    pub(super) fn walk<V: LeafVisitor, L: TriangleLanes>(
        &self,
        ray: &PreparedRay,
        t_max: f64,
        stack: &mut WalkStack,
        visitor: &mut V,
        lanes: L,
    ) {
        if self.nodes.is_empty() {
            visitor.counter().walk_end(WalkEnd::MissedOctree);
            return;
        }
        let Some((t0, t1)) = ray.box_range(&self.bounds, t_max, |t| t) else {
            visitor.counter().walk_end(WalkEnd::MissedOctree);
            return;
        };
        let o = ray.ray.origin.to_array();
        let inv = ray.inv_dir;
        // The boxes of what the children hold, where the tree has them: a
        // child whose box the ray misses is entered but holds nothing for
        // it.
        let held = self
            .has_boxes()
            .then(|| BoxRay::new(ray, &self.root_cell()));
        let entries = stack.cells.entries();
        entries[0] = CellEntry {
            min: self.bounds.min.to_array(),
            t0,
            t1,
            node: 0,
            level: 0,
        };
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let e = entries[top];
            // The stack holds cells in order along the ray, nearest on top:
            // once one starts past the limit, all the others do.
            if e.t0 > visitor.limit() {
                visitor.counter().walk_end(V::BEYOND_LIMIT);
                return;
            }
            visitor.counter().traversal_step();
            let node = self.nodes[e.node as usize];
            let level = e.level & !MISSED;
            let side = |level: u32| self.sides[level as usize & LEVEL_MASK];
            let visit = |kind| CellVisit {
                kind,
                depth: level,
                min: e.min,
                side: side(level),
                t_enter: e.t0,
                t_exit: e.t1,
            };
            if node.is_leaf() {
                visitor.counter().leaf_visit();
                // A leaf whose box the ray misses tests nothing, but ends the
                // walk as any leaf does (a hit found earlier may lie in it).
                let refs = if e.level & MISSED != 0 {
                    visitor.counter().cell(|| visit(StepKind::Missed));
                    &[]
                } else {
                    visitor.counter().cell(|| visit(StepKind::Leaf));
                    let first = node.first as usize;
                    &self.refs[first..first + node.count() as usize]
                };
                if visitor.visit_leaf(refs, e.t1, lanes) {
                    visitor.counter().walk_end(V::STOPPED);
                    return;
                }
                continue;
            }
            visitor.counter().cell(|| visit(StepKind::Inner));
            // The children's side: the cell's half, exactly as the build
            // halves it.
            let h = side(level + 1);
            let mid = [e.min[0] + h, e.min[1] + h, e.min[2] + h];
            // Parameters of the three mid-planes, and the octant entered at
            // t0: on a plane's upper side once it is crossed going up, or
            // until it is crossed going down. A ray parallel to a plane (or
            // in it: upper) never crosses it: its parameter is -inf on the
            // upper side, +inf on the lower, which gives the same rule.
            let mut t_mid = [0.0f64; 3];
            let mut child = 0usize;
            for k in 0..3 {
                let t = if ray.parallel >> k & 1 == 1 {
                    if o[k] >= mid[k] {
                        f64::NEG_INFINITY
                    } else {
                        f64::INFINITY
                    }
                } else {
                    (mid[k] - o[k]) * inv[k]
                };
                t_mid[k] = t;
                child |= (((t <= e.t0) as u32 ^ (ray.negative >> k & 1)) as usize) << k;
            }
            // The crossings inside the cell, in increasing t (ties keep
            // axis order): the children the ray passes through follow by
            // flipping one bit at each.
            let mut axes = [0usize; 3];
            let mut n = 0;
            for (k, &t) in t_mid.iter().enumerate() {
                if t > e.t0 && t < e.t1 {
                    axes[n] = k;
                    n += 1;
                }
            }
            if n > 1 && t_mid[axes[0]] > t_mid[axes[1]] {
                axes.swap(0, 1);
            }
            if n > 2 {
                if t_mid[axes[1]] > t_mid[axes[2]] {
                    axes.swap(1, 2);
                }
                if t_mid[axes[0]] > t_mid[axes[1]] {
                    axes.swap(0, 1);
                }
            }
            // Child i of the sequence is entered at times[i] and left at
            // times[i + 1].
            let mut children = [child; 4];
            let mut times = [e.t0, e.t1, e.t1, e.t1, e.t1];
            for i in 0..n {
                child ^= 1 << axes[i];
                children[i + 1] = child;
                times[i + 1] = t_mid[axes[i]];
            }
            times[n + 1] = e.t1;
            // Farthest first, so the nearest is popped next. Empty octants
            // are counted as entered leaves (Havran's measures) but cost
            // nothing else. A leaf whose box of what it holds (the box the
            // wide walk tests, `bounds.rs`) the ray misses is marked: none
            // of its shapes can meet the ray, so it is entered and tests
            // nothing (the cells entered stay Havran's).
            let limit = visitor.limit();
            let mask = node.mask();
            let boxes = held.as_ref().map(|ray| (self.boxes.children(e.node), ray));
            for i in (0..=n).rev() {
                let c = children[i];
                let min = child_corner(e.min, mid, c);
                if mask >> c & 1 == 0 {
                    if times[i] <= limit {
                        visitor.counter().traversal_step();
                        visitor.counter().leaf_visit();
                        visitor.counter().cell(|| CellVisit {
                            kind: StepKind::Empty,
                            depth: level + 1,
                            min,
                            side: h,
                            t_enter: times[i],
                            t_exit: times[i + 1],
                        });
                    }
                    continue;
                }
                let child = node.child(c);
                let lane = (mask & ((1 << c) - 1)).count_ones() as usize;
                let missed = match boxes {
                    Some((block, ray)) if self.nodes[child as usize].is_leaf() => {
                        if block.meets(lane, ray, limit_f32(limit)) {
                            0
                        } else {
                            MISSED
                        }
                    }
                    _ => 0,
                };
                entries[top & (STACK_CAPACITY - 1)] = CellEntry {
                    min,
                    t0: times[i],
                    t1: times[i + 1],
                    node: child,
                    level: (level + 1) | missed,
                };
                top += 1;
            }
        }
        visitor.counter().walk_end(WalkEnd::LeftOctree);
    }
}

/// A cell's level with this bit: the ray misses the box of what it holds.
const MISSED: u32 = 1 << 31;

/// Room on the traversal stack: each level leaves at most three siblings
/// waiting, plus the cell being entered (a power of two, so indices are
/// masked instead of bounds-checked).
const STACK_CAPACITY: usize = (3 * MAX_OCTREE_DEPTH as usize + 4).next_power_of_two();

/// A single ray's walk stacks: the exact walk's cells and the wide walk's
/// nodes. Scratch space the caller owns (one per tile), so no ray sets it up.
#[derive(Default)]
pub struct WalkStack {
    cells: CellStack<f64, STACK_CAPACITY>,
    wide: WideStack,
}
