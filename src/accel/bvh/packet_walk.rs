//! The traversal for packets of coherent rays: the binary tree depth
//! first, a node visited while any lane enters its box before that lane's
//! best hit, the child the packet enters first taken first. A packet's
//! lanes share their direction's signs, so each box's near and far planes
//! are the same for every lane. Each lane keeps its own closest hit, and a
//! lane's answer is exactly the single ray's (the primitive tests and the
//! tie rule are theirs).

// Lane loops index several arrays by the same lane number.
#![allow(clippy::needless_range_loop)]

use super::node::BvhNode;
use super::tree::Bvh;
use crate::accel::primitives::Primitives;
use crate::shapes::{PacketHits, RayPacket};
use crate::simd::{F64s, lanes, mask, max, min};
use crate::stats::Counter;

/// A packet's stack: nodes to visit.
#[derive(Default)]
pub struct BvhPacketStack(Vec<u32>);

/// `t` grown as the single-ray walk grows its limits (`walk.rs`).
#[inline(always)]
fn widen<const N: usize>(t: F64s<N>) -> F64s<N> {
    lanes!(N, |i| t[i] + t[i].abs() * super::walk::SLACK)
}

impl BvhNode {
    /// The lanes of `p` that enter this box before `limit` (not behind
    /// their origin), and where the first of them enters.
    #[inline(always)]
    fn lanes_entering<const N: usize>(&self, p: &RayPacket<N>, limit: F64s<N>) -> (u32, f64) {
        let (lo, hi) = (self.bounds.min.to_array(), self.bounds.max.to_array());
        let mut t0 = [0.0f64; N];
        let mut t1 = limit;
        for k in 0..3 {
            let (near_plane, far_plane) = if p.negative >> k & 1 == 1 {
                (hi[k], lo[k])
            } else {
                (lo[k], hi[k])
            };
            let near: F64s<N> = lanes!(N, |i| (near_plane - p.origin[k][i]) * p.inv_dir[k][i]);
            let far: F64s<N> = lanes!(N, |i| (far_plane - p.origin[k][i]) * p.inv_dir[k][i]);
            t0 = max(t0, near);
            t1 = min(t1, widen(far));
        }
        let hit = mask(t0, t1, |a, b| a <= b) & p.live;
        let mut first = f64::INFINITY;
        for i in 0..N {
            if hit >> i & 1 == 1 && t0[i] < first {
                first = t0[i];
            }
        }
        (hit, first)
    }
}

impl Bvh {
    /// Each lane's closest hit with `0 < t < t_max[lane]`, as
    /// [`Bvh::closest`] finds it for the lane's ray alone.
    #[inline(always)]
    pub fn closest_packet<C: Counter, const N: usize>(
        &self,
        prims: &Primitives,
        packet: &RayPacket<N>,
        t_max: F64s<N>,
        stack: &mut BvhPacketStack,
        counter: &mut C,
    ) -> PacketHits<N> {
        let mut best = PacketHits::new(t_max);
        for &i in &self.unbounded {
            prims.closest_lanes(i, packet, packet.live, &mut best, counter);
        }
        let stack = &mut stack.0;
        stack.clear();
        if !self.nodes.is_empty() {
            stack.push(0);
        }
        while let Some(index) = stack.pop() {
            let node = &self.nodes[index as usize];
            let (lanes, _) = node.lanes_entering(packet, widen(best.t));
            if lanes == 0 {
                continue;
            }
            if node.count > 0 {
                counter.add_lanes(0, lanes.count_ones(), lanes.count_ones());
                let start = node.first_or_second as usize;
                for &shape in &self.refs[start..start + node.count as usize] {
                    prims.closest_lanes(shape, packet, lanes, &mut best, counter);
                }
                continue;
            }
            counter.add_lanes(0, lanes.count_ones(), 0);
            let limit = widen(best.t);
            let (first, second) = (index + 1, node.first_or_second);
            let (a, ta) = self.nodes[first as usize].lanes_entering(packet, limit);
            let (b, tb) = self.nodes[second as usize].lanes_entering(packet, limit);
            // The child entered first is taken first (pushed last).
            let (near, far) = if tb < ta {
                ((second, b), (first, a))
            } else {
                ((first, a), (second, b))
            };
            if far.1 != 0 {
                stack.push(far.0);
            }
            if near.1 != 0 {
                stack.push(near.0);
            }
        }
        best
    }
}
