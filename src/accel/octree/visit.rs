//! What the walks share: the single-ray walk (`walk.rs`, Revelles'
//! sequence of children for one ray, and `wide_walk.rs`, eight children's
//! boxes at once when nothing is counted) and the packet walk (`packet_walk.rs`,
//! a fixed front-to-back order of octants for rays that share signs) are
//! different algorithms around the same parts, written here once: the stack
//! of cells waiting to be visited, the mailbox that tests a shape once per
//! ray, and what a visitor must tell the walk (its limit and its counter).
//! The tie rule of closest hits (`t`, then the lower shape index) is
//! `shapes::wins`, used by the single-ray test and the packet merge alike,
//! and the six axis permutations of the watertight triangle test are one
//! table (`along_axes!`) for both.
//!
//! What stays apart is what differs: the root slab test (a single ray may
//! be parallel to an axis and is then tested against the slab by its
//! origin; a packet takes no such ray, so its lanes need no branch), the
//! choice of children (Revelles' sequence against a fixed octant order)
//! and the shading of the hits (packets shade each light across their
//! lanes; both call the same per-hit steps in `render::integrator`).

use crate::shapes::TriangleLanes;
use crate::simd::F64s;
use crate::stats::Counter;
use crate::stats::walk_record::WalkEnd;

/// The ray parameters a walk carries per cell: one `f64` for a single ray,
/// one per lane for a packet.
pub(super) trait Params: Copy {
    const ZERO: Self;
}

impl Params for f64 {
    const ZERO: Self = 0.0;
}

impl<const N: usize> Params for F64s<N> {
    const ZERO: Self = [0.0; N];
}

/// A cell waiting on a walk's stack: its lowest corner, its node and its
/// level (which gives its side), and the ray's parameters at its entry and
/// exit (for a packet, per lane; empty where a lane's ray misses it).
#[derive(Clone, Copy, Debug)]
pub(super) struct CellEntry<T> {
    pub min: [f64; 3],
    pub t0: T,
    pub t1: T,
    pub node: u32,
    pub level: u32,
}

/// The cells a walk has still to visit: scratch space the caller owns (one
/// per tile of the image), so no ray sets it up. `CAPACITY` is a power of
/// two, so the walks index it masked instead of bounds-checked.
pub struct CellStack<T, const CAPACITY: usize> {
    entries: Box<[CellEntry<T>; CAPACITY]>,
}

impl<T: Params, const CAPACITY: usize> Default for CellStack<T, CAPACITY> {
    fn default() -> Self {
        const { assert!(CAPACITY.is_power_of_two()) };
        let empty = CellEntry {
            min: [0.0; 3],
            t0: T::ZERO,
            t1: T::ZERO,
            node: 0,
            level: 0,
        };
        Self {
            entries: Box::new([empty; CAPACITY]),
        }
    }
}

impl<T, const CAPACITY: usize> CellStack<T, CAPACITY> {
    /// The entries, as an array whose length the walk's masked indices
    /// are known to fit.
    #[inline(always)]
    pub(super) fn entries(&mut self) -> &mut [CellEntry<T>; CAPACITY] {
        &mut self.entries
    }
}

/// Remembers, for the last shapes tested, the lanes they were tested in
/// (direct-mapped, 16 entries), so a shape referenced from several leaves
/// is tested once per ray. A single ray is lane 0.
pub(super) struct Mailbox([(u32, u32); 16]);

impl Mailbox {
    pub(super) fn new() -> Self {
        Self([(u32::MAX, 0); 16])
    }

    /// For a single ray: `true` if `index` was tested already; records it
    /// otherwise.
    #[inline(always)]
    pub(super) fn seen(&mut self, index: u32) -> bool {
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
    pub(super) fn untested(&mut self, index: u32, lanes: u32) -> u32 {
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
pub(super) trait Visitor {
    /// The limit's form: `f64` for one ray, per lane for a packet.
    type Limit;
    type C: Counter;
    /// Cells starting beyond the limit cannot change the answer.
    fn limit(&self) -> Self::Limit;
    fn counter(&mut self) -> &mut Self::C;
}

/// What a single ray's walk does at its leaves.
pub(super) trait LeafVisitor: Visitor<Limit = f64> {
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
