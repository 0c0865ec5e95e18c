//! Octree over the bounded shapes of a scene.
//!
//! Build: breadth first, level by level, each node is split at its centre
//! into eight octants; a shape is referenced from every cell its surface
//! really touches (exact triangle/box and sphere/box tests). A node stays a
//! leaf when it holds at most `leaf_size` references, reaches `max_depth`,
//! or when a split would not separate its references: every non-empty
//! child would hold all of them, or the children together would hold more
//! than `max_duplication` times as many (the termination criterion Havran
//! discusses for hierarchical subdivisions: splitting large overlapping
//! objects only multiplies references). Optionally a surface-area cost
//! estimate (MacDonald & Booth 1990) keeps a node as a leaf when splitting
//! would not pay. A memory budget bounds the whole structure: once a split
//! would exceed it, nodes stay leaves, which is always correct, only slower.
//! Because the build goes level by level and decides in a fixed order, the
//! budget is spent on the coarse levels first and the tree is the same for
//! any number of threads.
//!
//! Traversal: front to back in the parametric manner of Revelles, Ureña &
//! Lastra, "An Efficient Parametric Algorithm for Octree Traversal" (WSCG
//! 2000): from the parameters at which the ray crosses a node's three
//! mid-planes follows the sequence of children it passes through, without
//! any point-in-box test. It runs iteratively on a small stack kept per
//! thread (no allocation, no recursion); a node stores a mask of its
//! non-empty children, which alone are stored and visited. Rays stop as
//! soon as the best hit lies before the exit of the current leaf.

use rayon::prelude::*;

use super::primitives::{ClosestHit, Primitives, ShadowCrossings, test_closest, test_occlusion};
use crate::math::{Aabb, DVec3};
use crate::shapes::{PreparedRay, Shape};
use crate::stats::Counter;

use crate::limits::{LimitError, MAX_DUPLICATION_RANGE, MAX_MEMORY_BUDGET_MIB, MAX_OCTREE_DEPTH};

#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct OctreeParams {
    /// Deepest level a node may have; the root is level 0.
    pub max_depth: u32,
    /// A node with at most this many references stays a leaf.
    pub leaf_size: u32,
    /// Stop splitting where the surface-area cost estimate says a split
    /// would cost more than it saves.
    pub cost_driven: bool,
    /// A node stays a leaf when its children would hold more than this many
    /// times its references (8 never stops: eight children hold at most 8x).
    #[serde(default = "default_max_duplication")]
    pub max_duplication: u32,
    /// Budget for the built structure (nodes and references), in MiB: past
    /// it, nodes stay leaves.
    #[serde(default = "default_memory_budget_mib")]
    pub memory_budget_mib: u32,
}

/// Chosen by `glint bench --sweep` (benches/octree_sweep_256.md).
pub const DEFAULT_MAX_DUPLICATION: u32 = 8;
/// Far above what any real scene needs (the 65,536-triangle tetra_s8 takes
/// 15 MiB), far below this machine's memory, and small enough that the
/// build finishes in seconds even when a scene would use it all.
pub const DEFAULT_MEMORY_BUDGET_MIB: u32 = 128;

fn default_max_duplication() -> u32 {
    DEFAULT_MAX_DUPLICATION
}

fn default_memory_budget_mib() -> u32 {
    DEFAULT_MEMORY_BUDGET_MIB
}

impl Default for OctreeParams {
    fn default() -> Self {
        // Chosen by `glint bench --sweep` over the seven SPD scenes
        // (benches/octree_sweep_256.md): leaf size 4 renders within 3% of
        // the fastest configuration (run-to-run noise) with half its
        // intersection tests, at most 0.33x Havran's best octree on every
        // scene; depth 12 and leaf size 2 were slower.
        Self {
            max_depth: 10,
            leaf_size: 4,
            cost_driven: false,
            max_duplication: DEFAULT_MAX_DUPLICATION,
            memory_budget_mib: DEFAULT_MEMORY_BUDGET_MIB,
        }
    }
}

impl OctreeParams {
    /// Every parameter within [`crate::limits`].
    pub fn check(&self) -> Result<(), LimitError> {
        if self.max_depth > MAX_OCTREE_DEPTH {
            return Err(LimitError::OctreeDepth(self.max_depth));
        }
        if self.leaf_size == 0 {
            return Err(LimitError::LeafSize);
        }
        if !MAX_DUPLICATION_RANGE.contains(&self.max_duplication) {
            return Err(LimitError::MaxDuplication(self.max_duplication));
        }
        if !(1..=MAX_MEMORY_BUDGET_MIB).contains(&self.memory_budget_mib) {
            return Err(LimitError::MemoryBudget(self.memory_budget_mib));
        }
        Ok(())
    }

    fn memory_budget_bytes(&self) -> u64 {
        self.memory_budget_mib as u64 * 1024 * 1024
    }
}

#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum OctreeError {
    /// The allocator refused memory the build needed (for example under a
    /// memory limit below the budget).
    #[error(
        "not enough memory to build the octree ({bytes} more bytes were refused); \
         lower the octree memory budget or switch the octree off"
    )]
    OutOfMemory { bytes: u64 },
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
    /// The budget the build had (`memory_budget_mib` in bytes).
    pub memory_budget_bytes: u64,
    /// Nodes left as leaves because splitting them would have exceeded
    /// the budget (0 when the budget never bound).
    pub leaves_stopped_by_budget: u64,
    /// Nodes left as leaves because a split would not have separated their
    /// references (`max_duplication`, or every child holding all of them).
    pub leaves_stopped_by_duplication: u64,
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

/// Leaf: `refs[first .. first + count]`. Interior: a mask of the octants
/// holding anything (octant bit 0 = upper x, bit 1 = upper y, bit 2 =
/// upper z), whose nodes alone are stored, consecutively from `first` in
/// octant order: empty octants cost neither memory nor a load. 8 bytes.
#[derive(Clone, Copy, Debug)]
struct Node {
    first: u32,
    /// Leaf: the reference count. Interior: [`INTERIOR`] | the octant mask.
    meta: u32,
}

const INTERIOR: u32 = 1 << 31;

impl Node {
    const EMPTY: Node = Node { first: 0, meta: 0 };

    #[inline(always)]
    fn is_leaf(self) -> bool {
        self.meta & INTERIOR == 0
    }

    #[inline(always)]
    fn count(self) -> u32 {
        self.meta
    }

    #[inline(always)]
    fn mask(self) -> u32 {
        self.meta & 0xff
    }

    /// Index of the node of octant `c`, which must be in the mask.
    #[inline(always)]
    fn child(self, c: usize) -> u32 {
        self.first + (self.mask() & ((1 << c) - 1)).count_ones()
    }
}

/// A cubic cell: its lowest corner and side. Children are formed by the
/// same arithmetic in the build and the traversal, so their cells agree to
/// the bit.
#[derive(Clone, Copy, Debug, Default)]
struct Cell {
    min: DVec3,
    side: f64,
}

impl Cell {
    #[inline(always)]
    fn half(&self) -> f64 {
        0.5 * self.side
    }

    #[inline(always)]
    fn mid(&self) -> DVec3 {
        self.min + DVec3::splat(self.half())
    }

    #[inline(always)]
    fn child(&self, c: usize) -> Cell {
        let h = self.half();
        let pick = |k: usize| if c >> k & 1 == 1 { h } else { 0.0 };
        Cell {
            min: self.min + DVec3::new(pick(0), pick(1), pick(2)),
            side: h,
        }
    }

    fn aabb(&self) -> Aabb {
        Aabb::new(self.min, self.min + DVec3::splat(self.side))
    }
}

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

/// Relative growth of boxes used to classify shapes, so that a shape
/// touching a cell in exact arithmetic is never missed through rounding.
const CLASSIFY_PAD: f64 = 1e-9;
/// Cost of one traversal step relative to one intersection test, for the
/// surface-area estimate.
const TRAVERSAL_COST: f64 = 1.0;
/// Below this many references a node is classified on one thread.
const PARALLEL_MIN: usize = 2048;
/// Nodes of a level are classified in batches of about this many
/// references, so a level's candidate children never all exist at once.
const BATCH_REFERENCES: usize = 1 << 20;

impl Octree {
    /// Builds the octree over the bounded shapes (unbounded ones are kept
    /// aside and tested for every ray). Fails only if the allocator refuses
    /// memory; the budget in `params` normally keeps the build far from that.
    pub fn build(shapes: &[Shape], params: OctreeParams) -> Result<Self, OctreeError> {
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
            stats: OctreeStats {
                memory_budget_bytes: params.memory_budget_bytes(),
                ..OctreeStats::default()
            },
        };
        if bounded.is_empty() {
            return Ok(tree);
        }
        // A cube around the shapes: cells stay cubes at every level, so a
        // ray crosses as few of them as possible (flat cells of a flat scene
        // would be crossed by the dozen). Padded so shapes on its faces lie inside.
        let half = DVec3::splat(0.5 * bounds.extent().max_element());
        let c = bounds.center();
        let padded = Aabb::new(c - half, c + half).padded(CLASSIFY_PAD);
        let root = Cell {
            min: padded.min,
            side: padded.extent().max_element(),
        };
        tree.bounds = root.aabb();
        let mut builder = Builder {
            shapes,
            params,
            budget: params.memory_budget_bytes(),
            used: NODE_BYTES + PENDING_BYTES + REF_BYTES * bounded.len() as u64,
            nodes: Blocks::new(),
            refs: Blocks::new(),
            stats: tree.stats,
        };
        builder.nodes.extend(&[Node::EMPTY])?;
        let root = Pending {
            slot: 0,
            cell: root,
            items: bounded,
            non_separating: 0,
        };
        builder.build(root)?;
        let Builder {
            nodes, refs, stats, ..
        } = builder;
        tree.nodes = nodes.into_vec()?;
        tree.refs = refs.into_vec()?;
        // Havran's counts include the empty octants, which are not stored
        // (only a root without shapes is a stored empty leaf).
        let stored_leaves = tree.nodes.iter().filter(|n| n.is_leaf()).count() as u64;
        let unstored: u64 = tree
            .nodes
            .iter()
            .filter(|n| !n.is_leaf())
            .map(|n| 8 - n.mask().count_ones() as u64)
            .sum();
        let stored_empty = tree
            .nodes
            .iter()
            .filter(|n| n.is_leaf() && n.count() == 0)
            .count() as u64;
        tree.stats = OctreeStats {
            nodes: tree.nodes.len() as u64 + unstored,
            leaves: stored_leaves + unstored,
            empty_leaves: stored_empty + unstored,
            references: tree.refs.len() as u64,
            memory_bytes: (tree.nodes.len() * std::mem::size_of::<Node>()
                + (tree.refs.len() + tree.unbounded.len()) * 4) as u64,
            ..stats
        };
        Ok(tree)
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
            self.collect_cells(0, self.root_cell(), 0, depth, &mut out);
        }
        out
    }

    fn root_cell(&self) -> Cell {
        Cell {
            min: self.bounds.min,
            side: self.bounds.max.x - self.bounds.min.x,
        }
    }

    /// Returns the references under node `index`.
    fn collect_cells(
        &self,
        index: usize,
        cell: Cell,
        level: u32,
        depth: u32,
        out: &mut Vec<OctreeCell>,
    ) -> u64 {
        let node = self.nodes[index];
        if node.is_leaf() {
            if node.count() > 0 {
                out.push(OctreeCell {
                    bounds: cell.aabb(),
                    depth: level,
                    references: node.count() as u64,
                });
            }
            return node.count() as u64;
        }
        let at_limit = level >= depth;
        let mut below = Vec::new();
        let target = if at_limit { &mut below } else { &mut *out };
        let mut total = 0;
        for c in 0..8 {
            if node.mask() >> c & 1 == 1 {
                let child = node.child(c) as usize;
                total += self.collect_cells(child, cell.child(c), level + 1, depth, target);
            }
        }
        if at_limit && total > 0 {
            out.push(OctreeCell {
                bounds: cell.aabb(),
                depth: level,
                references: total,
            });
        }
        total
    }

    /// Closest hit with `0 < t < t_max`.
    pub fn closest<C: Counter>(
        &self,
        prims: &Primitives,
        ray: &PreparedRay,
        t_max: f64,
        counter: &mut C,
    ) -> Option<ClosestHit> {
        let mut visitor = ClosestVisitor {
            prims,
            ray,
            best: None,
            t_max,
            mailbox: Mailbox::new(),
            counter,
        };
        for &i in &self.unbounded {
            test_closest(prims, i, ray, &mut visitor.best, t_max, visitor.counter);
        }
        let limit = visitor.best.map_or(t_max, |b| b.hit.t);
        self.traverse(ray, limit, &mut visitor);
        visitor.best
    }

    /// What a shadow ray meets over `(0, t_max)`, into `found` (cleared
    /// first; the caller keeps it, so no ray initialises the array).
    pub fn occlusion<C: Counter>(
        &self,
        prims: &Primitives,
        ray: &PreparedRay,
        t_max: f64,
        found: &mut ShadowCrossings,
        counter: &mut C,
    ) {
        found.clear();
        for &i in &self.unbounded {
            if test_occlusion(prims, i, ray, t_max, found, counter) {
                return;
            }
        }
        let mut visitor = OcclusionVisitor {
            prims,
            ray,
            t_max,
            found,
            mailbox: Mailbox::new(),
            counter,
        };
        self.traverse(ray, t_max, &mut visitor);
    }

    fn traverse<V: LeafVisitor>(&self, ray: &PreparedRay, t_max: f64, visitor: &mut V) {
        if self.nodes.is_empty() {
            return;
        }
        let walk = WalkRay::new(ray);
        let Some((t0, t1)) = self.bounds.ray_range(&walk.ray, 0.0, t_max) else {
            return;
        };
        STACK.with_borrow_mut(|stack| {
            stack.entries[0] = Entry {
                node: 0,
                cell: self.root_cell(),
                t0,
                t1,
            };
            self.walk(&walk, stack, visitor);
        });
    }

    /// The traversal proper: pops cells front to back until the visitor
    /// stops or nothing further along the ray can matter.
    #[inline(always)]
    fn walk<V: LeafVisitor>(&self, ray: &WalkRay, stack: &mut Stack, visitor: &mut V) {
        let (o, d, inv) = (ray.ray.origin, ray.ray.dir, ray.inv_dir);
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let e = stack.entries[top];
            // The stack holds cells in order along the ray, nearest on top:
            // once one starts past the limit, all the others do.
            if e.t0 > visitor.t_limit() {
                return;
            }
            visitor.counter().traversal_step();
            let node = self.nodes[e.node as usize];
            if node.is_leaf() {
                visitor.counter().leaf_visit();
                let first = node.first as usize;
                let refs = &self.refs[first..first + node.count() as usize];
                if visitor.visit_leaf(refs, e.t1) {
                    return;
                }
                continue;
            }
            let mid = e.cell.mid();
            // Parameters of the three mid-planes, and the octant entered at
            // t0: on a plane's upper side once it is crossed going up, or
            // until it is crossed going down. A ray parallel to a plane (or
            // in it: upper) never crosses it: its parameter is -inf on the
            // upper side, +inf on the lower, which gives the same rule.
            let mut t_mid = [0.0f64; 3];
            let mut child = 0usize;
            for k in 0..3 {
                let t = if d[k] == 0.0 {
                    if o[k] >= mid[k] {
                        f64::NEG_INFINITY
                    } else {
                        f64::INFINITY
                    }
                } else {
                    (mid[k] - o[k]) * inv[k]
                };
                t_mid[k] = t;
                child |= (((t <= e.t0) != ray.negative[k]) as usize) << k;
            }
            // The crossings inside the cell, in increasing t: the children
            // the ray passes through follow by flipping one bit at each.
            let mut inside = [0usize; 3];
            let mut n_inside = 0;
            for (k, &t) in t_mid.iter().enumerate() {
                if t > e.t0 && t < e.t1 {
                    inside[n_inside] = k;
                    n_inside += 1;
                }
            }
            // At most three: compare and swap (ties keep axis order).
            let earlier = |a: usize, b: usize| t_mid[a] > t_mid[b];
            if n_inside > 1 && earlier(inside[0], inside[1]) {
                inside.swap(0, 1);
            }
            if n_inside > 2 {
                if earlier(inside[1], inside[2]) {
                    inside.swap(1, 2);
                }
                if earlier(inside[0], inside[1]) {
                    inside.swap(0, 1);
                }
            }
            let crossings = &inside[..n_inside];
            let mut sequence = [(0usize, 0.0f64, 0.0f64); 4];
            let mut t_start = e.t0;
            for (i, &k) in crossings.iter().enumerate() {
                sequence[i] = (child, t_start, t_mid[k]);
                child ^= 1 << k;
                t_start = t_mid[k];
            }
            sequence[n_inside] = (child, t_start, e.t1);
            // Farthest first, so the nearest is popped next. Empty octants
            // are counted as entered leaves (Havran's measures) but cost
            // nothing else.
            let limit = visitor.t_limit();
            let mask = node.mask();
            for &(c, ts, te) in sequence[..=n_inside].iter().rev() {
                if mask >> c & 1 == 0 {
                    if ts <= limit {
                        visitor.counter().traversal_step();
                        visitor.counter().leaf_visit();
                    }
                    continue;
                }
                stack.entries[top] = Entry {
                    node: node.child(c),
                    cell: e.cell.child(c),
                    t0: ts,
                    t1: te,
                };
                top += 1;
            }
        }
    }
}

/// A cell waiting on the traversal stack, with the ray's parameters at its
/// entry and exit.
#[derive(Clone, Copy, Debug, Default)]
struct Entry {
    node: u32,
    cell: Cell,
    t0: f64,
    t1: f64,
}

/// Deepest stack a walk needs: each level leaves at most three siblings
/// waiting, plus the cell being entered.
const STACK_CAPACITY: usize = 3 * MAX_OCTREE_DEPTH as usize + 4;

/// The cells a walk has still to visit.
struct Stack {
    entries: [Entry; STACK_CAPACITY],
}

thread_local! {
    /// One traversal stack per thread, reused by every ray (a traversal
    /// never starts another on the same thread), so no ray initialises it.
    static STACK: std::cell::RefCell<Stack> = std::cell::RefCell::new(Stack {
        entries: [Entry::default(); STACK_CAPACITY],
    });
}

/// The ray as the traversal sees it: direction components too small to
/// invert are treated as exactly zero (parallel to the planes), which moves
/// the ray by less than the cells' padding over any finite distance.
struct WalkRay {
    ray: crate::math::Ray,
    inv_dir: DVec3,
    /// Per axis: the direction is negative.
    negative: [bool; 3],
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
        let negative = [ray.dir.x < 0.0, ray.dir.y < 0.0, ray.dir.z < 0.0];
        Self {
            ray,
            inv_dir,
            negative,
        }
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
    prims: &'a Primitives<'a>,
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
                    self.prims,
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
    prims: &'a Primitives<'a>,
    ray: &'a PreparedRay,
    t_max: f64,
    found: &'a mut ShadowCrossings,
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
            if !self.mailbox.seen(i)
                && test_occlusion(
                    self.prims,
                    i,
                    self.ray,
                    self.t_max,
                    self.found,
                    self.counter,
                )
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

/// Bytes one node and one reference take in the built structure.
const NODE_BYTES: u64 = std::mem::size_of::<Node>() as u64;
const REF_BYTES: u64 = 4;
/// What a node waiting for its verdict costs besides its references: the
/// struct and its heap block's bookkeeping (an allocator's header and
/// rounding, estimated).
const PENDING_BYTES: u64 = std::mem::size_of::<Pending>() as u64 + 32;
/// Consecutive levels a node may split without separating its references
/// before it stays a leaf: concentric spheres centred on a split point
/// separate one level further down, coincident triangles never do.
const MAX_NON_SEPARATING_SPLITS: u8 = 2;

/// A node waiting for its verdict: its slot in `nodes`, its cell, the
/// shapes whose surface touches it, and how many of its ancestors in a row
/// split without separating anything.
struct Pending {
    slot: u32,
    cell: Cell,
    items: Vec<u32>,
    non_separating: u8,
}

/// Why a node stays a leaf, for the build statistics.
#[derive(Clone, Copy, PartialEq, Eq)]
enum LeafReason {
    /// Few enough references, deep enough, or (cost-driven) not worth it.
    Done,
    /// A split would not separate the references.
    Duplication,
    /// Even the smallest split would exceed the memory budget.
    Budget,
}

/// What a node's classification proposes.
enum Proposal {
    Leaf(LeafReason),
    Split {
        children: Vec<Vec<u32>>,
        separates: bool,
    },
}

/// A growable array kept in fixed-size blocks, so that growing it never
/// holds the old and the new copy at once (a `Vec` doubling a 200 MB array
/// briefly needs 600 MB); turned into one exact `Vec` at the end.
struct Blocks<T> {
    blocks: Vec<Vec<T>>,
    len: usize,
}

const BLOCK: usize = 1 << 16;

impl<T: Copy> Blocks<T> {
    fn new() -> Self {
        Self {
            blocks: Vec::new(),
            len: 0,
        }
    }

    fn extend(&mut self, items: &[T]) -> Result<(), OctreeError> {
        for &item in items {
            if self.len.is_multiple_of(BLOCK) {
                let block = try_with_capacity(BLOCK)?;
                try_push(&mut self.blocks, block)?;
            }
            if let Some(block) = self.blocks.last_mut() {
                block.push(item);
            }
            self.len += 1;
        }
        Ok(())
    }

    fn set(&mut self, index: usize, item: T) {
        self.blocks[index / BLOCK][index % BLOCK] = item;
    }

    /// One exact `Vec`, freeing each block once copied.
    fn into_vec(self) -> Result<Vec<T>, OctreeError> {
        let mut out = try_with_capacity(self.len)?;
        for block in self.blocks {
            out.extend_from_slice(&block);
        }
        Ok(out)
    }
}

struct Builder<'a> {
    shapes: &'a [Shape],
    params: OctreeParams,
    budget: u64,
    /// Bytes held so far: the structure built, plus the nodes waiting for
    /// their verdict with their references.
    used: u64,
    nodes: Blocks<Node>,
    refs: Blocks<u32>,
    stats: OctreeStats,
}

/// Grows `v` by one element without aborting when memory runs out.
fn try_push<T>(v: &mut Vec<T>, item: T) -> Result<(), OctreeError> {
    v.try_reserve(1).map_err(|_| OctreeError::OutOfMemory {
        bytes: (v.capacity().max(1) * std::mem::size_of::<T>()) as u64,
    })?;
    v.push(item);
    Ok(())
}

fn try_with_capacity<T>(n: usize) -> Result<Vec<T>, OctreeError> {
    let mut v = Vec::new();
    v.try_reserve_exact(n)
        .map_err(|_| OctreeError::OutOfMemory {
            bytes: (n * std::mem::size_of::<T>()) as u64,
        })?;
    Ok(v)
}

impl Builder<'_> {
    /// Builds level by level from `root`.
    fn build(&mut self, root: Pending) -> Result<(), OctreeError> {
        let mut level = vec![root];
        let mut depth = 0;
        while !level.is_empty() {
            self.stats.max_depth = depth;
            let mut next = Vec::new();
            let mut rest = level.into_iter().peekable();
            while rest.peek().is_some() {
                // A batch of nodes, classified in parallel, decided in order.
                let mut batch = Vec::new();
                let mut references = 0;
                while let Some(p) = rest.next_if(|_| references < BATCH_REFERENCES) {
                    references += p.items.len();
                    batch.push(p);
                }
                let proposals: Vec<Result<Proposal, OctreeError>> =
                    batch.par_iter().map(|p| self.propose(p, depth)).collect();
                for (pending, proposal) in batch.into_iter().zip(proposals) {
                    self.decide(pending, proposal?, &mut next)?;
                }
            }
            level = next;
            depth += 1;
        }
        Ok(())
    }

    /// Whether `p`, at level `depth`, should split and into what.
    fn propose(&self, p: &Pending, depth: u32) -> Result<Proposal, OctreeError> {
        let n = p.items.len();
        let params = &self.params;
        let leaf = Proposal::Leaf(LeafReason::Done);
        if depth >= params.max_depth || n <= params.leaf_size as usize {
            return Ok(leaf);
        }
        // The smallest possible split (one child node) must fit.
        if self.used + NODE_BYTES > self.budget {
            return Ok(Proposal::Leaf(LeafReason::Budget));
        }
        let cells: [Aabb; 8] = std::array::from_fn(|c| p.cell.child(c).aabb().padded(CLASSIFY_PAD));
        // One byte per reference: the octants its surface touches. The
        // bounding box rules out octants cheaply; the exact test runs only
        // where the box spans several. A shape whose box meets a single
        // octant touches it (its surface touches this node), or at worst
        // only the padding: an extra reference, never a missing one.
        let mask_of = |&i: &u32| -> u8 {
            let shape = &self.shapes[i as usize];
            let candidates = match shape.bounds() {
                Some(b) => (0..8).fold(0u8, |m, c| m | ((b.overlaps(&cells[c]) as u8) << c)),
                None => 0xff,
            };
            if candidates.count_ones() <= 1 {
                return candidates;
            }
            (0..8).fold(0u8, |m, c| {
                let touches = candidates >> c & 1 == 1 && shape.overlaps_box(&cells[c]);
                m | ((touches as u8) << c)
            })
        };
        let mut masks = try_with_capacity::<u8>(n)?;
        if n >= PARALLEL_MIN {
            p.items.par_iter().map(mask_of).collect_into_vec(&mut masks);
        } else {
            masks.extend(p.items.iter().map(mask_of));
        }
        let mut counts = [0usize; 8];
        for m in &masks {
            for (c, count) in counts.iter_mut().enumerate() {
                *count += (m >> c & 1) as usize;
            }
        }
        let total: usize = counts.iter().sum();
        // A split separates unless several children each hold every
        // reference (one child holding them all still shrinks the cell).
        let occupied = counts.iter().filter(|&&k| k > 0).count();
        let separates = occupied == 1 || counts.iter().any(|&k| k > 0 && k < n);
        let stale = !separates && p.non_separating + 1 > MAX_NON_SEPARATING_SPLITS;
        if stale || total > params.max_duplication as usize * n {
            return Ok(Proposal::Leaf(LeafReason::Duplication));
        }
        if params.cost_driven {
            // Expected cost of a ray through this node, in intersection tests,
            // as a leaf and split (children weighted by their relative area).
            let area = p.cell.aabb().surface_area();
            if area > 0.0 {
                let split_cost = TRAVERSAL_COST
                    + (0..8)
                        .map(|c| p.cell.child(c).aabb().surface_area() / area * counts[c] as f64)
                        .sum::<f64>();
                if split_cost >= n as f64 {
                    return Ok(leaf);
                }
            }
        }
        let mut children = try_with_capacity::<Vec<u32>>(8)?;
        for &count in &counts {
            children.push(try_with_capacity(count)?);
        }
        for (&i, &m) in p.items.iter().zip(&masks) {
            for (c, child) in children.iter_mut().enumerate() {
                if m >> c & 1 == 1 {
                    child.push(i);
                }
            }
        }
        Ok(Proposal::Split {
            children,
            separates,
        })
    }

    /// Makes `p` a leaf, or splits it if its proposal fits the budget,
    /// queueing its non-empty children on `next`.
    fn decide(
        &mut self,
        p: Pending,
        proposal: Proposal,
        next: &mut Vec<Pending>,
    ) -> Result<(), OctreeError> {
        let held = PENDING_BYTES + REF_BYTES * p.items.len() as u64;
        match proposal {
            Proposal::Split {
                children,
                separates,
            } => {
                let queued: u64 = children
                    .iter()
                    .filter(|c| !c.is_empty())
                    .map(|c| PENDING_BYTES + REF_BYTES * c.len() as u64)
                    .sum();
                let mask = (0..8).fold(0u32, |m, c| m | ((!children[c].is_empty() as u32) << c));
                let stored = mask.count_ones() as u64;
                let after = self.used - held + stored * NODE_BYTES + queued;
                if after <= self.budget {
                    self.used = after;
                    let first = self.nodes.len;
                    // Only the non-empty octants get nodes.
                    for _ in 0..stored {
                        self.nodes.extend(&[Node::EMPTY])?;
                    }
                    self.nodes.set(
                        p.slot as usize,
                        Node {
                            first: first as u32,
                            meta: INTERIOR | mask,
                        },
                    );
                    let non_separating = if separates { 0 } else { p.non_separating + 1 };
                    let mut slot = first as u32;
                    for (c, items) in children.into_iter().enumerate() {
                        if items.is_empty() {
                            continue;
                        }
                        try_push(
                            next,
                            Pending {
                                slot,
                                cell: p.cell.child(c),
                                items,
                                non_separating,
                            },
                        )?;
                        slot += 1;
                    }
                    return Ok(());
                }
                self.stats.leaves_stopped_by_budget += 1;
            }
            Proposal::Leaf(reason) => {
                self.stats.leaves_stopped_by_duplication +=
                    (reason == LeafReason::Duplication) as u64;
                self.stats.leaves_stopped_by_budget += (reason == LeafReason::Budget) as u64;
            }
        }
        self.nodes.set(
            p.slot as usize,
            Node {
                first: self.refs.len as u32,
                meta: p.items.len() as u32,
            },
        );
        self.refs.extend(&p.items)?;
        self.used -= PENDING_BYTES;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::accel::{ShadowCrossings, closest_brute_force, occlusion_brute_force};
    use crate::math::Ray;
    use crate::shapes::{Plane, Sphere, Triangle};
    use crate::stats::NoCounts;

    /// Every stored leaf: its cell and its references.
    fn leaves(tree: &Octree) -> Vec<(Cell, Vec<u32>)> {
        fn walk(tree: &Octree, index: usize, cell: Cell, out: &mut Vec<(Cell, Vec<u32>)>) {
            let node = tree.nodes[index];
            if node.is_leaf() {
                let first = node.first as usize;
                out.push((
                    cell,
                    tree.refs[first..first + node.count() as usize].to_vec(),
                ));
                return;
            }
            for c in 0..8 {
                if node.mask() >> c & 1 == 1 {
                    walk(tree, node.child(c) as usize, cell.child(c), out);
                }
            }
        }
        let mut out = Vec::new();
        if !tree.nodes.is_empty() {
            walk(tree, 0, tree.root_cell(), &mut out);
        }
        out
    }

    /// `n`^3 spheres of radius `radius` one unit apart, the first at the
    /// origin.
    fn sphere_grid(n: u32, radius: f64) -> Vec<Shape> {
        let mut shapes = Vec::new();
        for i in 0..n {
            for j in 0..n {
                for k in 0..n {
                    let c = DVec3::new(i as f64, j as f64, k as f64);
                    shapes.push(Shape::Sphere(Sphere::new(c, radius)));
                }
            }
        }
        shapes
    }

    #[test]
    fn an_interior_node_finds_its_children_by_counting_octants_below() {
        // Octants 0, 2, 5 and 7 hold something, stored from node 10 on.
        let node = Node {
            first: 10,
            meta: INTERIOR | 0b1010_0101,
        };
        assert!(!node.is_leaf());
        let children: Vec<u32> = [0, 2, 5, 7].map(|c| node.child(c)).to_vec();
        assert_eq!(children, [10, 11, 12, 13]);
    }

    #[test]
    fn child_cells_tile_their_parent_exactly() {
        let parent = Cell {
            min: DVec3::new(-1.5, 0.25, 3.0),
            side: 0.75,
        };
        let mut volume = 0.0;
        for c in 0..8 {
            let child = parent.child(c);
            assert_eq!(child.side, 0.375);
            for k in 0..3 {
                let lower = parent.min[k];
                let expected = if c >> k & 1 == 1 {
                    parent.mid()[k]
                } else {
                    lower
                };
                assert_eq!(child.min[k], expected, "octant {c}, axis {k}");
            }
            volume += child.side.powi(3);
        }
        assert_eq!(volume, parent.side.powi(3));
    }

    #[test]
    fn every_shape_is_in_the_leaf_around_its_centre_and_only_in_leaves_it_overlaps() {
        let mut shapes = sphere_grid(6, 0.3);
        shapes.push(Shape::Plane(Plane::new(DVec3::ZERO, DVec3::Y)));
        let tree = Octree::build(&shapes, OctreeParams::default()).unwrap();
        assert_eq!(tree.unbounded, [216], "the plane is tested for every ray");
        let leaves = leaves(&tree);
        assert!(
            leaves.len() > 8,
            "the grid was split ({} leaves)",
            leaves.len()
        );
        for (cell, refs) in &leaves {
            for &r in refs {
                let bounds = shapes[r as usize].bounds().unwrap();
                assert!(
                    cell.aabb().padded(1e-9).overlaps(&bounds),
                    "shape {r} referenced by a leaf it does not touch"
                );
            }
        }
        for (index, shape) in shapes.iter().enumerate().take(216) {
            let centre = shape.bounds().unwrap().center();
            let around = leaves
                .iter()
                .filter(|(cell, _)| cell.aabb().contains(centre))
                .collect::<Vec<_>>();
            assert!(
                !around.is_empty(),
                "shape {index}: no leaf holds its centre"
            );
            for (_, refs) in around {
                assert!(refs.contains(&(index as u32)), "shape {index} missing");
            }
        }
        let stats = tree.stats();
        let stored: u64 = leaves.iter().map(|(_, r)| r.len() as u64).sum();
        assert_eq!(stats.references, stored);
        // Every interior node has eight children, stored or not.
        assert_eq!(stats.nodes, 1 + 8 * (stats.nodes - stats.leaves));
    }

    #[test]
    fn coincident_triangles_stop_splitting_instead_of_multiplying() {
        let triangle = Triangle::new([DVec3::ZERO, DVec3::X, DVec3::Y]).unwrap();
        let shapes = vec![Shape::Triangle(triangle); 200];
        let tree = Octree::build(&shapes, OctreeParams::default()).unwrap();
        let stats = tree.stats();
        assert!(stats.leaves_stopped_by_duplication > 0);
        // Splitting a stack of identical triangles separates nothing: the
        // build gives up after the non-separating levels it allows.
        assert!(stats.references <= 200 * 8 * 8, "{stats:?}");
        let ray = PreparedRay::new(Ray::new(DVec3::new(0.25, 0.25, 1.0), -DVec3::Z));
        let prims = Primitives::opaque(&shapes);
        let hit = tree
            .closest(&prims, &ray, f64::INFINITY, &mut NoCounts)
            .unwrap();
        assert_eq!(hit.shape, 0, "ties go to the lowest index");
        assert_eq!(hit.hit.t, 1.0);
    }

    #[test]
    fn a_budget_too_small_for_any_split_keeps_one_leaf_that_answers_alike() {
        let shapes = sphere_grid(4, 0.3);
        let params = OctreeParams {
            memory_budget_mib: 0,
            ..OctreeParams::default()
        };
        let tree = Octree::build(&shapes, params).unwrap();
        let stats = tree.stats();
        assert_eq!(stats.nodes, 1);
        assert_eq!(stats.leaves_stopped_by_budget, 1);
        let prims = Primitives::opaque(&shapes);
        for k in 0..16 {
            let ray = PreparedRay::new(Ray::new(
                DVec3::new(-2.0, k as f64 * 0.2, 1.1),
                DVec3::new(1.0, 0.05, 0.02).normalize(),
            ));
            assert_eq!(
                tree.closest(&prims, &ray, f64::INFINITY, &mut NoCounts),
                closest_brute_force(&prims, &ray, f64::INFINITY, &mut NoCounts)
            );
        }
    }

    #[test]
    fn rays_in_split_planes_and_parallel_to_axes_agree_with_brute_force() {
        // Spheres that reach across the split planes. Rays lying in those
        // planes, with zero direction components, are traversal's
        // degenerate case (Revelles et al. 2000).
        let shapes = sphere_grid(4, 0.6);
        let tree = Octree::build(&shapes, OctreeParams::default()).unwrap();
        let prims = Primitives::opaque(&shapes);
        let root = tree.root_cell();
        let plane = |quarters: f64| root.min.x + root.side * quarters / 4.0;
        let mut rays = Vec::new();
        for a in [plane(2.0), plane(1.0), plane(3.0), 1.0, 0.2] {
            for b in [plane(2.0), plane(1.0), plane(3.0), 2.0, 0.0] {
                rays.push(Ray::new(DVec3::new(-5.0, a, b), DVec3::X));
                rays.push(Ray::new(DVec3::new(a, 9.0, b), -DVec3::Y));
                rays.push(Ray::new(DVec3::new(a, b, -5.0), DVec3::Z));
                rays.push(Ray::new(
                    DVec3::new(-5.0, -5.0 + a, b),
                    DVec3::new(1.0, 1.0, 0.0).normalize(),
                ));
            }
        }
        let mut hits = 0;
        let (mut a, mut b) = (ShadowCrossings::default(), ShadowCrossings::default());
        for ray in rays {
            let ray = PreparedRay::new(ray);
            let octree = tree.closest(&prims, &ray, f64::INFINITY, &mut NoCounts);
            let brute = closest_brute_force(&prims, &ray, f64::INFINITY, &mut NoCounts);
            assert_eq!(octree, brute, "{:?}", ray.ray);
            hits += octree.is_some() as usize;
            tree.occlusion(&prims, &ray, 20.0, &mut a, &mut NoCounts);
            occlusion_brute_force(&prims, &ray, 20.0, &mut b, &mut NoCounts);
            assert_eq!(a, b, "{:?}", ray.ray);
        }
        assert!(hits > 40, "the rays meet the grid ({hits} hits)");
    }
}
