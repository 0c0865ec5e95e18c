//! What the octree's cell walks share: the single-ray walk (`walk.rs`,
//! Revelles' sequence of children for one ray) and the packet walk
//! (`packet_walk.rs`, a fixed front-to-back order of octants for rays that
//! share signs) are different algorithms around the same stack of cells
//! waiting to be visited, written here once. What every walk does at a
//! leaf, and the mailbox that tests a shape once per ray, is
//! `accel::leaf_visit`, which the wide walk and the BVH's walks share.
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

use crate::simd::F64s;

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
