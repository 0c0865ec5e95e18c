//! Building the octree: breadth first, level by level, classifying each
//! node's shapes into its octants in parallel and deciding in a fixed
//! order, within a memory budget (see the module docs of `octree`).

use rayon::prelude::*;

use super::bounds::NodeBoxes;
use super::node::LEVEL_MASK;
use super::node::{Cell, INTERIOR, Node};
use super::params::{OctreeError, OctreeParams, OctreeStats};
use super::tree::Octree;
use crate::math::{Aabb, DVec3};
use crate::shapes::Shape;

/// Relative growth of boxes used to classify shapes, so that a shape
/// touching a cell in exact arithmetic is never missed through rounding.
pub(super) const CLASSIFY_PAD: f64 = 1e-9;
/// ... but never more than this fraction of the cell's side: far from the
/// origin (a model 0.4 m across, 5e6 m out, as survey coordinates put it)
/// `CLASSIFY_PAD` of the coordinates exceeds the deep cells themselves, and
/// every shape near a cell would be referenced by it (10.8 million
/// references for 678 triangles, a 6 s build).
const CLASSIFY_PAD_OF_SIDE: f64 = 1e-3;
/// ... nor less than this many roundings of the coordinates, whatever the
/// cell's size.
const CLASSIFY_PAD_ROUNDINGS: f64 = 64.0 * f64::EPSILON;

/// `cell` grown by the classification's padding: `CLASSIFY_PAD` of its
/// coordinates' magnitude, at most `CLASSIFY_PAD_OF_SIDE` of its side (but
/// never below `CLASSIFY_PAD_ROUNDINGS` of its magnitude). Near the origin
/// the first bound is the smaller at every depth the octree allows.
pub(super) fn classify_box(cell: &Cell) -> Aabb {
    let aabb = cell.aabb();
    let magnitude = aabb.max_abs().max(f64::MIN_POSITIVE);
    let pad = (CLASSIFY_PAD * magnitude)
        .min((CLASSIFY_PAD_OF_SIDE * cell.side).max(CLASSIFY_PAD_ROUNDINGS * magnitude));
    Aabb::new(aabb.min - DVec3::splat(pad), aabb.max + DVec3::splat(pad))
}
/// Cost of one traversal step relative to one intersection test, for the
/// surface-area estimate.
const TRAVERSAL_COST: f64 = 1.0;
/// Below this many references a node (or a batch of nodes) is classified
/// on one thread.
const PARALLEL_MIN: usize = 2048;
/// Nodes of a level are classified in batches of about this many
/// references, so a level's candidate children never all exist at once...
const BATCH_REFERENCES: usize = 1 << 20;
/// ... and fewer under a small budget: a batch's candidate children hold
/// up to eight references each of its own (4 bytes each), outside the
/// budget's count until decided, so a batch of `budget / 256` references
/// adds at most an eighth of the budget. (With 2^20 under a 16 MiB
/// budget, shells -s 3 without the cost-driven stop peaked 59 MiB above
/// the scene.)
const BATCH_OF_BUDGET: u64 = 256;
/// Batches never shrink below this, so that small budgets still classify
/// in parallel.
const MIN_BATCH_REFERENCES: usize = 4096;

impl Octree {
    /// Builds the octree over the bounded shapes (unbounded ones are kept
    /// aside and tested for every ray). Fails only if the allocator refuses
    /// memory; the budget in `params` normally keeps the build far from that.
    pub fn build(shapes: &[Shape], params: OctreeParams) -> Result<Self, OctreeError> {
        // Past this level the walk's indices would wrap and answer wrongly;
        // the other parameters only cost speed or memory when odd, and the
        // edges (CLI, scene files, records) check them.
        let deepest = crate::limits::MAX_OCTREE_DEPTH;
        if params.max_depth > deepest {
            return Err(crate::limits::LimitError::OctreeDepth(params.max_depth).into());
        }
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
            sides: [0.0; LEVEL_MASK + 1],
            boxes: NodeBoxes::default(),
            planes: crate::accel::planes::PlaneGroups::build(shapes),
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
        tree.set_sides();
        tree.boxes = NodeBoxes::build(&tree.nodes, &tree.refs, tree.root_cell(), shapes);
        tree.stats = OctreeStats {
            nodes: tree.nodes.len() as u64 + unstored,
            leaves: stored_leaves + unstored,
            empty_leaves: stored_empty + unstored,
            references: tree.refs.len() as u64,
            memory_bytes: (tree.nodes.len() * std::mem::size_of::<Node>()
                + (tree.refs.len() + tree.unbounded.len()) * 4) as u64
                + tree.boxes.memory_bytes(),
            ..stats
        };
        Ok(tree)
    }
}

/// Bytes one node (with its box) and one reference take in the built
/// structure.
const NODE_BYTES: u64 = std::mem::size_of::<Node>() as u64 + NodeBoxes::BYTES_PER_NODE;
const REF_BYTES: u64 = 4;
/// What a node waiting for its verdict costs besides its references: the
/// struct and its heap block's bookkeeping (an allocator's header and
/// rounding, estimated).
const PENDING_BYTES: u64 = std::mem::size_of::<Pending>() as u64 + 32;
/// Consecutive levels a node may split without separating its references
/// before it stays a leaf: concentric spheres centred on a split point
/// separate one level further down, coincident triangles never do.
const MAX_NON_SEPARATING_SPLITS: u8 = 2;

/// A node whose references are at most this many triangles around one
/// mesh vertex inside it stays a leaf. Every child holding the vertex
/// would hold the whole fan again, so only the maximum depth stopped such
/// a node: around each vertex of valence 6 the tree went ten levels down
/// (23 references per triangle on the bunny, 51 on SPD tetra), builds took
/// 3-5x as long and the trees 3-4x the memory, and no ray got faster
/// (docs/benchmarks.md, "Vertex fans"). Mesh vertices have 5-7 triangles
/// around them, up to 12 on the bunny; larger fans (a polygon cut into a
/// fan, a sphere's pole) are cut by the cells around them and split as
/// before.
const MAX_FAN: usize = 16;

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
    fn batch_references(&self) -> usize {
        ((self.budget / BATCH_OF_BUDGET) as usize).clamp(MIN_BATCH_REFERENCES, BATCH_REFERENCES)
    }

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
                while let Some(p) = rest.next_if(|_| references < self.batch_references()) {
                    references += p.items.len();
                    batch.push(p);
                }
                // A small batch on this thread: waking the pool's threads
                // costs more than classifying a few hundred references.
                let proposals: Vec<Result<Proposal, OctreeError>> = if references < PARALLEL_MIN {
                    batch.iter().map(|p| self.propose(p, depth)).collect()
                } else {
                    batch.par_iter().map(|p| self.propose(p, depth)).collect()
                };
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
        if n <= MAX_FAN && is_vertex_fan(self.shapes, &p.items, &classify_box(&p.cell)) {
            return Ok(leaf);
        }
        // The smallest possible split (one child node) must fit.
        if self.used + NODE_BYTES > self.budget {
            return Ok(Proposal::Leaf(LeafReason::Budget));
        }
        let cells: [Aabb; 8] = std::array::from_fn(|c| classify_box(&p.cell.child(c)));
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
                let after = self.used - held
                    + stored * NODE_BYTES
                    + NodeBoxes::BYTES_PER_INTERIOR_NODE
                    + queued;
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

/// Whether every reference is a triangle with one vertex, inside `cell`,
/// in common (exactly: meshes and polygon fans share vertices by value).
fn is_vertex_fan(shapes: &[Shape], items: &[u32], cell: &Aabb) -> bool {
    let vertices = |i: &u32| match &shapes[*i as usize] {
        Shape::Triangle(t) => Some(t.vertices),
        _ => None,
    };
    let Some(first) = items.first().and_then(vertices) else {
        return false;
    };
    first.iter().any(|v| {
        cell.contains(*v)
            && items[1..]
                .iter()
                .all(|i| vertices(i).is_some_and(|t| t.contains(v)))
    })
}
