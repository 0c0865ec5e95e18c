//! The traversal: front to back in the parametric manner of Revelles,
//! Ureña & Lastra (2000), iteratively on a per-thread stack, for the
//! closest hit and for shadow rays.

use super::super::primitives::{
    ClosestHit, Primitives, ShadowCrossings, test_closest, test_occlusion,
};
use super::node::Cell;
use super::tree::Octree;
use crate::limits::MAX_OCTREE_DEPTH;
use crate::math::DVec3;
use crate::shapes::PreparedRay;
use crate::stats::Counter;

impl Octree {
    /// Closest hit with `0 < t < t_max`.
    pub fn closest<C: Counter>(
        &self,
        prims: &Primitives,
        ray: &PreparedRay,
        t_max: f64,
        counter: &mut C,
    ) -> Option<ClosestHit> {
        let mut visitor = ClosestVisitor {
            prims,
            ray,
            best: None,
            t_max,
            mailbox: Mailbox::new(),
            counter,
        };
        for &i in &self.unbounded {
            test_closest(prims, i, ray, &mut visitor.best, t_max, visitor.counter);
        }
        let limit = visitor.best.map_or(t_max, |b| b.hit.t);
        self.traverse(ray, limit, &mut visitor);
        visitor.best
    }

    /// What a shadow ray meets over `(0, t_max)`, into `found` (cleared
    /// first; the caller keeps it, so no ray initialises the array).
    pub fn occlusion<C: Counter>(
        &self,
        prims: &Primitives,
        ray: &PreparedRay,
        t_max: f64,
        found: &mut ShadowCrossings,
        counter: &mut C,
    ) {
        found.clear();
        for &i in &self.unbounded {
            if test_occlusion(prims, i, ray, t_max, found, counter) {
                return;
            }
        }
        let mut visitor = OcclusionVisitor {
            prims,
            ray,
            t_max,
            found,
            mailbox: Mailbox::new(),
            counter,
        };
        self.traverse(ray, t_max, &mut visitor);
    }

    fn traverse<V: LeafVisitor>(&self, ray: &PreparedRay, t_max: f64, visitor: &mut V) {
        if self.nodes.is_empty() {
            return;
        }
        let walk = WalkRay::new(ray);
        let Some((t0, t1)) = self.bounds.ray_range(&walk.ray, 0.0, t_max) else {
            return;
        };
        STACK.with_borrow_mut(|stack| {
            stack.entries[0] = Entry {
                node: 0,
                cell: self.root_cell(),
                t0,
                t1,
            };
            self.walk(&walk, stack, visitor);
        });
    }

    /// The traversal proper: pops cells front to back until the visitor
    /// stops or nothing further along the ray can matter.
    #[inline(always)]
    fn walk<V: LeafVisitor>(&self, ray: &WalkRay, stack: &mut Stack, visitor: &mut V) {
        let (o, d, inv) = (ray.ray.origin, ray.ray.dir, ray.inv_dir);
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let e = stack.entries[top];
            // The stack holds cells in order along the ray, nearest on top:
            // once one starts past the limit, all the others do.
            if e.t0 > visitor.t_limit() {
                return;
            }
            visitor.counter().traversal_step();
            let node = self.nodes[e.node as usize];
            if node.is_leaf() {
                visitor.counter().leaf_visit();
                let first = node.first as usize;
                let refs = &self.refs[first..first + node.count() as usize];
                if visitor.visit_leaf(refs, e.t1) {
                    return;
                }
                continue;
            }
            let mid = e.cell.mid();
            // Parameters of the three mid-planes, and the octant entered at
            // t0: on a plane's upper side once it is crossed going up, or
            // until it is crossed going down. A ray parallel to a plane (or
            // in it: upper) never crosses it: its parameter is -inf on the
            // upper side, +inf on the lower, which gives the same rule.
            let mut t_mid = [0.0f64; 3];
            let mut child = 0usize;
            for k in 0..3 {
                let t = if d[k] == 0.0 {
                    if o[k] >= mid[k] {
                        f64::NEG_INFINITY
                    } else {
                        f64::INFINITY
                    }
                } else {
                    (mid[k] - o[k]) * inv[k]
                };
                t_mid[k] = t;
                child |= (((t <= e.t0) != ray.negative[k]) as usize) << k;
            }
            // The crossings inside the cell, in increasing t: the children
            // the ray passes through follow by flipping one bit at each.
            let mut inside = [0usize; 3];
            let mut n_inside = 0;
            for (k, &t) in t_mid.iter().enumerate() {
                if t > e.t0 && t < e.t1 {
                    inside[n_inside] = k;
                    n_inside += 1;
                }
            }
            // At most three: compare and swap (ties keep axis order).
            let earlier = |a: usize, b: usize| t_mid[a] > t_mid[b];
            if n_inside > 1 && earlier(inside[0], inside[1]) {
                inside.swap(0, 1);
            }
            if n_inside > 2 {
                if earlier(inside[1], inside[2]) {
                    inside.swap(1, 2);
                }
                if earlier(inside[0], inside[1]) {
                    inside.swap(0, 1);
                }
            }
            let crossings = &inside[..n_inside];
            let mut sequence = [(0usize, 0.0f64, 0.0f64); 4];
            let mut t_start = e.t0;
            for (i, &k) in crossings.iter().enumerate() {
                sequence[i] = (child, t_start, t_mid[k]);
                child ^= 1 << k;
                t_start = t_mid[k];
            }
            sequence[n_inside] = (child, t_start, e.t1);
            // Farthest first, so the nearest is popped next. Empty octants
            // are counted as entered leaves (Havran's measures) but cost
            // nothing else.
            let limit = visitor.t_limit();
            let mask = node.mask();
            for &(c, ts, te) in sequence[..=n_inside].iter().rev() {
                if mask >> c & 1 == 0 {
                    if ts <= limit {
                        visitor.counter().traversal_step();
                        visitor.counter().leaf_visit();
                    }
                    continue;
                }
                stack.entries[top] = Entry {
                    node: node.child(c),
                    cell: e.cell.child(c),
                    t0: ts,
                    t1: te,
                };
                top += 1;
            }
        }
    }
}

/// A cell waiting on the traversal stack, with the ray's parameters at its
/// entry and exit.
#[derive(Clone, Copy, Debug, Default)]
struct Entry {
    node: u32,
    cell: Cell,
    t0: f64,
    t1: f64,
}

/// Deepest stack a walk needs: each level leaves at most three siblings
/// waiting, plus the cell being entered.
const STACK_CAPACITY: usize = 3 * MAX_OCTREE_DEPTH as usize + 4;

/// The cells a walk has still to visit.
struct Stack {
    entries: [Entry; STACK_CAPACITY],
}

thread_local! {
    /// One traversal stack per thread, reused by every ray (a traversal
    /// never starts another on the same thread), so no ray initialises it.
    static STACK: std::cell::RefCell<Stack> = std::cell::RefCell::new(Stack {
        entries: [Entry::default(); STACK_CAPACITY],
    });
}

/// The ray as the traversal sees it: direction components too small to
/// invert are treated as exactly zero (parallel to the planes), which moves
/// the ray by less than the cells' padding over any finite distance.
struct WalkRay {
    ray: crate::math::Ray,
    inv_dir: DVec3,
    /// Per axis: the direction is negative.
    negative: [bool; 3],
}

impl WalkRay {
    fn new(r: &PreparedRay) -> Self {
        let mut ray = r.ray;
        let mut inv_dir = DVec3::ZERO;
        for k in 0..3 {
            let inv = 1.0 / ray.dir[k];
            if inv.is_finite() {
                inv_dir[k] = inv;
            } else {
                ray.dir[k] = 0.0;
            }
        }
        let negative = [ray.dir.x < 0.0, ray.dir.y < 0.0, ray.dir.z < 0.0];
        Self {
            ray,
            inv_dir,
            negative,
        }
    }
}

/// Remembers the last shapes tested for this ray, so a shape referenced
/// from several leaves is usually tested once (direct-mapped, 16 entries).
struct Mailbox([u32; 16]);

impl Mailbox {
    fn new() -> Self {
        Self([u32::MAX; 16])
    }

    /// `true` if `index` was tested already; records it otherwise.
    #[inline(always)]
    fn seen(&mut self, index: u32) -> bool {
        let slot = &mut self.0[(index & 15) as usize];
        if *slot == index {
            return true;
        }
        *slot = index;
        false
    }
}

trait LeafVisitor {
    type C: Counter;
    fn counter(&mut self) -> &mut Self::C;
    /// Tests the shapes of a leaf the ray leaves at `t_exit`; `true` to stop.
    fn visit_leaf(&mut self, refs: &[u32], t_exit: f64) -> bool;
    /// Cells starting beyond this parameter cannot change the answer.
    fn t_limit(&self) -> f64;
}

struct ClosestVisitor<'a, C> {
    prims: &'a Primitives<'a>,
    ray: &'a PreparedRay,
    best: Option<ClosestHit>,
    t_max: f64,
    mailbox: Mailbox,
    counter: &'a mut C,
}

impl<C: Counter> LeafVisitor for ClosestVisitor<'_, C> {
    type C = C;
    fn counter(&mut self) -> &mut C {
        self.counter
    }

    #[inline(always)]
    fn visit_leaf(&mut self, refs: &[u32], t_exit: f64) -> bool {
        for &i in refs {
            if !self.mailbox.seen(i) {
                test_closest(
                    self.prims,
                    i,
                    self.ray,
                    &mut self.best,
                    self.t_max,
                    self.counter,
                );
            }
        }
        // A hit exactly on the exit face may tie with one in the next cell:
        // only a hit strictly inside this cell ends the walk.
        self.best.is_some_and(|b| b.hit.t < t_exit)
    }

    fn t_limit(&self) -> f64 {
        self.best.map_or(self.t_max, |b| b.hit.t)
    }
}

struct OcclusionVisitor<'a, C> {
    prims: &'a Primitives<'a>,
    ray: &'a PreparedRay,
    t_max: f64,
    found: &'a mut ShadowCrossings,
    mailbox: Mailbox,
    counter: &'a mut C,
}

impl<C: Counter> LeafVisitor for OcclusionVisitor<'_, C> {
    type C = C;
    fn counter(&mut self) -> &mut C {
        self.counter
    }

    #[inline(always)]
    fn visit_leaf(&mut self, refs: &[u32], _t_exit: f64) -> bool {
        for &i in refs {
            if !self.mailbox.seen(i)
                && test_occlusion(
                    self.prims,
                    i,
                    self.ray,
                    self.t_max,
                    self.found,
                    self.counter,
                )
            {
                return true;
            }
        }
        false
    }

    fn t_limit(&self) -> f64 {
        self.t_max
    }
}
