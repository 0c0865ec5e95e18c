//! The traversal: depth first, nearer child first, for the closest hit and
//! for shadow rays, one walk for both: the query is a leaf visitor
//! (`accel::leaf_visit`), the octree's own.

use super::node::{BvhNode, widen};
use super::tree::Bvh;
use super::wide::LEAF;
use crate::accel::leaf_visit::{ClosestVisitor, LeafVisitor, OcclusionVisitor};
use crate::accel::octree::bounds::{Baseline, BoxLanes};
use crate::accel::octree::bounds::{Block, BoxRay};
use crate::accel::primitives::{ClosestHit, Primitives, ShadowCrossings, test_occlusion};
use crate::accel::wide_walk::{Opened, WideStack, WideTree, walk_wide};
use crate::shapes::PreparedRay;
use crate::stats::Counter;

/// The nodes still to visit, with the distance at which the ray enters
/// each (binary walk, and wide walk). One per tile, so no ray allocates.
#[derive(Default)]
pub struct BvhStack {
    binary: Vec<(u32, f64)>,
    wide: WideStack,
}

/// The BVH's eight-wide nodes (`wide.rs`) as the wide walk takes them: a
/// lane's child is an entry of its own, a leaf's marked by [`LEAF`].
impl WideTree for Bvh {
    const BY_OCTANT: bool = false;

    #[inline(always)]
    fn box_ray(&self, ray: &PreparedRay) -> BoxRay {
        BoxRay::relative_to(ray.ray.origin.to_array(), ray.inv_dir, self.wide.corner)
    }

    #[inline(always)]
    fn root(&self) -> (&Block, u32) {
        (&self.wide.root, self.wide.root_entry)
    }

    #[inline(always)]
    fn open(&self, at: u32) -> Opened<'_> {
        if at & LEAF != 0 {
            let (first, count) = self.wide.leaves[(at & !LEAF) as usize];
            Opened::Leaf(&self.refs[first as usize..(first + count) as usize])
        } else {
            Opened::Interior {
                boxes: &self.wide.blocks[at as usize],
                count: self.wide.counts[at as usize] as u32,
                first: 0,
            }
        }
    }

    #[inline(always)]
    fn child(&self, node: u32, _: u32, lane: u32) -> u32 {
        self.wide.children[node as usize][lane as usize]
    }

    #[inline(always)]
    fn limit(&self, t: f64) -> f64 {
        widen(t)
    }
}

impl BvhNode {
    /// Where the ray enters the box within `[0, t_max]`, or `None` if it
    /// misses ([`PreparedRay::box_range`], far sides grown by [`widen`]).
    #[inline(always)]
    fn entry(&self, ray: &PreparedRay, t_max: f64) -> Option<f64> {
        ray.box_range(&self.bounds, t_max, widen).map(|(t0, _)| t0)
    }
}

impl Bvh {
    /// Closest hit with `0 < t < t_max`; `stack` is the caller's scratch.
    pub fn closest<C: Counter>(
        &self,
        prims: &Primitives,
        ray: &PreparedRay,
        t_max: f64,
        stack: &mut BvhStack,
        counter: &mut C,
    ) -> Option<ClosestHit> {
        self.closest_inline(prims, ray, t_max, stack, counter, Baseline)
    }

    /// [`Bvh::closest`], inlined into a caller compiled for a SIMD level
    /// whose `lanes` test a wide node's children.
    #[inline(always)]
    pub fn closest_inline<C: Counter, L: BoxLanes>(
        &self,
        prims: &Primitives,
        ray: &PreparedRay,
        t_max: f64,
        stack: &mut BvhStack,
        counter: &mut C,
        lanes: L,
    ) -> Option<ClosestHit> {
        let mut visitor = ClosestVisitor::new(prims, ray, t_max, counter);
        for &i in &self.unbounded {
            visitor.test(i);
        }
        self.walk(ray, stack, &mut visitor, lanes);
        visitor.best()
    }

    /// What a shadow ray meets over `(0, t_max)`, into `found` (cleared
    /// first); stops at the first opaque surface.
    pub fn occlusion<C: Counter>(
        &self,
        prims: &Primitives,
        ray: &PreparedRay,
        t_max: f64,
        found: &mut ShadowCrossings,
        stack: &mut BvhStack,
        counter: &mut C,
    ) {
        self.occlusion_inline(prims, ray, t_max, found, stack, counter, Baseline);
    }

    /// [`Bvh::occlusion`], inlined into a caller compiled for a SIMD level
    /// whose `lanes` test a wide node's children.
    #[inline(always)]
    #[allow(clippy::too_many_arguments)]
    pub fn occlusion_inline<C: Counter, L: BoxLanes>(
        &self,
        prims: &Primitives,
        ray: &PreparedRay,
        t_max: f64,
        found: &mut ShadowCrossings,
        stack: &mut BvhStack,
        counter: &mut C,
        lanes: L,
    ) {
        found.clear();
        for &i in &self.unbounded {
            if test_occlusion(prims, i, ray, t_max, found, counter) {
                return;
            }
        }
        let mut visitor = OcclusionVisitor::new(prims, ray, t_max, found, counter);
        self.walk(ray, stack, &mut visitor, lanes);
    }

    /// Visits the leaves `ray` meets before the visitor's limit until it
    /// says stop: through the wide nodes when nothing is counted, else
    /// through the binary nodes, whose steps the counts are of.
    #[inline(always)]
    fn walk<V: LeafVisitor, L: BoxLanes>(
        &self,
        ray: &PreparedRay,
        stack: &mut BvhStack,
        visitor: &mut V,
        lanes: L,
    ) {
        if !<V::C as Counter>::COUNTS && self.has_wide() {
            walk_wide(self, ray, &mut stack.wide, visitor, lanes);
        } else {
            self.walk_binary(ray, &mut stack.binary, visitor, lanes);
        }
    }

    /// The binary walk: depth first; a closest-hit query enters the nearer
    /// child first ([`LeafVisitor::NEAREST_FIRST`]), a shadow query the
    /// second child first, as stored.
    #[inline(always)]
    fn walk_binary<V: LeafVisitor, L: BoxLanes>(
        &self,
        ray: &PreparedRay,
        stack: &mut Vec<(u32, f64)>,
        visitor: &mut V,
        lanes: L,
    ) {
        let Some(root) = self.nodes.first() else {
            return;
        };
        stack.clear();
        if let Some(t) = root.entry(ray, widen(visitor.limit())) {
            stack.push((0, t));
        }
        while let Some((index, t_enter)) = stack.pop() {
            let limit = widen(visitor.limit());
            if t_enter > limit {
                continue;
            }
            visitor.counter().traversal_step();
            let node = &self.nodes[index as usize];
            if node.count > 0 {
                visitor.counter().leaf_visit();
                let start = node.first_or_second as usize;
                let refs = &self.refs[start..start + node.count as usize];
                if visitor.visit_leaf(refs, f64::NEG_INFINITY, lanes) {
                    return;
                }
                continue;
            }
            let (first, second) = (index + 1, node.first_or_second);
            let near = self.nodes[first as usize].entry(ray, limit);
            let far = self.nodes[second as usize].entry(ray, limit);
            match (near, far) {
                (Some(a), Some(b)) if V::NEAREST_FIRST && b < a => {
                    stack.push((first, a));
                    stack.push((second, b));
                }
                (Some(a), Some(b)) => {
                    stack.push((second, b));
                    stack.push((first, a));
                }
                (Some(a), None) => stack.push((first, a)),
                (None, Some(b)) => stack.push((second, b)),
                (None, None) => {}
            }
        }
    }
}
