//! The traversal for packets of coherent rays (Knoll, Hansen & Wald 2007
//! walk packets through octrees; here with Revelles' parametric cells). A
//! packet's lanes share their direction's signs, so every lane meets an
//! interior node's children in the same order: by how many of its planes
//! separate them from the near corner (0, then 1, 2, 3). A single ray passes
//! through at most one child of each rank, one rank after the other, so
//! that fixed order is front to back for every lane. Each lane keeps its own
//! interval in each cell and its own closest hit; a cell is visited while
//! any lane is inside it before its limit, and a lane's answer is exactly
//! the single ray's (the closest hit is the lexicographic minimum of
//! `(t, shape index)` whatever the order of the tests).

// Lane loops index several arrays by the same lane number.
#![allow(clippy::needless_range_loop)]

use super::node::{LEVEL_MASK, Node, child_corner};
use super::tree::Octree;
use super::visit::{CellEntry, CellStack};
use crate::accel::leaf_visit::{Mailbox, Visitor};
use crate::accel::primitives::Primitives;
use crate::limits::MAX_OCTREE_DEPTH;
use crate::shapes::{PacketHits, RayPacket};
use crate::simd::{F64s, lanes, mask, max, min, per_axis};
use crate::stats::Counter;

/// Room on a packet's stack: each level may leave seven siblings waiting,
/// plus the cell being entered (rounded up to a power of two).
const PACKET_STACK_CAPACITY: usize = (7 * MAX_OCTREE_DEPTH as usize + 8).next_power_of_two();

/// A packet's walk stack.
pub type PacketStack<const N: usize> = CellStack<F64s<N>, PACKET_STACK_CAPACITY>;

/// What a packet's walk does at its leaves.
trait PacketVisitor<const N: usize>: Visitor<Limit = F64s<N>> {
    /// Tests the shape `index` in `lanes`.
    fn test(&mut self, index: u32, lanes: u32);
}

struct Closest<'a, C, const N: usize> {
    prims: &'a Primitives<'a>,
    packet: &'a RayPacket<N>,
    best: PacketHits<N>,
    counter: &'a mut C,
}

impl<C: Counter, const N: usize> Visitor for Closest<'_, C, N> {
    type Limit = F64s<N>;
    type C = C;
    #[inline(always)]
    fn limit(&self) -> F64s<N> {
        self.best.t
    }
    #[inline(always)]
    fn counter(&mut self) -> &mut C {
        self.counter
    }
}

impl<C: Counter, const N: usize> PacketVisitor<N> for Closest<'_, C, N> {
    #[inline(always)]
    fn test(&mut self, index: u32, lanes: u32) {
        self.prims
            .closest_lanes(index, self.packet, lanes, &mut self.best, self.counter);
    }
}

impl Octree {
    /// Each lane's closest hit with `0 < t < t_max[lane]`, as
    /// [`Octree::closest`] finds it for the lane's ray alone.
    #[inline(always)]
    pub fn closest_packet<C: Counter, const N: usize>(
        &self,
        prims: &Primitives,
        packet: &RayPacket<N>,
        t_max: F64s<N>,
        stack: &mut PacketStack<N>,
        counter: &mut C,
    ) -> PacketHits<N> {
        let mut visitor = Closest {
            prims,
            packet,
            best: PacketHits::new(t_max),
            counter,
        };
        for &i in &self.unbounded {
            visitor.test(i, packet.live);
        }
        self.walk_packet(packet, stack, &mut visitor);
        visitor.best
    }

    #[inline(always)]
    fn walk_packet<V: PacketVisitor<N>, const N: usize>(
        &self,
        p: &RayPacket<N>,
        stack: &mut PacketStack<N>,
        visitor: &mut V,
    ) {
        if self.nodes.is_empty() {
            return;
        }
        let (lo, hi) = (self.bounds.min.to_array(), self.bounds.max.to_array());
        let (o, inv) = (&p.origin, &p.inv_dir);
        // The root's slab test in each lane, as the single ray's.
        let limit = visitor.limit();
        let mut t0 = [0.0f64; N];
        let mut t1 = limit;
        for k in 0..3 {
            let mut near: F64s<N> = lanes!(N, |i| (lo[k] - o[k][i]) * inv[k][i]);
            let mut far: F64s<N> = lanes!(N, |i| (hi[k] - o[k][i]) * inv[k][i]);
            if p.negative >> k & 1 == 1 {
                std::mem::swap(&mut near, &mut far);
            }
            t0 = max(t0, near);
            t1 = min(t1, far);
        }
        if mask(t0, t1, |a, b| a <= b) & p.live == 0 {
            return;
        }
        let entries = stack.entries();
        entries[0] = CellEntry {
            min: lo,
            t0,
            t1,
            node: 0,
            level: 0,
        };
        let mut top = 1;
        let mut mailbox = Mailbox::new();
        while top > 0 {
            top -= 1;
            let e = entries[top];
            // A lane's exit, no later than its limit (which only falls).
            let t1 = min(e.t1, visitor.limit());
            let active = mask(e.t0, t1, |a, b| a <= b) & p.live;
            if active == 0 {
                continue;
            }
            let lanes = active.count_ones();
            let node = self.nodes[e.node as usize];
            if node.is_leaf() {
                visitor.counter().add_lanes(0, lanes, lanes);
                let first = node.first as usize;
                for &index in &self.refs[first..first + node.count() as usize] {
                    let fresh = mailbox.untested(index, active);
                    if fresh != 0 {
                        visitor.test(index, fresh);
                    }
                }
                continue;
            }
            visitor.counter().add_lanes(0, lanes, 0);
            let h = self.sides[(e.level + 1) as usize & LEVEL_MASK];
            let mid = [e.min[0] + h, e.min[1] + h, e.min[2] + h];
            let t_mid: [F64s<N>; 3] = per_axis!(|k| lanes!(N, |i| (mid[k] - o[k][i]) * inv[k][i]));
            // Each octant's interval, by its far bits (bit k: past the
            // mid-plane of axis k along the rays): it starts where the last
            // of its far mid-planes is crossed and ends where the first of
            // the others is. Octants share the partial minima and maxima
            // (exact operations, so any grouping gives the same values).
            let t0 = e.t0;
            let after: [F64s<N>; 3] = per_axis!(|k| max(t0, t_mid[k]));
            let before: [F64s<N>; 3] = per_axis!(|k| min(t1, t_mid[k]));
            let after01 = max(after[0], after[1]);
            let before01 = min(before[0], before[1]);
            let enter = [
                t0,
                after[0],
                after[1],
                after01,
                after[2],
                max(after[0], after[2]),
                max(after[1], after[2]),
                max(after01, after[2]),
            ];
            let leave = [
                min(before01, before[2]),
                min(before[1], before[2]),
                min(before[0], before[2]),
                before[2],
                before01,
                before[1],
                before[0],
                t1,
            ];
            let cell = Cell {
                e: &e,
                mid,
                enter: &enter,
                leave: &leave,
                active,
                negative: p.negative,
                node_mask: node.mask(),
                first_child: node,
            };
            // The octants by their far bits (those past a mid-plane along
            // the rays), farthest first, so the nearest is popped next.
            cell.push::<7, _>(entries, &mut top, visitor);
            cell.push::<3, _>(entries, &mut top, visitor);
            cell.push::<5, _>(entries, &mut top, visitor);
            cell.push::<6, _>(entries, &mut top, visitor);
            cell.push::<1, _>(entries, &mut top, visitor);
            cell.push::<2, _>(entries, &mut top, visitor);
            cell.push::<4, _>(entries, &mut top, visitor);
            cell.push::<0, _>(entries, &mut top, visitor);
        }
    }
}

/// An interior cell being split for a packet.
struct Cell<'a, const N: usize> {
    e: &'a CellEntry<F64s<N>>,
    /// The mid-planes, where the upper children start.
    mid: [f64; 3],
    /// Each octant's entry and exit per lane, by its far bits.
    enter: &'a [F64s<N>; 8],
    leave: &'a [F64s<N>; 8],
    active: u32,
    negative: u32,
    node_mask: u32,
    first_child: Node,
}

impl<const N: usize> Cell<'_, N> {
    /// Pushes the child whose far bits are `FAR` (bit k: past the mid-plane
    /// of axis k along the rays) if a lane enters it before its limit.
    #[inline(always)]
    fn push<const FAR: u32, V: PacketVisitor<N>>(
        &self,
        entries: &mut [CellEntry<F64s<N>>; PACKET_STACK_CAPACITY],
        top: &mut usize,
        visitor: &mut V,
    ) {
        let (c0, c1) = (self.enter[FAR as usize], self.leave[FAR as usize]);
        let inside = mask(c0, c1, |a, b| a <= b) & self.active;
        if inside == 0 {
            return;
        }
        let c = (FAR ^ self.negative) as usize & 7;
        if self.node_mask >> c & 1 == 0 {
            // An empty octant: entered (Havran's measures count it),
            // nothing to test.
            let n = inside.count_ones();
            visitor.counter().add_lanes(0, n, n);
            return;
        }
        let e = self.e;
        entries[*top & (PACKET_STACK_CAPACITY - 1)] = CellEntry {
            min: child_corner(e.min, self.mid, c),
            t0: c0,
            t1: c1,
            node: self.first_child.child(c),
            level: e.level + 1,
        };
        *top += 1;
    }
}
