//! The single-ray walk when nothing is counted, one for the octree and the
//! BVH: a node's children are tested eight at once against their boxes
//! (`octree/bounds.rs`), as a BVH with eight-wide nodes is (Embree; Wald
//! et al. 2008, "Getting Rid of Packets"), and the children a closest-hit
//! ray meets are visited nearest entry first; a child whose box starts
//! beyond the visitor's limit is skipped. Any order gives the same
//! answer: every shape that could hold the closest hit or block the light
//! is tested, in `f64`, and the closest hit is the lexicographic minimum
//! of `(t, shape index)` whatever the order of the tests. So a shadow ray
//! in a tree whose children are stored by octant takes them in that
//! order, the far side along z first, without sorting.

use super::leaf_visit::LeafVisitor;
use super::octree::bounds::{Block, BoxLanes, BoxRay, limit_f32};
use crate::shapes::PreparedRay;

/// Room on the stack: each level leaves at most seven siblings waiting,
/// plus the node being entered; enough for 146 levels (a power of two, so
/// indices are masked). A tree deeper than [`WideStack::MAX_DEPTH`] does
/// not take this walk.
const CAPACITY: usize = 1024;

/// A node a wide tree's walk opens: a leaf's shape references, or an
/// interior node's children's boxes (lanes `0 .. count`) and its first
/// child (what [`WideTree::child`] needs besides the lane).
pub(crate) enum Opened<'a> {
    Leaf(&'a [u32]),
    Interior {
        boxes: &'a Block,
        count: u32,
        first: u32,
    },
}

/// A tree whose interior nodes keep their children's boxes in one
/// [`Block`]: the octree, and the BVH's eight-wide form.
pub(crate) trait WideTree {
    /// Whether an interior node's lanes are its children by octant, z's
    /// bit the highest: then a lane order is monotone in z.
    const BY_OCTANT: bool;
    /// The ray as the boxes take it (relative to the tree's corner).
    fn box_ray(&self, ray: &PreparedRay) -> BoxRay;
    /// The root's box (lane 0 of a block) and the root node.
    fn root(&self) -> (&Block, u32);
    fn open(&self, node: u32) -> Opened<'_>;
    /// The child in `lane` of interior node `node`, whose first child is
    /// `first`.
    fn child(&self, node: u32, first: u32, lane: u32) -> u32;
    /// The limit the boxes are tested against, for the visitor's `t`.
    fn limit(&self, t: f64) -> f64;
}

/// A node waiting on the stack, and where the ray may enter its box.
#[derive(Clone, Copy, Debug, Default)]
struct Waiting {
    node: u32,
    entry: f32,
}

/// The wide walk's stack: scratch space the caller owns (one per tile),
/// so no ray sets it up.
pub(crate) struct WideStack {
    entries: Box<[Waiting; CAPACITY]>,
}

impl WideStack {
    /// The deepest tree the stack holds the walk of.
    pub(crate) const MAX_DEPTH: usize = (CAPACITY - 1) / 7 - 1;
}

impl Default for WideStack {
    fn default() -> Self {
        Self {
            entries: Box::new([Waiting::default(); CAPACITY]),
        }
    }
}

/// Visits the leaves of `tree` whose boxes `ray` meets before the
/// visitor's limit, until the visitor says stop: nearest first if the
/// visitor asks for it ([`LeafVisitor::NEAREST_FIRST`]) or the tree's
/// lanes have no order, else the far side along z first.
#[inline(always)]
pub(crate) fn walk_wide<T: WideTree, V: LeafVisitor, L: BoxLanes>(
    tree: &T,
    ray: &PreparedRay,
    stack: &mut WideStack,
    visitor: &mut V,
    lanes: L,
) {
    let box_ray = tree.box_ray(ray);
    let (root_box, root) = tree.root();
    let (hit, entry) = lanes.hit(
        root_box,
        1,
        &box_ray,
        limit_f32(tree.limit(visitor.limit())),
    );
    if hit == 0 {
        return;
    }
    let entries = &mut *stack.entries;
    entries[0] = Waiting {
        node: root,
        entry: entry[0],
    };
    let mut top = 1usize;
    let upward = ray.negative & 0b100 == 0;
    while top > 0 {
        top -= 1;
        let waiting = entries[top & (CAPACITY - 1)];
        // The limit only falls: a box entered past it holds nothing that
        // could change the answer.
        let limit = limit_f32(tree.limit(visitor.limit()));
        if waiting.entry > limit {
            continue;
        }
        let mut node = waiting.node;
        loop {
            let (boxes, count, first) = match tree.open(node) {
                Opened::Leaf(refs) => {
                    if visitor.visit_leaf(refs, f64::NEG_INFINITY, lanes) {
                        return;
                    }
                    break;
                }
                Opened::Interior {
                    boxes,
                    count,
                    first,
                } => (boxes, count, first),
            };
            let (mut hits, entry) = lanes.hit(boxes, count, &box_ray, limit);
            if hits == 0 {
                break;
            }
            if hits & (hits - 1) == 0 {
                // One child: enter it without the stack.
                node = tree.child(node, first, hits.trailing_zeros());
                continue;
            }
            if T::BY_OCTANT && !V::NEAREST_FIRST {
                // Not sorted by entry: by stored order, the far side along
                // z first (monotone in z; within a z half not front to
                // back). The cells near a shadow ray's origin hold the
                // surface it leaves and its neighbours, which seldom block
                // it; a blocker found sooner ends the walk sooner
                // (docs/notes/experiments.md). One child is entered next,
                // the others wait.
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
                        node: tree.child(node, first, j),
                        entry: entry[j as usize],
                    };
                    top += 1;
                }
                node = tree.child(node, first, next);
                continue;
            }
            // Every child met, kept sorted farthest first above the waiting
            // ones, so the nearest is entered next.
            let base = top;
            while hits != 0 {
                let j = hits.trailing_zeros();
                hits &= hits - 1;
                let child = Waiting {
                    node: tree.child(node, first, j),
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
            node = entries[top & (CAPACITY - 1)].node;
        }
    }
}
