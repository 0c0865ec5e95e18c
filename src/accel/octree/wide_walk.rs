//! The single-ray walk when nothing is counted: a node's children are
//! tested eight at once against the boxes of what they hold
//! (`bounds.rs`), as a BVH with eight-wide nodes is (Embree; Wald et al.
//! 2008, "Getting Rid of Packets"), and the children a closest-hit ray
//! meets are visited nearest entry first; a cell whose box starts beyond
//! the best hit so far is skipped. A shadow ray's are visited in a fixed
//! order, the far side along z first. Any order gives the same answer,
//! the exact walk's (`walk.rs`): every shape that could hold the closest
//! hit or block the light is tested, in `f64`, and the closest hit is the
//! lexicographic minimum of `(t, shape index)` whatever the order of the
//! tests. Havran's measures
//! count the exact walk's cells, so a counted query takes that walk.

use super::bounds::{BoxLanes, BoxRay, limit_f32};
use super::tree::Octree;
use super::visit::LeafVisitor;
use crate::limits::MAX_OCTREE_DEPTH;
use crate::shapes::PreparedRay;

/// Room on the stack: each level leaves at most seven siblings waiting,
/// plus the node being entered (a power of two, so indices are masked).
const CAPACITY: usize = (7 * (MAX_OCTREE_DEPTH as usize + 1) + 1).next_power_of_two();

/// A node waiting on the stack, and where the ray may enter its box.
#[derive(Clone, Copy, Debug, Default)]
struct Waiting {
    node: u32,
    entry: f32,
}

/// The wide walk's stack: scratch space the caller owns, like
/// `WalkStack` (`walk.rs`), which holds it.
pub(super) struct WideStack {
    entries: Box<[Waiting; CAPACITY]>,
}

impl Default for WideStack {
    fn default() -> Self {
        Self {
            entries: Box::new([Waiting::default(); CAPACITY]),
        }
    }
}

impl Octree {
    /// Whether the wide walk can run on this tree (its boxes exist).
    #[inline(always)]
    pub(super) fn has_boxes(&self) -> bool {
        !self.boxes.is_empty()
    }

    /// Visits the leaves whose boxes `ray` meets before the visitor's
    /// limit, until the visitor says stop: nearest first if the visitor
    /// asks for it ([`LeafVisitor::NEAREST_FIRST`]), else the far side
    /// along z first.
    #[inline(always)]
    pub(super) fn walk_wide<V: LeafVisitor, L: BoxLanes>(
        &self,
        ray: &PreparedRay,
        stack: &mut WideStack,
        visitor: &mut V,
        lanes: L,
    ) {
        let boxes = &self.boxes;
        let box_ray = BoxRay::new(ray, &self.root_cell());
        let (root, entry) = lanes.hit(boxes.root(), 1, &box_ray, limit_f32(visitor.limit()));
        if root == 0 {
            return;
        }
        let entries = &mut *stack.entries;
        entries[0] = Waiting {
            node: 0,
            entry: entry[0],
        };
        let mut top = 1usize;
        let upward = ray.negative & 0b100 == 0;
        while top > 0 {
            top -= 1;
            let waiting = entries[top & (CAPACITY - 1)];
            // The limit only falls: a box entered past it holds nothing
            // that could change the answer.
            let limit = limit_f32(visitor.limit());
            if waiting.entry > limit {
                continue;
            }
            let mut index = waiting.node;
            loop {
                let node = self.nodes[index as usize];
                if node.is_leaf() {
                    let first = node.first as usize;
                    let refs = &self.refs[first..first + node.count() as usize];
                    if visitor.visit_leaf(refs, f64::NEG_INFINITY, lanes) {
                        return;
                    }
                    break;
                }
                let first = node.first;
                let (mut hits, entry) = lanes.hit(
                    boxes.children(index),
                    node.mask().count_ones(),
                    &box_ray,
                    limit,
                );
                if hits == 0 {
                    break;
                }
                if hits & (hits - 1) == 0 {
                    // One child: enter it without the stack.
                    index = first + hits.trailing_zeros();
                    continue;
                }
                if !V::NEAREST_FIRST {
                    // Not sorted by entry: by stored order, the far side
                    // along z first (children are stored by octant, z's
                    // bit the highest, so that order is monotone in z;
                    // within a z half it is not front to back). The cells
                    // near a shadow ray's origin hold the surface it
                    // leaves and its neighbours, which seldom block it; a
                    // blocker found sooner ends the walk sooner
                    // (docs/notes/experiments.md). One child is entered
                    // next, the others wait.
                    let next = if upward {
                        31 - hits.leading_zeros()
                    } else {
                        hits.trailing_zeros()
                    };
                    hits &= !(1 << next);
                    while hits != 0 {
                        let j = if upward {
                            hits.trailing_zeros()
                        } else {
                            31 - hits.leading_zeros()
                        };
                        hits &= !(1 << j);
                        entries[top & (CAPACITY - 1)] = Waiting {
                            node: first + j,
                            entry: entry[j as usize],
                        };
                        top += 1;
                    }
                    index = first + next;
                    continue;
                }
                // Every child met, kept sorted farthest first above the
                // waiting ones, so the nearest is entered next.
                let base = top;
                while hits != 0 {
                    let j = hits.trailing_zeros();
                    hits &= hits - 1;
                    let child = Waiting {
                        node: first + j,
                        entry: entry[j as usize],
                    };
                    let mut at = top;
                    while at > base && entries[(at - 1) & (CAPACITY - 1)].entry < child.entry {
                        entries[at & (CAPACITY - 1)] = entries[(at - 1) & (CAPACITY - 1)];
                        at -= 1;
                    }
                    entries[at & (CAPACITY - 1)] = child;
                    top += 1;
                }
                top -= 1;
                index = entries[top & (CAPACITY - 1)].node;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::octree::OctreeParams;
    use crate::accel::octree::bounds::Baseline;
    use crate::accel::octree::visit::Visitor;
    use crate::accel::sphere_grid;
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
        tree.walk_wide(ray, &mut WideStack::default(), &mut log, Baseline);
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
