//! The traversal: depth first, nearer child first, for the closest hit and
//! for shadow rays.

use super::node::BvhNode;
use super::tree::Bvh;
use crate::accel::octree::bounds::{Baseline, BoxLanes};
use crate::accel::primitives::{
    ClosestHit, Primitives, ShadowCrossings, test_closest, test_occlusion,
};
use crate::shapes::PreparedRay;
use crate::stats::{Counter, NoCounts};

/// A node is skipped only when the ray enters it this far (relative)
/// beyond the best hit or the end of the ray: far above the rounding of
/// the slab test and of hit distances, so a hit that ties with the best
/// is never skipped.
const SLACK: f64 = 1e-9;

/// The nodes still to visit, with the distance at which the ray enters
/// each (binary walk, and wide walk). One per tile, so no ray allocates.
#[derive(Default)]
pub struct BvhStack {
    binary: Vec<(u32, f64)>,
    wide: Vec<(u32, f32)>,
}

/// `t` grown by [`SLACK`].
#[inline(always)]
fn widen(t: f64) -> f64 {
    t + t.abs() * SLACK
}

impl BvhNode {
    /// Where the ray enters the box within `[0, t_max]`, or `None` if it
    /// misses ([`PreparedRay::box_range`], far sides widened by [`SLACK`]).
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
        let mut best = None;
        for &i in &self.unbounded {
            test_closest(prims, i, ray, &mut best, t_max, counter);
        }
        let limit = |best: &Option<ClosestHit>| widen(best.map_or(t_max, |b| b.hit.t));
        let Some(root) = self.nodes.first() else {
            return best;
        };
        if !C::COUNTS && self.has_wide() {
            let best = std::cell::Cell::new(best);
            self.wide.walk(
                ray.ray.origin.to_array(),
                ray.inv_dir,
                &mut stack.wide,
                lanes,
                || limit(&best.get()),
                |first, count| {
                    let mut found = best.get();
                    let refs = &self.refs[first as usize..(first + count) as usize];
                    for &shape in refs {
                        test_closest(prims, shape, ray, &mut found, t_max, &mut NoCounts);
                    }
                    best.set(found);
                    false
                },
            );
            return best.get();
        }
        let stack = &mut stack.binary;
        stack.clear();
        if let Some(t) = root.entry(ray, limit(&best)) {
            stack.push((0, t));
        }
        while let Some((index, t_enter)) = stack.pop() {
            if t_enter > limit(&best) {
                continue;
            }
            counter.traversal_step();
            let node = &self.nodes[index as usize];
            if node.count > 0 {
                counter.leaf_visit();
                let start = node.first_or_second as usize;
                for &shape in &self.refs[start..start + node.count as usize] {
                    test_closest(prims, shape, ray, &mut best, t_max, counter);
                }
                continue;
            }
            let (first, second) = (index + 1, node.first_or_second);
            let t_max = limit(&best);
            let near = self.nodes[first as usize].entry(ray, t_max);
            let far = self.nodes[second as usize].entry(ray, t_max);
            match (near, far) {
                (Some(a), Some(b)) if b < a => {
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
        best
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
        let Some(root) = self.nodes.first() else {
            return;
        };
        let limit = widen(t_max);
        if !C::COUNTS && self.has_wide() {
            self.wide.walk(
                ray.ray.origin.to_array(),
                ray.inv_dir,
                &mut stack.wide,
                lanes,
                || limit,
                |first, count| {
                    let refs = &self.refs[first as usize..(first + count) as usize];
                    refs.iter().any(|&shape| {
                        test_occlusion(prims, shape, ray, t_max, found, &mut NoCounts)
                    })
                },
            );
            return;
        }
        let stack = &mut stack.binary;
        stack.clear();
        if root.entry(ray, limit).is_some() {
            stack.push((0, 0.0));
        }
        while let Some((index, _)) = stack.pop() {
            counter.traversal_step();
            let node = &self.nodes[index as usize];
            if node.count > 0 {
                counter.leaf_visit();
                let start = node.first_or_second as usize;
                for &shape in &self.refs[start..start + node.count as usize] {
                    if test_occlusion(prims, shape, ray, t_max, found, counter) {
                        return;
                    }
                }
                continue;
            }
            for child in [node.first_or_second, index + 1] {
                if self.nodes[child as usize].entry(ray, limit).is_some() {
                    stack.push((child, 0.0));
                }
            }
        }
    }
}
