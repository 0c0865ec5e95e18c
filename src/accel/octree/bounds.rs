//! The box of what each node holds, for the single-ray walk to test a
//! node's children eight at a time (`accel/wide_walk.rs`). A cell is a cube,
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
use crate::shapes::{PreparedRay, Shape, TriangleLanes};

/// Lanes a node's children take: one per octant.
pub(super) const WIDTH: usize = 8;

/// Growth of every box beyond its contents, relative to the root's side:
/// far above the rounding of `f64` hit points (so a computed hit never
/// lies outside the box of the shape it is on), far below the size of
/// anything a scene models.
pub(crate) const PAD_RELATIVE: f64 = 1e-9;

/// Relative error allowed each slab parameter: more than the three
/// roundings (subtraction, product, reciprocal) of `f32` arithmetic can
/// move it.
const WIDEN: f32 = 1.0 / (1 << 20) as f32;

/// Root sides outside this range keep the exact walk alone: relative
/// coordinates must stay normal, finite `f32` numbers with room to spare.
pub(crate) const SIDE_RANGE: std::ops::RangeInclusive<f64> = 1e-30..=1e30;

/// Axis-parallel or nearly so: such an axis's slab is not tested (which
/// only adds visits), so no product can overflow into a NaN.
const MAX_INVERSE: f64 = 1e30;

/// The boxes of an interior node's children, one lane each in storage
/// order, as six planes of eight lanes: `planes[2k]` the lowest coordinate
/// along axis `k`, `planes[2k + 1]` the highest, relative to the root's
/// corner. Lanes past the children hold an empty box. One aligned block
/// per interior node: a node's test loads six registers, no more.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub struct Block {
    planes: [[f32; WIDTH]; 6],
}

impl Block {
    /// The planes a ray meets first and last along axis `k` (`k` < 3),
    /// by the sign of its direction.
    #[inline(always)]
    fn near_far(&self, k: usize, negative: bool) -> (&[f32; WIDTH], &[f32; WIDTH]) {
        let (lo, hi) = match k {
            0 => (&self.planes[0], &self.planes[1]),
            1 => (&self.planes[2], &self.planes[3]),
            _ => (&self.planes[4], &self.planes[5]),
        };
        if negative { (hi, lo) } else { (lo, hi) }
    }

    /// Writes `held` grown by `pad`, relative to `origin` and rounded
    /// outward, into lane `lane` (an empty box stays empty).
    pub(crate) fn set(&mut self, lane: usize, held: Aabb, origin: crate::math::DVec3, pad: f64) {
        if held.is_empty() {
            return;
        }
        let (lo, hi) = (held.min - origin, held.max - origin);
        for k in 0..3 {
            self.planes[2 * k][lane] = round_down(lo[k] - pad);
            self.planes[2 * k + 1][lane] = round_up(hi[k] + pad);
        }
    }

    /// Whether `ray` meets lane `lane`'s box before `limit`: one lane of
    /// [`BoxLanes::hit`], the same operations in the same order.
    #[inline(always)]
    pub(super) fn meets(&self, lane: usize, ray: &BoxRay, limit: f32) -> bool {
        let (mut near, mut far) = (f32::NEG_INFINITY, f32::INFINITY);
        for k in 0..3 {
            let (np, fp) = self.near_far(k, ray.negative[k]);
            let a = (np[lane] - ray.near_origin[k]) * ray.inv[k];
            let b = (fp[lane] - ray.far_origin[k]) * ray.inv[k];
            near = if a > near { a } else { near };
            far = if b < far { b } else { far };
        }
        (near <= far * (1.0 + 2.0 * WIDEN)) & (far >= 0.0) & (near <= limit)
    }

    /// The surface area of lane `lane`'s box (0 for an empty lane).
    pub(super) fn surface_area(&self, lane: usize) -> f64 {
        let side = |k: usize| {
            (self.planes[2 * k + 1][lane] as f64 - self.planes[2 * k][lane] as f64).max(0.0)
        };
        let (x, y, z) = (side(0), side(1), side(2));
        2.0 * (x * y + y * z + z * x)
    }

    pub(crate) const EMPTY: Block = Block {
        planes: [
            [f32::MAX; WIDTH],
            [-f32::MAX; WIDTH],
            [f32::MAX; WIDTH],
            [-f32::MAX; WIDTH],
            [f32::MAX; WIDTH],
            [-f32::MAX; WIDTH],
        ],
    };
}

impl Default for Block {
    fn default() -> Self {
        Block::EMPTY
    }
}

/// The boxes of what each node holds: a [`Block`] per interior node (of
/// its children's boxes) and one for the root's own box (lane 0).
#[derive(Clone, Debug, Default)]
pub struct NodeBoxes {
    blocks: Vec<Block>,
    /// Per stored node: its block (interior nodes), or `u32::MAX`.
    block_of: Vec<u32>,
}

impl NodeBoxes {
    /// Bytes per stored node (its block index) and per interior node (its
    /// children's block).
    pub(super) const BYTES_PER_NODE: u64 = 4;
    pub(super) const BYTES_PER_INTERIOR_NODE: u64 = std::mem::size_of::<Block>() as u64;

    /// The boxes of a tree's nodes (`nodes` and `refs` in the root cell
    /// `root`) over `shapes`; empty when the root's size is outside what
    /// `f32` boxes can hold faithfully.
    pub(super) fn build(nodes: &[Node], refs: &[u32], root: Cell, shapes: &[Shape]) -> Self {
        if nodes.is_empty() || !SIDE_RANGE.contains(&root.side) {
            return Self::default();
        }
        let mut boxes = Self {
            // Block 0: the root's own box.
            blocks: vec![Block::EMPTY],
            block_of: vec![u32::MAX; nodes.len()],
        };
        let mut fill = Fill {
            nodes,
            refs,
            shapes,
            origin: root.min,
            pad: PAD_RELATIVE * root.side,
            boxes: &mut boxes,
        };
        let held = fill.node(0, root);
        fill.set(0, 0, held);
        boxes
    }

    pub(super) fn is_empty(&self) -> bool {
        self.blocks.is_empty()
    }

    pub(super) fn memory_bytes(&self) -> u64 {
        (self.blocks.len() * std::mem::size_of::<Block>() + self.block_of.len() * 4) as u64
    }

    /// The root's box, in lane 0.
    #[inline(always)]
    pub(super) fn root(&self) -> &Block {
        self.blocks.first().unwrap_or(&Block::EMPTY)
    }

    /// The boxes of interior node `node`'s children.
    #[inline(always)]
    pub(super) fn children(&self, node: u32) -> &Block {
        let block = self.block_of.get(node as usize).copied().unwrap_or(0);
        self.blocks.get(block as usize).unwrap_or(&Block::EMPTY)
    }
}

/// How the eight boxes of a node's children are tested: the lanes' code
/// for a SIMD level. Each answers the same (see [`BoxLanes::hit`]).
pub trait BoxLanes: TriangleLanes {
    /// The lanes `0 .. count` (at most eight) of `block` whose box `ray`
    /// may meet before `limit` (from `limit_f32`), and where it
    /// may enter each (not before 0): never a lane it does meet, nor a
    /// later entry.
    ///
    /// With the origin rounded away from each plane, a parameter's sign is
    /// exact and its size off by a few roundings at most, which `WIDEN`
    /// covers: the ray meets the box if it enters before it leaves, does
    /// not leave it behind the origin, and enters before the limit
    /// (widened by `limit_f32`).
    fn hit(self, block: &Block, count: u32, ray: &BoxRay, limit: f32) -> (u32, [f32; WIDTH]);
}

/// Baseline x86-64 (or any machine): plain loops over the lanes.
#[derive(Clone, Copy, Debug, Default)]
pub struct Baseline;

/// Baseline tests triangles one by one.
impl TriangleLanes for Baseline {
    const FOUR_AT_ONCE: bool = false;
}

/// Another level's boxes with triangles tested one by one: for scenes
/// where fewer than half the shapes are triangles, where sorting them out
/// for batches costs more than the batches save (and a copy of the walk
/// of its own keeps their code as it was).
#[derive(Clone, Copy, Debug)]
pub(crate) struct OneByOne<L>(pub L);

impl<L: BoxLanes> TriangleLanes for OneByOne<L> {
    const FOUR_AT_ONCE: bool = false;
}

impl<L: BoxLanes> BoxLanes for OneByOne<L> {
    #[inline(always)]
    fn hit(self, block: &Block, count: u32, ray: &BoxRay, limit: f32) -> (u32, [f32; WIDTH]) {
        self.0.hit(block, count, ray, limit)
    }
}

/// Another level's lanes, with shadow rays skipping the shapes in the
/// plane they leave ([`TriangleLanes::SKIPS_PLANES`]).
#[derive(Clone, Copy, Debug)]
pub(crate) struct SkippingPlanes<L>(pub L);

impl<L: BoxLanes> TriangleLanes for SkippingPlanes<L> {
    const FOUR_AT_ONCE: bool = L::FOUR_AT_ONCE;
    const SKIPS_PLANES: bool = true;

    #[inline(always)]
    fn intersect_four(
        self,
        triangles: [&crate::shapes::Triangle; 4],
        live: u32,
        ray: &crate::shapes::PreparedRay,
        t_max: f64,
    ) -> crate::shapes::FourHits {
        self.0.intersect_four(triangles, live, ray, t_max)
    }
}

impl<L: BoxLanes> BoxLanes for SkippingPlanes<L> {
    #[inline(always)]
    fn hit(self, block: &Block, count: u32, ray: &BoxRay, limit: f32) -> (u32, [f32; WIDTH]) {
        self.0.hit(block, count, ray, limit)
    }
}

impl BoxLanes for Baseline {
    #[inline(always)]
    fn hit(self, block: &Block, count: u32, ray: &BoxRay, limit: f32) -> (u32, [f32; WIDTH]) {
        let mut near = [f32::NEG_INFINITY; WIDTH];
        let mut far = [f32::INFINITY; WIDTH];
        for k in 0..3 {
            let (np, fp) = block.near_far(k, ray.negative[k]);
            let (no, fo, inv) = (ray.near_origin[k], ray.far_origin[k], ray.inv[k]);
            for j in 0..WIDTH {
                let a = (np[j] - no) * inv;
                let b = (fp[j] - fo) * inv;
                near[j] = if a > near[j] { a } else { near[j] };
                far[j] = if b < far[j] { b } else { far[j] };
            }
        }
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

/// AVX2: the eight lanes in one register, the same operations in the same
/// order as [`Baseline`] (no NaN can arise, so `max` and `min` agree).
impl BoxLanes for pulp::x86::V3 {
    #[inline(always)]
    fn hit(self, block: &Block, count: u32, ray: &BoxRay, limit: f32) -> (u32, [f32; WIDTH]) {
        use pulp::{Simd, cast, f32x8};
        let simd = self;
        let mut near = simd.splat_f32s(f32::NEG_INFINITY);
        let mut far = simd.splat_f32s(f32::INFINITY);
        for k in 0..3 {
            let (np, fp) = block.near_far(k, ray.negative[k]);
            let (np, fp): (f32x8, f32x8) = (cast(*np), cast(*fp));
            let (no, fo) = (
                simd.splat_f32s(ray.near_origin[k]),
                simd.splat_f32s(ray.far_origin[k]),
            );
            let inv = simd.splat_f32s(ray.inv[k]);
            let a = simd.mul_f32s(simd.sub_f32s(np, no), inv);
            let b = simd.mul_f32s(simd.sub_f32s(fp, fo), inv);
            near = simd.max_f32s(near, a);
            far = simd.min_f32s(far, b);
        }
        let zero = simd.splat_f32s(0.0);
        let widened = simd.mul_f32s(far, simd.splat_f32s(1.0 + 2.0 * WIDEN));
        let meets = simd.and_m32s(
            simd.and_m32s(
                simd.less_than_or_equal_f32s(near, widened),
                simd.greater_than_or_equal_f32s(far, zero),
            ),
            simd.less_than_or_equal_f32s(near, simd.splat_f32s(limit)),
        );
        let mask = simd.avx._mm256_movemask_ps(cast(meets)) as u32;
        let entry: [f32; WIDTH] = cast(simd.max_f32s(near, zero));
        (mask & ((1u32 << count) - 1), entry)
    }
}

/// A ray prepared for [`NodeBoxes::hit`]: per axis, the planes it meets
/// first and last (by its direction's sign), its origin relative to the
/// root rounded away from each (so the near parameter can only fall and
/// the far one only rise, and both keep their exact sign), and its
/// reciprocal direction.
#[derive(Clone, Copy, Debug)]
pub struct BoxRay {
    /// Per axis: the direction is negative (the near plane is the high one).
    negative: [bool; 3],
    near_origin: [f32; 3],
    far_origin: [f32; 3],
    inv: [f32; 3],
}

impl BoxRay {
    #[inline(always)]
    pub(super) fn new(ray: &PreparedRay, root: &Cell) -> Self {
        Self::from_parts(ray.ray.origin.to_array(), ray.inv_dir, root)
    }

    /// The ray from `origin` whose reciprocal direction is `inv_dir` (0
    /// where it is parallel to an axis's planes).
    #[inline(always)]
    pub(super) fn from_parts(origin: [f64; 3], inv_dir: [f64; 3], root: &Cell) -> Self {
        Self::relative_to(origin, inv_dir, root.min)
    }

    /// The same, for boxes relative to `corner`.
    #[inline(always)]
    pub(crate) fn relative_to(
        origin: [f64; 3],
        inv_dir: [f64; 3],
        corner: crate::math::DVec3,
    ) -> Self {
        // The roundings in four lanes (the last a copy of the first),
        // without branches, so they compile to a few vector instructions:
        // one lane at a time, they were a tenth of a single ray's walk.
        let o = [
            origin[0] - corner.x,
            origin[1] - corner.y,
            origin[2] - corner.z,
            origin[0] - corner.x,
        ];
        let d = [inv_dir[0], inv_dir[1], inv_dir[2], inv_dir[0]];
        let mut up = [0.0f32; 4];
        let mut down = [0.0f32; 4];
        let mut d32 = [0.0f32; 4];
        for k in 0..4 {
            up[k] = round_up(o[k]);
            down[k] = round_down(o[k]);
            d32[k] = d[k] as f32;
        }
        let mut negative_axes = [false; 3];
        let mut near_origin = [0.0; 3];
        let mut far_origin = [0.0; 3];
        let mut inv = [1.0; 3];
        for k in 0..3 {
            // `inv_dir` is 0 where the ray is parallel to the axis's planes.
            let usable = d[k].abs() <= MAX_INVERSE && d32[k] != 0.0;
            let negative = d[k] < 0.0;
            negative_axes[k] = negative;
            // Unusable: any box passes this axis ((plane - inf) * 1 = -inf
            // for the near plane, +inf for the far one).
            let (near, far) = if negative {
                (down[k], up[k])
            } else {
                (up[k], down[k])
            };
            near_origin[k] = if usable { near } else { f32::INFINITY };
            far_origin[k] = if usable { far } else { f32::NEG_INFINITY };
            inv[k] = if usable { d32[k] } else { 1.0 };
        }
        BoxRay {
            negative: negative_axes,
            near_origin,
            far_origin,
            inv,
        }
    }
}

/// The limit `t` as an `f32` no smaller than it, widened as the box
/// parameters are.
#[inline(always)]
pub(crate) fn limit_f32(t: f64) -> f32 {
    if !t.is_finite() {
        // No limit, or (a blocked shadow lane) below everything.
        return if t == f64::NEG_INFINITY {
            f32::NEG_INFINITY
        } else {
            f32::INFINITY
        };
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
/// children's, each written into its parent's block.
struct Fill<'a> {
    nodes: &'a [Node],
    refs: &'a [u32],
    shapes: &'a [Shape],
    origin: crate::math::DVec3,
    pad: f64,
    boxes: &'a mut NodeBoxes,
}

impl Fill<'_> {
    /// The box of what node `index` (in `cell`) holds, its children's
    /// boxes written into its block.
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
            return held;
        }
        let block = self.boxes.blocks.len();
        self.boxes.blocks.push(Block::EMPTY);
        self.boxes.block_of[index] = block as u32;
        let mut lane = 0;
        for c in 0..8 {
            if node.mask() >> c & 1 == 1 {
                let child = node.child(c) as usize;
                let child_held = self.node(child, cell.child(c));
                self.set(block, lane, child_held);
                held = held.union(child_held);
                lane += 1;
            }
        }
        held
    }

    /// Writes `held`, padded, relative and rounded outward, into lane
    /// `lane` of block `block` (an empty box stays empty).
    fn set(&mut self, block: usize, lane: usize, held: Aabb) {
        self.boxes.blocks[block].set(lane, held, self.origin, self.pad);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{Aabb, DVec3, Ray, XorShift};
    use crate::shapes::PreparedRay;

    /// Rays that touch a box only at a corner, an edge or a face (and rays
    /// along an axis, which the rounding of the origin must not cut off)
    /// are met, entering no later than the touching point: the `f32`
    /// boxes and rounded origins are conservative where they are tightest.
    #[test]
    fn rays_grazing_a_box_meet_it() {
        let mut random = XorShift(0x9e37_79b9_7f4a_7c15);
        let corner = DVec3::new(-3.0, 1.5, 7.25);
        for case in 0..20_000 {
            let scale = [1e-3, 1.0, 1e3][case % 3];
            let mut point =
                || DVec3::new(random.unit(), random.unit(), random.unit()) * scale + corner;
            let (p, q) = (point(), point());
            let held = Aabb::new(p.min(q), p.max(q));
            let mut block = Block::EMPTY;
            block.set(0, held, corner, 0.0);
            // A point of the box's surface: a corner, or a face's point.
            let mut on = held.min;
            for k in 0..3 {
                let t = random.unit();
                on[k] = match (case / 3 + k) % 3 {
                    0 => held.min[k],
                    1 => held.max[k],
                    _ => held.min[k] + t * (held.max[k] - held.min[k]),
                };
            }
            let mut dir = DVec3::new(
                random.unit() - 0.5,
                random.unit() - 0.5,
                random.unit() - 0.5,
            );
            // Along an axis now and then: the other two reciprocals are 0.
            if case % 7 == 0 {
                dir = DVec3::ZERO;
                dir[case % 3] = if case % 2 == 0 { 1.0 } else { -1.0 };
            }
            let dir = dir.normalize();
            let back = 10.0 * scale * random.unit();
            let origin = on - back * dir;
            let inv_dir = PreparedRay::new(Ray::new(origin, dir)).inv_dir;
            let ray = BoxRay::relative_to(origin.to_array(), inv_dir, corner);
            let (mask, entry) = Baseline.hit(&block, 1, &ray, f32::INFINITY);
            assert_eq!(
                mask, 1,
                "case {case}: {held:?} from {origin:?} along {dir:?}"
            );
            assert!(
                f64::from(entry[0]) <= back * (1.0 + 1e-5),
                "case {case}: enters at {} past {back}",
                entry[0]
            );
        }
    }
}
