//! The BVH collapsed into eight-wide nodes for the queries that count
//! nothing: a node's children are tested at once in `f32` lanes, with the
//! octree's conservative box test (`octree/bounds.rs`, after Ize 2013),
//! and visited nearest entry first, as Embree's 8-wide BVH is (Wald et
//! al. 2008, "Getting Rid of Packets"). Each wide node takes the
//! children of the binary nodes below it, opening the largest first,
//! until it holds eight. Counted queries keep the binary walk, whose
//! steps are the tree's own.

use super::node::BvhNode;
use crate::accel::octree::bounds::{Block, BoxLanes, BoxRay, PAD_RELATIVE, SIDE_RANGE, limit_f32};
use crate::math::DVec3;

/// Children per wide node: the lanes of a [`Block`].
const WIDTH: usize = 8;
/// A child entry that is a leaf: this bit, and the leaf's index.
const LEAF: u32 = 1 << 31;

/// The wide nodes: per node, its children's boxes and entries.
#[derive(Clone, Debug, Default)]
pub(super) struct WideNodes {
    blocks: Vec<Block>,
    children: Vec<[u32; WIDTH]>,
    counts: Vec<u8>,
    /// Per leaf: its first reference and how many.
    leaves: Vec<(u32, u32)>,
    /// The root's box (lane 0) and entry.
    root: Block,
    root_entry: u32,
    /// The corner boxes are relative to.
    corner: DVec3,
}

impl WideNodes {
    /// The wide form of `bvh`'s binary nodes; empty when there are none or
    /// the scene's size is outside what `f32` boxes hold faithfully.
    pub(super) fn build(nodes: &[BvhNode]) -> Self {
        let Some(root) = nodes.first() else {
            return Self::default();
        };
        let side = root.bounds.extent().max_element();
        if !SIDE_RANGE.contains(&side) {
            return Self::default();
        }
        let mut wide = Self {
            corner: root.bounds.min,
            ..Self::default()
        };
        let pad = PAD_RELATIVE * side;
        wide.root.set(0, root.bounds, wide.corner, pad);
        wide.root_entry = wide.collapse(nodes, 0, pad);
        wide
    }

    pub(super) fn is_empty(&self) -> bool {
        self.blocks.is_empty() && self.leaves.is_empty()
    }

    pub(super) fn memory_bytes(&self) -> u64 {
        (self.blocks.len() * (std::mem::size_of::<Block>() + 4 * WIDTH + 1) + self.leaves.len() * 8)
            as u64
    }

    /// The entry of binary node `index`'s subtree.
    fn collapse(&mut self, nodes: &[BvhNode], index: usize, pad: f64) -> u32 {
        let node = &nodes[index];
        if node.count > 0 {
            self.leaves.push((node.first_or_second, node.count));
            return LEAF | (self.leaves.len() - 1) as u32;
        }
        let mut gathered = vec![index + 1, node.first_or_second as usize];
        while gathered.len() < WIDTH {
            // Open the interior node with the largest surface: the one a
            // ray is likeliest to enter.
            let widest = gathered
                .iter()
                .enumerate()
                .filter(|(_, g)| nodes[**g].count == 0)
                .max_by(|a, b| {
                    let area = |g: usize| nodes[g].bounds.surface_area();
                    area(*a.1).total_cmp(&area(*b.1)).then(b.0.cmp(&a.0))
                })
                .map(|(at, _)| at);
            let Some(at) = widest else { break };
            let g = gathered[at];
            gathered[at] = g + 1;
            gathered.push(nodes[g].first_or_second as usize);
        }
        let wide = self.blocks.len();
        self.blocks.push(Block::EMPTY);
        self.children.push([0; WIDTH]);
        self.counts.push(gathered.len() as u8);
        for (lane, &g) in gathered.iter().enumerate() {
            self.blocks[wide].set(lane, nodes[g].bounds, self.corner, pad);
            let entry = self.collapse(nodes, g, pad);
            self.children[wide][lane] = entry;
        }
        wide as u32
    }

    /// Visits the leaves whose boxes `origin`/`inv_dir` meets before
    /// `limit()`, nearest first: `leaf(first, count)` tests their shapes
    /// and says `true` to stop. `stack` is the caller's scratch.
    #[inline(always)]
    pub(super) fn walk<L: BoxLanes>(
        &self,
        origin: [f64; 3],
        inv_dir: [f64; 3],
        stack: &mut Vec<(u32, f32)>,
        lanes: L,
        mut limit: impl FnMut() -> f64,
        mut leaf: impl FnMut(u32, u32) -> bool,
    ) {
        let ray = BoxRay::relative_to(origin, inv_dir, self.corner);
        let (root, entry) = lanes.hit(&self.root, 1, &ray, limit_f32(limit()));
        if root == 0 {
            return;
        }
        stack.clear();
        stack.push((self.root_entry, entry[0]));
        while let Some((mut at, entry)) = stack.pop() {
            let bound = limit_f32(limit());
            if entry > bound {
                continue;
            }
            loop {
                if at & LEAF != 0 {
                    let (first, count) = self.leaves[(at & !LEAF) as usize];
                    if leaf(first, count) {
                        return;
                    }
                    break;
                }
                let node = at as usize;
                let (mut hits, entry) =
                    lanes.hit(&self.blocks[node], self.counts[node] as u32, &ray, bound);
                if hits == 0 {
                    break;
                }
                if hits & (hits - 1) == 0 {
                    at = self.children[node][hits.trailing_zeros() as usize];
                    continue;
                }
                // Farthest first onto the stack, so the nearest is entered next.
                let base = stack.len();
                while hits != 0 {
                    let lane = hits.trailing_zeros() as usize;
                    hits &= hits - 1;
                    let child = (self.children[node][lane], entry[lane]);
                    let mut pos = stack.len();
                    stack.push(child);
                    while pos > base && stack[pos - 1].1 < child.1 {
                        stack[pos] = stack[pos - 1];
                        pos -= 1;
                    }
                    stack[pos] = child;
                }
                let Some((next, _)) = stack.pop() else { break };
                at = next;
            }
        }
    }
}
