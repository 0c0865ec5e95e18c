//! Ray queries over a scene's shapes: brute force over every shape, or
//! through the [`Octree`]. Both answer exactly the same: ties between equal
//! distances go to the lower shape index in both.

mod octree;

pub use octree::{MAX_OCTREE_DEPTH, Octree, OctreeCell, OctreeParams, OctreeStats};

use crate::shapes::{PreparedRay, Shape, ShapeHit};
use crate::stats::Counter;

/// The closest hit found so far.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClosestHit {
    pub shape: u32,
    pub hit: ShapeHit,
}

/// Tests shape `index` and keeps its hit if it is closer than `best`, or as
/// close with a lower index (so the answer never depends on visiting order).
#[inline(always)]
pub(crate) fn test_closest<C: Counter>(
    shapes: &[Shape],
    index: u32,
    ray: &PreparedRay,
    best: &mut Option<ClosestHit>,
    t_max: f64,
    counter: &mut C,
) {
    counter.intersection_test();
    let limit = best.map_or(t_max, |b| b.hit.t);
    // `limit` is exclusive in `intersect`; an equal t with a lower index
    // also wins, so look just past it.
    let probe = if best.is_some() {
        next_up(limit)
    } else {
        limit
    };
    if let Some(hit) = shapes[index as usize].intersect(ray, probe) {
        let better = match best {
            None => true,
            Some(b) => hit.t < b.hit.t || (hit.t == b.hit.t && index < b.shape),
        };
        if better {
            *best = Some(ClosestHit { shape: index, hit });
        }
    }
}

/// The smallest `f64` above `x` (for finite, non-negative `x`).
#[inline(always)]
fn next_up(x: f64) -> f64 {
    if x.is_finite() {
        f64::from_bits(x.to_bits() + 1)
    } else {
        x
    }
}

/// Closest hit by testing every shape in index order.
pub fn closest_brute_force<C: Counter>(
    shapes: &[Shape],
    ray: &PreparedRay,
    t_max: f64,
    counter: &mut C,
) -> Option<ClosestHit> {
    let mut best = None;
    for i in 0..shapes.len() as u32 {
        test_closest(shapes, i, ray, &mut best, t_max, counter);
    }
    best
}

/// What a shadow ray found between its origin and the light.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum Occlusion {
    #[default]
    Clear,
    /// Only transparent shapes are in the way: their indices, unordered,
    /// possibly repeated.
    Transparent(Vec<u32>),
    Blocked,
}

impl Occlusion {
    /// Records a hit on `index`; `true` if the ray is now fully blocked.
    #[inline(always)]
    pub(crate) fn record(&mut self, index: u32, transparent: bool) -> bool {
        if !transparent {
            *self = Occlusion::Blocked;
            return true;
        }
        match self {
            Occlusion::Clear => *self = Occlusion::Transparent(vec![index]),
            Occlusion::Transparent(v) => v.push(index),
            Occlusion::Blocked => return true,
        }
        false
    }
}

/// Any hits in `(0, t_max)`, testing every shape; stops at the first opaque one.
pub fn occlusion_brute_force<C: Counter>(
    shapes: &[Shape],
    is_transparent: &[bool],
    ray: &PreparedRay,
    t_max: f64,
    counter: &mut C,
) -> Occlusion {
    let mut occlusion = Occlusion::Clear;
    for (i, shape) in shapes.iter().enumerate() {
        counter.intersection_test();
        if shape.intersect(ray, t_max).is_some() && occlusion.record(i as u32, is_transparent[i]) {
            break;
        }
    }
    occlusion
}
