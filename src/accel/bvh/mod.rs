//! A bounding volume hierarchy over the bounded shapes of a scene, beside
//! the octree, so that a user can hold one against the other (Havran's
//! thesis compared them; the octree stays glint's default).
//!
//! Build: top down with the surface-area heuristic evaluated over binned
//! centroids (Wald, "On fast Construction of SAH-based Bounding Volume
//! Hierarchies", 2007), the two halves of a large node built in parallel.
//! Each shape is referenced once; a node holds the box of what is below it.
//! The split depends only on the shapes, so the tree is the same for any
//! number of threads.
//!
//! Traversal: depth first on a per-thread stack, the nearer child first,
//! skipping a node whose box the ray enters beyond the best hit so far.
//! Counted queries walk the binary tree (`walk.rs`; its steps are what
//! the statistics report); the others walk it collapsed into eight-wide
//! nodes tested in `f32` lanes (`wide.rs`). Primitive tests are the octree's and brute force's (`primitives.rs`), so
//! the answers are theirs: the closest hit is the lexicographic minimum of
//! (distance, shape index) and a shadow ray collects the same crossings.

mod build;
mod node;
mod tree;
mod walk;
mod wide;

pub use tree::{Bvh, BvhStats};
pub use walk::BvhStack;

#[cfg(test)]
mod tests;
