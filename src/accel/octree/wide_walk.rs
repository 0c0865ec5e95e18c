//! The octree as a wide tree (`accel::wide_walk`): an interior node's
//! children are stored by octant, and their boxes are those of what they
//! hold (`bounds.rs`). Havran's measures count the exact walk's cells
//! (`walk.rs`), so a counted query takes that walk instead.

use super::bounds::{Block, BoxRay};
use super::tree::Octree;
use crate::accel::wide_walk::{Opened, WideTree};
use crate::shapes::PreparedRay;

impl Octree {
    /// Whether the wide walk can run on this tree (its boxes exist).
    #[inline(always)]
    pub(super) fn has_boxes(&self) -> bool {
        !self.boxes.is_empty()
    }
}

impl WideTree for Octree {
    const BY_OCTANT: bool = true;

    #[inline(always)]
    fn box_ray(&self, ray: &PreparedRay) -> BoxRay {
        BoxRay::new(ray, &self.root_cell())
    }

    #[inline(always)]
    fn root(&self) -> (&Block, u32) {
        (self.boxes.root(), 0)
    }

    #[inline(always)]
    fn open(&self, index: u32) -> Opened<'_> {
        let node = self.nodes[index as usize];
        if node.is_leaf() {
            let first = node.first as usize;
            Opened::Leaf(&self.refs[first..first + node.count() as usize])
        } else {
            Opened::Interior {
                boxes: self.boxes.children(index),
                count: node.mask().count_ones(),
                first: node.first,
            }
        }
    }

    #[inline(always)]
    fn child(&self, _: u32, first: u32, lane: u32) -> u32 {
        first + lane
    }

    #[inline(always)]
    fn limit(&self, t: f64) -> f64 {
        t
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::leaf_visit::{LeafVisitor, Visitor};
    use crate::accel::octree::OctreeParams;
    use crate::accel::octree::bounds::Baseline;
    use crate::accel::sphere_grid;
    use crate::accel::wide_walk::{WideStack, walk_wide};
    use crate::math::{DVec3, Ray, XorShift};
    use crate::shapes::TriangleLanes;
    use crate::stats::NoCounts;
    use crate::stats::walk_record::WalkEnd;

    /// Records the leaves a walk visits (by where their references start)
    /// and never stops it.
    struct LeafLog<const NEAREST_FIRST: bool> {
        leaves: Vec<usize>,
        counter: NoCounts,
    }

    impl<const NEAREST_FIRST: bool> Visitor for LeafLog<NEAREST_FIRST> {
        type Limit = f64;
        type C = NoCounts;
        fn limit(&self) -> f64 {
            f64::INFINITY
        }
        fn counter(&mut self) -> &mut NoCounts {
            &mut self.counter
        }
    }

    impl<const NEAREST_FIRST: bool> LeafVisitor for LeafLog<NEAREST_FIRST> {
        const STOPPED: WalkEnd = WalkEnd::HitInCell;
        const BEYOND_LIMIT: WalkEnd = WalkEnd::CellsBeyondHit;
        const NEAREST_FIRST: bool = NEAREST_FIRST;
        fn visit_leaf<L: TriangleLanes>(&mut self, refs: &[u32], _: f64, _: L) -> bool {
            self.leaves.push(refs.as_ptr() as usize);
            false
        }
    }

    fn leaves_met<const NEAREST_FIRST: bool>(tree: &Octree, ray: &PreparedRay) -> Vec<usize> {
        let mut log = LeafLog::<NEAREST_FIRST> {
            leaves: Vec::new(),
            counter: NoCounts,
        };
        walk_wide(tree, ray, &mut WideStack::default(), &mut log, Baseline);
        log.leaves
    }

    #[test]
    fn the_far_side_first_order_meets_each_leaf_the_sorted_walk_meets_once() {
        // 512 spheres in a cube, small leaves: deep trees whose nodes meet
        // rays in several children, up and down along z.
        let shapes = sphere_grid(8, 0.3);
        let params = OctreeParams {
            leaf_size: 1,
            ..OctreeParams::default()
        };
        let tree = Octree::build(&shapes, params).unwrap();
        assert!(tree.has_boxes());
        let mut random = XorShift(0x9e37_79b9_7f4a_7c15);
        let (mut several, mut downward) = (0, 0);
        for _ in 0..2000 {
            let mut point = || DVec3::new(random.unit(), random.unit(), random.unit());
            let origin = point() * 7.0;
            let dir = (point() - 0.5).normalize();
            let ray = PreparedRay::new(Ray::new(origin, dir));
            let mut sorted = leaves_met::<true>(&tree, &ray);
            let far_first = leaves_met::<false>(&tree, &ray);
            let mut once = far_first.clone();
            once.sort_unstable();
            once.dedup();
            assert_eq!(once.len(), far_first.len(), "a leaf met twice: {ray:?}");
            sorted.sort_unstable();
            assert_eq!(once, sorted, "{ray:?}");
            several += (far_first.len() > 1) as u32;
            downward += (dir.z < 0.0) as u32;
        }
        // The rays exercised both orders through many leaves.
        assert!(several > 1000 && downward > 500, "{several} {downward}");
    }
}
