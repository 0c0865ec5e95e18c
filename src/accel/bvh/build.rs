//! Binned surface-area-heuristic build (Wald 2007).

use super::node::BvhNode;
use super::tree::{Bvh, BvhStats};
use super::wide::WideNodes;
use crate::math::{Aabb, DVec3};
use crate::shapes::Shape;

/// Centroid bins per split: Wald found 16-32 as good as a full sweep.
const BINS: usize = 32;
/// Cost of visiting a node relative to one intersection test.
const TRAVERSAL_COST: f64 = 0.5;
/// A node with more shapes than this is split even when the heuristic
/// would keep it (unless their centroids coincide).
const MAX_LEAF: usize = 8;
/// Nodes with more shapes than this build their two halves in parallel.
const PARALLEL_MIN: usize = 4096;
/// Below this depth splits are the heuristic's; deeper, at the median
/// centroid, so that a scene the heuristic peels one shape at a time
/// (centroids spaced geometrically) still gets a tree of logarithmic depth.
const MEDIAN_BELOW: u32 = 48;
/// Relative growth of each shape's box, far above the rounding of the
/// slab test and far below any feature of a scene.
const PAD: f64 = 64.0 * f64::EPSILON;

/// A shape as the build sorts it.
#[derive(Clone, Copy)]
struct Item {
    shape: u32,
    bounds: Aabb,
    centroid: DVec3,
}

/// The tree before it is flattened.
enum Built {
    Leaf {
        bounds: Aabb,
        start: usize,
        count: usize,
    },
    Interior {
        bounds: Aabb,
        children: Box<(Built, Built)>,
    },
}

impl Built {
    fn bounds(&self) -> Aabb {
        match self {
            Built::Leaf { bounds, .. } | Built::Interior { bounds, .. } => *bounds,
        }
    }
}

impl Bvh {
    /// Builds the hierarchy over the bounded shapes (unbounded ones are
    /// kept aside and tested for every ray). Runs on the current rayon pool.
    pub fn build(shapes: &[Shape]) -> Self {
        let mut items = Vec::new();
        let mut unbounded = Vec::new();
        for (i, s) in shapes.iter().enumerate() {
            match s.bounds() {
                Some(b) => {
                    let bounds = b.padded(PAD);
                    items.push(Item {
                        shape: i as u32,
                        bounds,
                        centroid: bounds.center(),
                    });
                }
                None => unbounded.push(i as u32),
            }
        }
        let mut bvh = Bvh {
            unbounded,
            planes: crate::accel::planes::PlaneGroups::build(shapes),
            ..Bvh::default()
        };
        if !items.is_empty() {
            let root = split(&mut items, 0, 0);
            bvh.refs = items.iter().map(|it| it.shape).collect();
            bvh.nodes.reserve(2 * items.len());
            flatten(&root, 0, &mut bvh.nodes, &mut bvh.stats);
            bvh.wide = WideNodes::build(&bvh.nodes);
        }
        bvh.stats.nodes = bvh.nodes.len() as u64;
        bvh.stats.references = bvh.refs.len() as u64;
        bvh.stats.memory_bytes = (bvh.nodes.len() * std::mem::size_of::<BvhNode>()
            + (bvh.refs.len() + bvh.unbounded.len()) * std::mem::size_of::<u32>())
            as u64
            + bvh.wide.memory_bytes();
        bvh
    }
}

/// Builds the subtree over `items` (which it reorders), whose first item
/// is reference `offset` of the whole tree.
fn split(items: &mut [Item], offset: usize, depth: u32) -> Built {
    let bounds = items.iter().fold(Aabb::EMPTY, |b, it| b.union(it.bounds));
    let leaf = Built::Leaf {
        bounds,
        start: offset,
        count: items.len(),
    };
    if items.len() <= 2 {
        return leaf;
    }
    let centroids = items.iter().fold(Aabb::EMPTY, |b, it| b.grow(it.centroid));
    let extent = centroids.extent();
    let axis = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    let (lo, width) = (centroids.min[axis], extent[axis]);
    if !(width > 0.0) {
        // Every centroid at one place (nested spheres, coincident
        // triangles): no plane separates them, but their sizes may. The
        // larger half and the smaller half: a ray that misses the smaller
        // half's box, or meets the larger shapes first, skips it.
        if items.len() <= MAX_LEAF {
            return leaf;
        }
        let middle = items.len() / 2;
        items.select_nth_unstable_by(middle, |a, b| {
            b.bounds
                .surface_area()
                .total_cmp(&a.bounds.surface_area())
                .then(a.shape.cmp(&b.shape))
        });
        return join(items, middle, offset, depth);
    }
    if depth >= MEDIAN_BELOW {
        let middle = items.len() / 2;
        items.select_nth_unstable_by(middle, |a, b| {
            a.centroid[axis]
                .total_cmp(&b.centroid[axis])
                .then(a.shape.cmp(&b.shape))
        });
        return join(items, middle, offset, depth);
    }
    let scale = BINS as f64 / width;
    let bin_of = |it: &Item| (((it.centroid[axis] - lo) * scale) as usize).min(BINS - 1);
    let mut bin_bounds = [Aabb::EMPTY; BINS];
    let mut bin_count = [0usize; BINS];
    for it in items.iter() {
        let b = bin_of(it);
        bin_bounds[b] = bin_bounds[b].union(it.bounds);
        bin_count[b] += 1;
    }
    // Area times count of the bins left of each plane, then right of it.
    let mut left_cost = [0.0; BINS];
    let (mut area_box, mut n) = (Aabb::EMPTY, 0);
    for b in 0..BINS - 1 {
        area_box = area_box.union(bin_bounds[b]);
        n += bin_count[b];
        left_cost[b] = if n > 0 {
            area_box.surface_area() * n as f64
        } else {
            0.0
        };
    }
    let (mut best_plane, mut best_cost) = (0, f64::INFINITY);
    let (mut area_box, mut n) = (Aabb::EMPTY, 0);
    for b in (1..BINS).rev() {
        area_box = area_box.union(bin_bounds[b]);
        n += bin_count[b];
        let right = if n > 0 {
            area_box.surface_area() * n as f64
        } else {
            0.0
        };
        // The plane between bins b - 1 and b; the first plane wins ties.
        let cost = left_cost[b - 1] + right;
        if cost <= best_cost {
            (best_plane, best_cost) = (b, cost);
        }
    }
    let area = bounds.surface_area();
    let split_cost = TRAVERSAL_COST + if area > 0.0 { best_cost / area } else { 0.0 };
    if items.len() <= MAX_LEAF && split_cost >= items.len() as f64 {
        return leaf;
    }
    // Bins 0 and BINS - 1 both hold a centroid, so both sides are non-empty.
    let mut middle = 0;
    for i in 0..items.len() {
        if bin_of(&items[i]) < best_plane {
            items.swap(i, middle);
            middle += 1;
        }
    }
    join(items, middle, offset, depth)
}

/// The interior node over `items` split before `middle`.
fn join(items: &mut [Item], middle: usize, offset: usize, depth: u32) -> Built {
    let (left, right) = items.split_at_mut(middle);
    let (a, b) = if left.len() + right.len() >= PARALLEL_MIN {
        rayon::join(
            || split(left, offset, depth + 1),
            || split(right, offset + middle, depth + 1),
        )
    } else {
        (
            split(left, offset, depth + 1),
            split(right, offset + middle, depth + 1),
        )
    };
    Built::Interior {
        bounds: a.bounds().union(b.bounds()),
        children: Box::new((a, b)),
    }
}

/// Appends `node`'s subtree to `nodes` in depth-first order.
fn flatten(node: &Built, depth: u32, nodes: &mut Vec<BvhNode>, stats: &mut BvhStats) {
    stats.max_depth = stats.max_depth.max(depth);
    match node {
        Built::Leaf {
            bounds,
            start,
            count,
        } => {
            stats.leaves += 1;
            nodes.push(BvhNode {
                bounds: *bounds,
                first_or_second: *start as u32,
                count: *count as u32,
            });
        }
        Built::Interior { bounds, children } => {
            let at = nodes.len();
            nodes.push(BvhNode {
                bounds: *bounds,
                first_or_second: 0,
                count: 0,
            });
            flatten(&children.0, depth + 1, nodes, stats);
            nodes[at].first_or_second = nodes.len() as u32;
            flatten(&children.1, depth + 1, nodes, stats);
        }
    }
}
