//! What an octree will cost before a ray is cast: the surface-area
//! argument of MacDonald & Booth (1990), as Havran's thesis (2000) applies
//! it to octrees. A random line that crosses a convex cell crosses a convex
//! cell inside it with probability the ratio of their surface areas
//! (Crofton), which for an octant of a cube is exactly 1/4 per level. So a
//! ray crossing the root enters, on average, `sum 4^-depth` cells over the
//! cells it could enter (counted as the walk counts them: nodes and the
//! empty octants of inner nodes), and tests each leaf's references with
//! the chance that it meets the box of what the leaf holds (the walk tests
//! nothing in a leaf whose box the ray misses): that box's surface area
//! over the root's, or `4^-depth` where the tree has no boxes; plus every
//! unbounded shape.
//!
//! View-independent on purpose: rays of every kind (eye, shadow, mirror)
//! are counted together, and a tree is chosen for all of them, not for
//! the eye rays alone that a camera's projected areas would weigh. What it
//! leaves out, and so overestimates: rays stopping at their first hit, the
//! mailbox (a shape in several leaves is tested once per ray), and rays
//! that miss the root cell. docs/speed-and-accuracy.md, "Predicting an octree's cost", says by
//! how much on the SPD scenes.

use serde::Serialize;

use super::tree::Octree;

/// Expected work per ray that crosses the root cell, from the tree alone.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct PredictedCost {
    pub traversal_steps_per_ray: f64,
    pub intersection_tests_per_ray: f64,
}

impl Octree {
    /// The expected traversal steps and intersection tests of a ray that
    /// crosses the root cell (module documentation: the model and what it
    /// leaves out). Linear in the number of nodes; renders nothing.
    pub fn predicted_cost(&self) -> PredictedCost {
        let mut steps = 0.0;
        let mut tests = self.unbounded.len() as f64;
        if !self.nodes.is_empty() {
            steps += 1.0;
            let root_area = 6.0 * self.root_cell().side.powi(2);
            // Per node: the chance of entering its cell, and of meeting the
            // box of what it holds.
            let mut stack = vec![(0u32, 1.0f64, 1.0f64)];
            while let Some((index, weight, held)) = stack.pop() {
                let node = self.nodes[index as usize];
                if node.is_leaf() {
                    tests += held * node.count() as f64;
                    continue;
                }
                // Each octant, stored or empty, is entered with a quarter
                // of the parent's chance.
                let child_weight = 0.25 * weight;
                steps += 8.0 * child_weight;
                let mask = node.mask();
                let boxes = self.has_boxes().then(|| self.boxes.children(index));
                for (lane, c) in (0..8).filter(|c| mask >> c & 1 == 1).enumerate() {
                    let held = match boxes {
                        Some(block) => (block.surface_area(lane) / root_area).min(child_weight),
                        None => child_weight,
                    };
                    stack.push((node.child(c), child_weight, held));
                }
            }
        }
        PredictedCost {
            traversal_steps_per_ray: steps,
            intersection_tests_per_ray: tests,
        }
    }
}
