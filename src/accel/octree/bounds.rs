//! The box of what each node holds, for the single-ray walk to test a
//! node's children eight at a time (`wide_walk.rs`). A cell is a cube,
//! often mostly empty: the box of the shapes it references, clipped to
//! it, lets a ray skip the empty part the way a BVH node does (Embree's
//! 8-wide nodes). Boxes are `f32`, relative to the root's lowest corner
//! and rounded outward, in structure-of-arrays layout indexed by node, so
//! the children of a node (stored consecutively) are eight consecutive
//! lanes of each plane. The test is conservative in the manner of Ize,
//! "Robust BVH Ray Traversal" (JCGT 2013): the ray's origin is rounded
//! away from each plane it is tested against and the intervals are widened
//! by more than `f32` arithmetic can err, so a box is never missed where
//! the ray meets it; the shapes are then tested in `f64` as before.

use super::node::{Cell, Node};
use crate::math::Aabb;
use crate::shapes::{PreparedRay, Shape};

/// Lanes a node's children take: one per octant.
pub(super) const WIDTH: usize = 8;

/// Growth of every box beyond its contents, relative to the root's side:
/// far above the rounding of `f64` hit points (so a computed hit never
/// lies outside the box of the shape it is on), far below the size of
/// anything a scene models.
const PAD_RELATIVE: f64 = 1e-9;

/// Relative error allowed each slab parameter: more than the three
/// roundings (subtraction, product, reciprocal) of `f32` arithmetic can
/// move it.
const WIDEN: f32 = 1.0 / (1 << 20) as f32;

/// Root sides outside this range keep the exact walk alone: relative
/// coordinates must stay normal, finite `f32` numbers with room to spare.
const SIDE_RANGE: std::ops::RangeInclusive<f64> = 1e-30..=1e30;

/// Axis-parallel or nearly so: such an axis's slab is not tested (which
/// only adds visits), so no product can overflow into a NaN.
const MAX_INVERSE: f64 = 1e30;

/// Each stored node's box: `planes[2k]` the lowest coordinate along axis
/// `k`, `planes[2k + 1]` the highest, relative to the root's corner.
#[derive(Clone, Debug, Default)]
pub(super) struct NodeBoxes {
    planes: [Vec<f32>; 6],
}

impl NodeBoxes {
    /// Bytes per stored node.
    pub(super) const BYTES_PER_NODE: u64 = 6 * 4;

    /// The boxes of a tree's nodes (`nodes` and `refs` in the root cell
    /// `root`) over `shapes`; empty when the root's size is outside what
    /// `f32` boxes can hold faithfully.
    pub(super) fn build(nodes: &[Node], refs: &[u32], root: Cell, shapes: &[Shape]) -> Self {
        if nodes.is_empty() || !SIDE_RANGE.contains(&root.side) {
            return Self::default();
        }
        // Node count plus a node's width of padding: eight lanes can be
        // read from any node, and lanes past a node's children are masked.
        let len = nodes.len() + WIDTH;
        let empty_lo = vec![f32::MAX; len];
        let empty_hi = vec![-f32::MAX; len];
        let mut boxes = Self {
            planes: [
                empty_lo.clone(),
                empty_hi.clone(),
                empty_lo.clone(),
                empty_hi.clone(),
                empty_lo,
                empty_hi,
            ],
        };
        let pad = PAD_RELATIVE * root.side;
        let mut fill = Fill {
            nodes,
            refs,
            shapes,
            origin: root.min,
            pad,
            boxes: &mut boxes,
        };
        fill.node(0, root);
        boxes
    }

    pub(super) fn is_empty(&self) -> bool {
        self.planes[0].is_empty()
    }

    pub(super) fn memory_bytes(&self) -> u64 {
        self.planes.iter().map(|p| p.len() as u64 * 4).sum()
    }

    /// The lanes of nodes `first .. first + count` (at most eight) whose box
    /// `ray` may meet before `limit` (from [`limit_f32`]), and where it may
    /// enter each (not before 0): never a lane it does meet, nor a later
    /// entry.
    #[inline(always)]
    pub(super) fn hit(
        &self,
        first: usize,
        count: u32,
        ray: &BoxRay,
        limit: f32,
    ) -> (u32, [f32; 8]) {
        let plane = |p: usize| -> &[f32; WIDTH] {
            match self.planes[p].get(first..first + WIDTH) {
                Some(s) => s.try_into().unwrap_or(&[0.0; WIDTH]),
                None => &[0.0; WIDTH],
            }
        };
        let mut near = [f32::NEG_INFINITY; WIDTH];
        let mut far = [f32::INFINITY; WIDTH];
        for k in 0..3 {
            let (np, fp) = (plane(ray.near_plane[k]), plane(ray.far_plane[k]));
            let (no, fo, inv) = (ray.near_origin[k], ray.far_origin[k], ray.inv[k]);
            for j in 0..WIDTH {
                let a = (np[j] - no) * inv;
                let b = (fp[j] - fo) * inv;
                near[j] = if a > near[j] { a } else { near[j] };
                far[j] = if b < far[j] { b } else { far[j] };
            }
        }
        // With the origin rounded away from each plane, a parameter's sign
        // is exact and its size off by a few roundings at most, which
        // `WIDEN` covers: the ray meets the box if it enters before it
        // leaves, does not leave it behind the origin, and enters before
        // the limit (widened by `limit_f32`).
        let mut mask = 0u32;
        let mut entry = [0.0f32; WIDTH];
        for j in 0..WIDTH {
            let meets =
                (near[j] <= far[j] * (1.0 + 2.0 * WIDEN)) & (far[j] >= 0.0) & (near[j] <= limit);
            mask |= (meets as u32) << j;
            entry[j] = if near[j] > 0.0 { near[j] } else { 0.0 };
        }
        (mask & ((1u32 << count) - 1), entry)
    }
}

/// A ray prepared for [`NodeBoxes::hit`]: per axis, the planes it meets
/// first and last (by its direction's sign), its origin relative to the
/// root rounded away from each (so the near parameter can only fall and
/// the far one only rise, and both keep their exact sign), and its
/// reciprocal direction.
#[derive(Clone, Copy, Debug)]
pub(super) struct BoxRay {
    near_plane: [usize; 3],
    far_plane: [usize; 3],
    near_origin: [f32; 3],
    far_origin: [f32; 3],
    inv: [f32; 3],
}

impl BoxRay {
    #[inline(always)]
    pub(super) fn new(ray: &PreparedRay, root: &Cell) -> Self {
        let o = (ray.ray.origin - root.min).to_array();
        let mut near_plane = [0; 3];
        let mut far_plane = [0; 3];
        let mut near_origin = [0.0; 3];
        let mut far_origin = [0.0; 3];
        let mut inv = [1.0; 3];
        for k in 0..3 {
            // `inv_dir` is 0 where the ray is parallel to the axis's planes.
            let d = ray.inv_dir[k];
            let d32 = d as f32;
            let usable = d.abs() <= MAX_INVERSE && d32 != 0.0;
            let negative = d < 0.0;
            let (up, down) = (round_up(o[k]), round_down(o[k]));
            near_plane[k] = 2 * k + negative as usize;
            far_plane[k] = 2 * k + 1 - negative as usize;
            // Unusable: any box passes this axis ((plane - inf) * 1 = -inf
            // for the near plane, +inf for the far one).
            near_origin[k] = match (usable, negative) {
                (false, _) => f32::INFINITY,
                (true, true) => down,
                (true, false) => up,
            };
            far_origin[k] = match (usable, negative) {
                (false, _) => f32::NEG_INFINITY,
                (true, true) => up,
                (true, false) => down,
            };
            inv[k] = if usable { d32 } else { 1.0 };
        }
        BoxRay {
            near_plane,
            far_plane,
            near_origin,
            far_origin,
            inv,
        }
    }
}

/// The limit `t` as an `f32` no smaller than it, widened as the box
/// parameters are.
#[inline(always)]
pub(super) fn limit_f32(t: f64) -> f32 {
    if t.is_nan() {
        return f32::INFINITY;
    }
    round_up(t) * (1.0 + 2.0 * WIDEN)
}

/// Relative step that moves an `f64` past at least two `f32` steps, so
/// that rounding to the nearest `f32` cannot bring it back past where it
/// was; the absolute term does the same at zero.
const STEP: f64 = 1.0 / (1u64 << 21) as f64;
const STEP_AT_ZERO: f64 = 1e-35;

/// An `f32` below `x` (which may itself carry the rounding of the `f64`
/// arithmetic that made it).
#[inline(always)]
fn round_down(x: f64) -> f32 {
    (x - x.abs() * STEP - STEP_AT_ZERO) as f32
}

/// An `f32` above `x`.
#[inline(always)]
fn round_up(x: f64) -> f32 {
    (x + x.abs() * STEP + STEP_AT_ZERO) as f32
}

/// Computes the boxes depth first: a leaf's is the union of its shapes'
/// boxes clipped to its cell, an interior node's the union of its
/// children's.
struct Fill<'a> {
    nodes: &'a [Node],
    refs: &'a [u32],
    shapes: &'a [Shape],
    origin: crate::math::DVec3,
    pad: f64,
    boxes: &'a mut NodeBoxes,
}

impl Fill<'_> {
    fn node(&mut self, index: usize, cell: Cell) -> Aabb {
        let node = self.nodes[index];
        let mut held = Aabb::EMPTY;
        if node.is_leaf() {
            let first = node.first as usize;
            let cell_box = cell.aabb();
            for &r in &self.refs[first..first + node.count() as usize] {
                if let Some(b) = self.shapes[r as usize].bounds() {
                    held = held.union(b.intersection(cell_box));
                }
            }
        } else {
            for c in 0..8 {
                if node.mask() >> c & 1 == 1 {
                    let child = node.child(c) as usize;
                    held = held.union(self.node(child, cell.child(c)));
                }
            }
        }
        if !held.is_empty() {
            let lo = held.min - self.origin;
            let hi = held.max - self.origin;
            for k in 0..3 {
                self.boxes.planes[2 * k][index] = round_down(lo[k] - self.pad);
                self.boxes.planes[2 * k + 1][index] = round_up(hi[k] + self.pad);
            }
        }
        held
    }
}
