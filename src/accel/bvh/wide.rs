//! The BVH collapsed into eight-wide nodes for the queries that count
//! nothing: a node's children are tested at once in `f32` lanes, with the
//! octree's conservative box test (`octree/bounds.rs`, after Ize 2013),
//! and visited nearest entry first, as Embree's 8-wide BVH is (Wald et
//! al. 2008, "Getting Rid of Packets"). Each wide node takes the
//! children of the binary nodes below it, opening the largest first,
//! until it holds eight. The walk is the octree's (`accel::wide_walk`);
//! counted queries keep the binary walk, whose steps are the tree's own.

use super::node::BvhNode;
use crate::accel::octree::bounds::{Block, PAD_RELATIVE, SIDE_RANGE};
use crate::accel::wide_walk::WideStack;
use crate::math::DVec3;

/// Children per wide node: the lanes of a [`Block`].
const WIDTH: usize = 8;
/// A child entry that is a leaf: this bit, and the leaf's index.
pub(super) const LEAF: u32 = 1 << 31;

/// The wide nodes: per node, its children's boxes and entries.
#[derive(Clone, Debug, Default)]
pub(super) struct WideNodes {
    pub(super) blocks: Vec<Block>,
    pub(super) children: Vec<[u32; WIDTH]>,
    pub(super) counts: Vec<u8>,
    /// Per leaf: its first reference and how many.
    pub(super) leaves: Vec<(u32, u32)>,
    /// The root's box (lane 0) and entry.
    pub(super) root: Block,
    pub(super) root_entry: u32,
    /// The corner boxes are relative to.
    pub(super) corner: DVec3,
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
        let mut depth = 0;
        wide.root_entry = wide.collapse(nodes, 0, pad, 0, &mut depth);
        // Deeper than the walk's stack holds: the binary walk serves.
        if depth > WideStack::MAX_DEPTH {
            return Self::default();
        }
        wide
    }

    pub(super) fn is_empty(&self) -> bool {
        self.blocks.is_empty() && self.leaves.is_empty()
    }

    pub(super) fn memory_bytes(&self) -> u64 {
        (self.blocks.len() * (std::mem::size_of::<Block>() + 4 * WIDTH + 1) + self.leaves.len() * 8)
            as u64
    }

    /// The entry of binary node `index`'s subtree, `level` wide levels
    /// below the root; `depth` is the deepest level made.
    fn collapse(
        &mut self,
        nodes: &[BvhNode],
        index: usize,
        pad: f64,
        level: usize,
        depth: &mut usize,
    ) -> u32 {
        *depth = (*depth).max(level);
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
            let entry = self.collapse(nodes, g, pad, level + 1, depth);
            self.children[wide][lane] = entry;
        }
        wide as u32
    }
}
