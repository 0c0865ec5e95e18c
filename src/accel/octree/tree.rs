//! The built octree: its nodes and references, the shapes tested for every
//! ray, and what it says of itself (statistics, cells for the overlay).
//! Building is `build.rs`'s, the traversal `walk.rs`'s.

use super::bounds::NodeBoxes;
use super::node::LEVEL_MASK;
use super::node::{Cell, Node};
use super::params::{OctreeCell, OctreeParams, OctreeStats};
use crate::math::Aabb;

#[derive(Clone, Debug)]
pub struct Octree {
    pub(super) bounds: Aabb,
    pub(super) nodes: Vec<Node>,
    pub(super) refs: Vec<u32>,
    /// Shapes without bounds (planes, unclipped quadrics), tested for every ray.
    pub(super) unbounded: Vec<u32>,
    pub(super) params: OctreeParams,
    pub(super) stats: OctreeStats,
    /// The side of a cell at each level, halved from the root's exactly as
    /// the build halves it.
    pub(super) sides: [f64; LEVEL_MASK + 1],
    /// The box of what each stored node holds, for the wide walk.
    pub(super) boxes: NodeBoxes,
    /// The shapes grouped by the plane they lie in, for rays leaving one.
    pub(super) planes: crate::accel::planes::PlaneGroups,
}

impl Octree {
    pub fn stats(&self) -> OctreeStats {
        self.stats
    }

    pub fn params(&self) -> OctreeParams {
        self.params
    }

    pub fn bounds(&self) -> Aabb {
        self.bounds
    }

    /// The shapes grouped by the plane they lie in.
    pub fn planes(&self) -> &crate::accel::planes::PlaneGroups {
        &self.planes
    }

    /// Whether the whole tree is one leaf (a scene of a few shapes, or a
    /// build stopped at the root).
    pub fn is_one_leaf(&self) -> bool {
        self.nodes.len() <= 1
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

    /// Fills the side table from the root cell.
    pub(super) fn set_sides(&mut self) {
        let mut side = self.root_cell().side;
        for s in self.sides.iter_mut() {
            *s = side;
            side *= 0.5;
        }
    }

    pub(super) fn root_cell(&self) -> Cell {
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
}
