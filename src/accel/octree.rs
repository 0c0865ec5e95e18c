//! Octree over the bounded shapes of a scene.
//!
//! Build: each node is split at its centre into eight octants until it holds
//! at most `leaf_size` references or reaches `max_depth`; a shape is
//! referenced from every leaf it really overlaps (exact triangle/box and
//! sphere/box tests). Optionally a surface-area cost estimate (MacDonald &
//! Booth 1990) keeps a node as a leaf when splitting would not pay.
//!
//! Traversal: front to back in the parametric manner of Revelles, Ureña &
//! Lastra, "An Efficient Parametric Algorithm for Octree Traversal" (WSCG
//! 2000): from the parameters at which the ray crosses a node's three
//! mid-planes follows the sequence of children it passes through, without
//! any point-in-box test. Rays stop as soon as the best hit lies before the
//! exit of the current leaf.

use rayon::prelude::*;

use super::{ClosestHit, Occlusion, test_closest};
use crate::math::{Aabb, DVec3};
use crate::shapes::{PreparedRay, Shape};
use crate::stats::Counter;

/// Deepest octree level glint builds: 2^21 cells per axis is far below
/// any useful resolution and keeps build recursion shallow.
pub const MAX_OCTREE_DEPTH: u32 = 21;

#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct OctreeParams {
    /// Deepest level a node may have; the root is level 0.
    pub max_depth: u32,
    /// A node with at most this many references stays a leaf.
    pub leaf_size: u32,
    /// Stop splitting where the surface-area cost estimate says a split
    /// would cost more than it saves.
    pub cost_driven: bool,
}

impl Default for OctreeParams {
    fn default() -> Self {
        // Chosen by `glint bench --sweep` over the seven SPD scenes
        // (benches/octree_sweep_256.md): the lowest total render time, and
        // within 1.25x of each scene's best configuration.
        Self {
            max_depth: 10,
            leaf_size: 8,
            cost_driven: false,
        }
    }
}

/// Machine-independent description of a built octree, with Havran's names:
/// interior nodes N_IN = `nodes - leaves`, leaves N_V + N_EV = `leaves`,
/// empty leaves N_EV, references N_OIV.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct OctreeStats {
    pub nodes: u64,
    pub leaves: u64,
    pub empty_leaves: u64,
    pub references: u64,
    pub max_depth: u32,
    pub memory_bytes: u64,
}

/// A cell of the octree as the overlay draws it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OctreeCell {
    pub bounds: Aabb,
    /// Level of the cell; the root is 0.
    pub depth: u32,
    /// Primitive references in the cell (summed over its leaves when it
    /// stands for a subtree).
    pub references: u64,
}

/// Leaf: `refs[first .. first + count]`. Interior: eight children stored
/// consecutively from `first`, octant bit 0 = upper x, bit 1 = upper y,
/// bit 2 = upper z. 8 bytes, so a cache line holds a node's eight children.
#[derive(Clone, Copy, Debug)]
struct Node {
    first: u32,
    count: u32,
}

const INTERIOR: u32 = u32::MAX;

#[derive(Clone, Debug)]
pub struct Octree {
    bounds: Aabb,
    nodes: Vec<Node>,
    refs: Vec<u32>,
    /// Shapes without bounds (planes, unclipped quadrics), tested for every ray.
    unbounded: Vec<u32>,
    params: OctreeParams,
    stats: OctreeStats,
}

enum BuildNode {
    Leaf(Vec<u32>),
    Interior(Box<[BuildNode; 8]>),
}

/// Relative growth of boxes used to classify shapes, so that a shape
/// touching a cell in exact arithmetic is never missed through rounding.
const CLASSIFY_PAD: f64 = 1e-9;
/// Cost of one traversal step relative to one intersection test, for the
/// surface-area estimate.
const TRAVERSAL_COST: f64 = 1.0;
/// Below this many references a node's children are built on one thread.
const PARALLEL_MIN: usize = 2048;

/// The box of octant `child` of `[min, max]`, split at its centre. Build and
/// traversal both use this, so their cells are bit-identical.
#[inline(always)]
fn octant(min: DVec3, max: DVec3, mid: DVec3, child: usize) -> (DVec3, DVec3) {
    let pick = |k: usize, lo: f64, m: f64, hi: f64| {
        if child >> k & 1 == 1 {
            (m, hi)
        } else {
            (lo, m)
        }
    };
    let (x0, x1) = pick(0, min.x, mid.x, max.x);
    let (y0, y1) = pick(1, min.y, mid.y, max.y);
    let (z0, z1) = pick(2, min.z, mid.z, max.z);
    (DVec3::new(x0, y0, z0), DVec3::new(x1, y1, z1))
}

#[inline(always)]
fn centre(min: DVec3, max: DVec3) -> DVec3 {
    0.5 * (min + max)
}

impl Octree {
    pub fn build(shapes: &[Shape], params: OctreeParams) -> Self {
        let mut bounds = Aabb::EMPTY;
        let mut bounded = Vec::new();
        let mut unbounded = Vec::new();
        for (i, s) in shapes.iter().enumerate() {
            match s.bounds() {
                Some(b) => {
                    bounds = bounds.union(b);
                    bounded.push(i as u32);
                }
                None => unbounded.push(i as u32),
            }
        }
        let mut tree = Self {
            bounds: Aabb::EMPTY,
            nodes: Vec::new(),
            refs: Vec::new(),
            unbounded,
            params,
            stats: OctreeStats::default(),
        };
        if bounded.is_empty() {
            return tree;
        }
        // A cube around the shapes: cells stay cubes at every level, so a
        // ray crosses as few of them as possible (flat cells of a flat scene
        // would be crossed by the dozen). Padded so shapes on its faces lie inside.
        let half = DVec3::splat(0.5 * bounds.extent().max_element());
        let c = bounds.center();
        tree.bounds = Aabb::new(c - half, c + half).padded(CLASSIFY_PAD);
        let root = build_node(
            shapes,
            bounded,
            tree.bounds.min,
            tree.bounds.max,
            0,
            &params,
        );
        tree.nodes.push(Node { first: 0, count: 0 });
        let mut max_depth = 0;
        flatten(root, 0, 0, &mut tree.nodes, &mut tree.refs, &mut max_depth);
        let leaves = tree.nodes.iter().filter(|n| n.count != INTERIOR).count() as u64;
        let empty = tree.nodes.iter().filter(|n| n.count == 0).count() as u64;
        tree.stats = OctreeStats {
            nodes: tree.nodes.len() as u64,
            leaves,
            empty_leaves: empty,
            references: tree.refs.len() as u64,
            max_depth,
            memory_bytes: (tree.nodes.len() * std::mem::size_of::<Node>()
                + (tree.refs.len() + tree.unbounded.len()) * 4) as u64,
        };
        tree
    }

    pub fn stats(&self) -> OctreeStats {
        self.stats
    }

    pub fn params(&self) -> OctreeParams {
        self.params
    }

    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// The cells to draw for an overlay down to level `depth`: every
    /// non-empty leaf above that level, and every non-empty node at it
    /// (standing for its subtree), with the references beneath it.
    pub fn cells(&self, depth: u32) -> Vec<OctreeCell> {
        let mut out = Vec::new();
        if !self.nodes.is_empty() && !self.bounds.is_empty() {
            self.collect_cells(0, self.bounds.min, self.bounds.max, 0, depth, &mut out);
        }
        out
    }

    /// Returns the references under node `index`.
    fn collect_cells(
        &self,
        index: usize,
        min: DVec3,
        max: DVec3,
        level: u32,
        depth: u32,
        out: &mut Vec<OctreeCell>,
    ) -> u64 {
        let node = self.nodes[index];
        if node.count != INTERIOR {
            if node.count > 0 {
                out.push(OctreeCell {
                    bounds: Aabb::new(min, max),
                    depth: level,
                    references: node.count as u64,
                });
            }
            return node.count as u64;
        }
        let mid = centre(min, max);
        let at_limit = level >= depth;
        let mut below = Vec::new();
        let target = if at_limit { &mut below } else { &mut *out };
        let mut total = 0;
        for child in 0..8 {
            let (lo, hi) = octant(min, max, mid, child);
            total += self.collect_cells(
                node.first as usize + child,
                lo,
                hi,
                level + 1,
                depth,
                target,
            );
        }
        if at_limit && total > 0 {
            out.push(OctreeCell {
                bounds: Aabb::new(min, max),
                depth: level,
                references: total,
            });
        }
        total
    }

    /// Closest hit with `0 < t < t_max`.
    pub fn closest<C: Counter>(
        &self,
        shapes: &[Shape],
        ray: &PreparedRay,
        t_max: f64,
        counter: &mut C,
    ) -> Option<ClosestHit> {
        let mut visitor = ClosestVisitor {
            shapes,
            ray,
            best: None,
            t_max,
            mailbox: Mailbox::new(),
            counter,
        };
        for &i in &self.unbounded {
            test_closest(shapes, i, ray, &mut visitor.best, t_max, visitor.counter);
        }
        let limit = visitor.best.map_or(t_max, |b| b.hit.t);
        self.traverse(ray, limit, &mut visitor);
        visitor.best
    }

    /// Shapes in the way of a shadow ray over `(0, t_max)`.
    pub fn occlusion<C: Counter>(
        &self,
        shapes: &[Shape],
        is_transparent: &[bool],
        ray: &PreparedRay,
        t_max: f64,
        counter: &mut C,
    ) -> Occlusion {
        let mut visitor = OcclusionVisitor {
            shapes,
            is_transparent,
            ray,
            t_max,
            occlusion: Occlusion::Clear,
            mailbox: Mailbox::new(),
            counter,
        };
        for &i in &self.unbounded {
            visitor.counter.intersection_test();
            if shapes[i as usize].intersect(ray, t_max).is_some()
                && visitor.occlusion.record(i, is_transparent[i as usize])
            {
                return Occlusion::Blocked;
            }
        }
        self.traverse(ray, t_max, &mut visitor);
        visitor.occlusion
    }

    fn traverse<V: LeafVisitor>(&self, ray: &PreparedRay, t_max: f64, visitor: &mut V) {
        if self.nodes.is_empty() {
            return;
        }
        let walk = WalkRay::new(ray);
        let Some((t0, t1)) = self.bounds.ray_range(&walk.ray, 0.0, t_max) else {
            return;
        };
        self.visit(0, self.bounds.min, self.bounds.max, t0, t1, &walk, visitor);
    }

    /// Visits child `index` of a node; empty leaves are counted and skipped
    /// without a call (a large share of the leaves a ray enters are empty).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn visit_child<V: LeafVisitor>(
        &self,
        index: u32,
        min: DVec3,
        max: DVec3,
        t0: f64,
        t1: f64,
        ray: &WalkRay,
        visitor: &mut V,
    ) -> bool {
        if self.nodes[index as usize].count == 0 {
            visitor.counter().traversal_step();
            visitor.counter().leaf_visit();
            return false;
        }
        self.visit(index, min, max, t0, t1, ray, visitor)
    }

    /// Visits node `index` over the ray segment `[t0, t1]`; `true` once
    /// nothing further along the ray can matter.
    #[allow(clippy::too_many_arguments)]
    fn visit<V: LeafVisitor>(
        &self,
        index: u32,
        min: DVec3,
        max: DVec3,
        t0: f64,
        t1: f64,
        ray: &WalkRay,
        visitor: &mut V,
    ) -> bool {
        visitor.counter().traversal_step();
        let node = self.nodes[index as usize];
        if node.count != INTERIOR {
            visitor.counter().leaf_visit();
            let refs = &self.refs[node.first as usize..(node.first + node.count) as usize];
            return visitor.visit_leaf(refs, t1);
        }
        let mid = centre(min, max);
        // Parameters of the three mid-planes and the octant entered at t0.
        let mut t_mid = [f64::INFINITY; 3];
        let mut child = 0usize;
        for k in 0..3 {
            let d = ray.ray.dir[k];
            if d == 0.0 {
                // Parallel to the plane (or in it): the side never changes;
                // a ray lying in the plane goes to the upper octants.
                if ray.ray.origin[k] >= mid[k] {
                    child |= 1 << k;
                }
            } else {
                let t = (mid[k] - ray.ray.origin[k]) * ray.inv_dir[k];
                t_mid[k] = t;
                // Upper side at t0: already crossed going up, or not yet crossed going down.
                if (t <= t0) == (d > 0.0) {
                    child |= 1 << k;
                }
            }
        }
        // Crossings in increasing t (a three-element sorting network).
        let mut order = [0usize, 1, 2];
        if t_mid[order[0]] > t_mid[order[1]] {
            order.swap(0, 1);
        }
        if t_mid[order[1]] > t_mid[order[2]] {
            order.swap(1, 2);
        }
        if t_mid[order[0]] > t_mid[order[1]] {
            order.swap(0, 1);
        }
        let mut t_start = t0;
        for k in order {
            let t = t_mid[k];
            if !(t > t0 && t < t1) {
                continue;
            }
            if t_start > visitor.t_limit() {
                return true;
            }
            let (cmin, cmax) = octant(min, max, mid, child);
            if self.visit_child(
                node.first + child as u32,
                cmin,
                cmax,
                t_start,
                t,
                ray,
                visitor,
            ) {
                return true;
            }
            child ^= 1 << k;
            t_start = t;
        }
        if t_start > visitor.t_limit() {
            return true;
        }
        let (cmin, cmax) = octant(min, max, mid, child);
        self.visit_child(
            node.first + child as u32,
            cmin,
            cmax,
            t_start,
            t1,
            ray,
            visitor,
        )
    }
}

/// The ray as the traversal sees it: direction components too small to
/// invert are treated as exactly zero (parallel to the planes), which moves
/// the ray by less than the cells' padding over any finite distance.
struct WalkRay {
    ray: crate::math::Ray,
    inv_dir: DVec3,
}

impl WalkRay {
    fn new(r: &PreparedRay) -> Self {
        let mut ray = r.ray;
        let mut inv_dir = DVec3::ZERO;
        for k in 0..3 {
            let inv = 1.0 / ray.dir[k];
            if inv.is_finite() {
                inv_dir[k] = inv;
            } else {
                ray.dir[k] = 0.0;
            }
        }
        Self { ray, inv_dir }
    }
}

/// Remembers the last shapes tested for this ray, so a shape referenced
/// from several leaves is usually tested once (direct-mapped, 16 entries).
struct Mailbox([u32; 16]);

impl Mailbox {
    fn new() -> Self {
        Self([u32::MAX; 16])
    }

    /// `true` if `index` was tested already; records it otherwise.
    #[inline(always)]
    fn seen(&mut self, index: u32) -> bool {
        let slot = &mut self.0[(index & 15) as usize];
        if *slot == index {
            return true;
        }
        *slot = index;
        false
    }
}

trait LeafVisitor {
    type C: Counter;
    fn counter(&mut self) -> &mut Self::C;
    /// Tests the shapes of a leaf the ray leaves at `t_exit`; `true` to stop.
    fn visit_leaf(&mut self, refs: &[u32], t_exit: f64) -> bool;
    /// Cells starting beyond this parameter cannot change the answer.
    fn t_limit(&self) -> f64;
}

struct ClosestVisitor<'a, C> {
    shapes: &'a [Shape],
    ray: &'a PreparedRay,
    best: Option<ClosestHit>,
    t_max: f64,
    mailbox: Mailbox,
    counter: &'a mut C,
}

impl<C: Counter> LeafVisitor for ClosestVisitor<'_, C> {
    type C = C;
    fn counter(&mut self) -> &mut C {
        self.counter
    }

    #[inline(always)]
    fn visit_leaf(&mut self, refs: &[u32], t_exit: f64) -> bool {
        for &i in refs {
            if !self.mailbox.seen(i) {
                test_closest(
                    self.shapes,
                    i,
                    self.ray,
                    &mut self.best,
                    self.t_max,
                    self.counter,
                );
            }
        }
        // A hit exactly on the exit face may tie with one in the next cell:
        // only a hit strictly inside this cell ends the walk.
        self.best.is_some_and(|b| b.hit.t < t_exit)
    }

    fn t_limit(&self) -> f64 {
        self.best.map_or(self.t_max, |b| b.hit.t)
    }
}

struct OcclusionVisitor<'a, C> {
    shapes: &'a [Shape],
    is_transparent: &'a [bool],
    ray: &'a PreparedRay,
    t_max: f64,
    occlusion: Occlusion,
    mailbox: Mailbox,
    counter: &'a mut C,
}

impl<C: Counter> LeafVisitor for OcclusionVisitor<'_, C> {
    type C = C;
    fn counter(&mut self) -> &mut C {
        self.counter
    }

    #[inline(always)]
    fn visit_leaf(&mut self, refs: &[u32], _t_exit: f64) -> bool {
        for &i in refs {
            if self.mailbox.seen(i) {
                continue;
            }
            self.counter.intersection_test();
            if self.shapes[i as usize]
                .intersect(self.ray, self.t_max)
                .is_some()
                && self.occlusion.record(i, self.is_transparent[i as usize])
            {
                return true;
            }
        }
        false
    }

    fn t_limit(&self) -> f64 {
        self.t_max
    }
}

fn build_node(
    shapes: &[Shape],
    items: Vec<u32>,
    min: DVec3,
    max: DVec3,
    depth: u32,
    params: &OctreeParams,
) -> BuildNode {
    if depth >= params.max_depth || items.len() <= params.leaf_size as usize {
        return BuildNode::Leaf(items);
    }
    let mid = centre(min, max);
    let classify = |child: usize| -> Vec<u32> {
        let (cmin, cmax) = octant(min, max, mid, child);
        let cell = Aabb::new(cmin, cmax).padded(CLASSIFY_PAD);
        items
            .iter()
            .copied()
            .filter(|&i| shapes[i as usize].overlaps_box(&cell))
            .collect()
    };
    let parts: Vec<Vec<u32>> = if items.len() >= PARALLEL_MIN {
        (0..8).into_par_iter().map(classify).collect()
    } else {
        (0..8).map(classify).collect()
    };
    if params.cost_driven {
        // Expected cost of a ray through this node, in intersection tests,
        // as a leaf and split (children weighted by their relative area).
        let area = Aabb::new(min, max).surface_area();
        if area > 0.0 {
            let leaf_cost = items.len() as f64;
            let split_cost = TRAVERSAL_COST
                + (0..8)
                    .map(|c| {
                        let (cmin, cmax) = octant(min, max, mid, c);
                        Aabb::new(cmin, cmax).surface_area() / area * parts[c].len() as f64
                    })
                    .sum::<f64>();
            if split_cost >= leaf_cost {
                return BuildNode::Leaf(items);
            }
        }
    }
    drop(items);
    let build_child = |(c, part): (usize, Vec<u32>)| {
        let (cmin, cmax) = octant(min, max, mid, c);
        build_node(shapes, part, cmin, cmax, depth + 1, params)
    };
    let total: usize = parts.iter().map(Vec::len).sum();
    let children: Vec<BuildNode> = if total >= PARALLEL_MIN {
        parts
            .into_iter()
            .enumerate()
            .collect::<Vec<_>>()
            .into_par_iter()
            .map(build_child)
            .collect()
    } else {
        parts.into_iter().enumerate().map(build_child).collect()
    };
    let children: Box<[BuildNode; 8]> = match children.into_boxed_slice().try_into() {
        Ok(c) => c,
        Err(_) => unreachable!("always eight octants"),
    };
    BuildNode::Interior(children)
}

fn flatten(
    node: BuildNode,
    slot: usize,
    depth: u32,
    nodes: &mut Vec<Node>,
    refs: &mut Vec<u32>,
    max_depth: &mut u32,
) {
    *max_depth = (*max_depth).max(depth);
    match node {
        BuildNode::Leaf(items) => {
            nodes[slot] = Node {
                first: refs.len() as u32,
                count: items.len() as u32,
            };
            refs.extend(items);
        }
        BuildNode::Interior(children) => {
            let first = nodes.len();
            nodes.resize(first + 8, Node { first: 0, count: 0 });
            nodes[slot] = Node {
                first: first as u32,
                count: INTERIOR,
            };
            for (c, child) in (*children).into_iter().enumerate() {
                flatten(child, first + c, depth + 1, nodes, refs, max_depth);
            }
        }
    }
}
