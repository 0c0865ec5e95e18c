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
//! soon as the best hit lies before the exit of the current leaf. That walk
//! is the one Havran's measures count; a query that counts nothing takes
//! the wide walk instead (`accel/wide_walk.rs`): each node's children tested at
//! once against the boxes of what they hold, with the same answers.

// The eight-wide box test, shared with the BVH's wide nodes.
pub(crate) mod bounds;
mod build;
mod node;
mod packet_walk;
mod params;
mod predict;
mod tree;
mod visit;
mod walk;
mod wide_walk;

pub use bounds::{Baseline, BoxLanes};
pub(crate) use bounds::{OneByOne, SkippingPlanes};
pub use packet_walk::PacketStack;
pub use params::{DEFAULT_MEMORY_BUDGET_MIB, OctreeCell, OctreeError, OctreeParams, OctreeStats};
pub use predict::PredictedCost;
pub use tree::Octree;
pub use walk::WalkStack;

#[cfg(test)]
mod tests;
