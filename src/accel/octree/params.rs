//! What an octree is built with and what it reports: its parameters,
//! Havran's statistics of the built tree, its errors, and the cells the
//! overlay draws.

use crate::limits::{LimitError, MAX_DUPLICATION_RANGE, MAX_MEMORY_BUDGET_MIB, MAX_OCTREE_DEPTH};
use crate::math::Aabb;
use crate::shapes::Shape;

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
/// Far above what any real scene needs, far below a laptop's memory, and
/// small enough that the build finishes in seconds even when a scene
/// would use it all (docs/notes/experiments.md, "Figures behind
/// constants").
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
        // (benches/octree_sweep_256.md): depth 10 and leaf size 4 render
        // about as fast as the fastest setting with half its intersection
        // tests. The cost-driven stop is on: without it nested, overlapping
        // shapes (the SPD generator's `shells`) split until the memory
        // budget and render slower than no octree at all, while elsewhere
        // it changes nothing measurable (docs/benchmarks.md, "The default
        // octree").
        Self {
            max_depth: 10,
            leaf_size: 4,
            cost_driven: true,
            max_duplication: DEFAULT_MAX_DUPLICATION,
            memory_budget_mib: DEFAULT_MEMORY_BUDGET_MIB,
        }
    }
}

/// The leaf size of large meshes' octrees when the scene does not choose
/// one.
pub const MESH_LEAF_SIZE: u32 = 8;
/// A scene whose bounded shapes are at least this share triangles, and at
/// least [`MESH_MIN_TRIANGLES`] of them, gets [`MESH_LEAF_SIZE`].
const MESH_TRIANGLE_SHARE: f64 = 0.9;
const MESH_MIN_TRIANGLES: usize = 20_000;

impl OctreeParams {
    /// The defaults, with the leaf size chosen for `shapes`: 8 for a large
    /// mesh (at least 20,000 triangles, nine bounded shapes in ten), 4
    /// otherwise. A single ray tests a node's eight children at once
    /// against boxes of what they hold (`wide_walk.rs`), so on a large
    /// mesh leaves of eight render nearly as fast as smaller ones and
    /// halve the build's time and memory. On smaller meshes the build is
    /// cheap and larger leaves cost the packets' walk, which tests every
    /// triangle of a leaf it enters; cones, spheres and quadrics cost
    /// several triangles' worth per test, so mixed scenes keep 4. Figures:
    /// docs/benchmarks.md, "Leaves of eight for large meshes".
    pub fn default_for(shapes: &[Shape]) -> Self {
        // Only bounded shapes go into the tree (planes are tested apart).
        let bounded = shapes.iter().filter(|s| s.bounds().is_some()).count();
        let triangles = shapes
            .iter()
            .filter(|s| matches!(s, Shape::Triangle(_)))
            .count();
        let large_mesh = triangles >= MESH_MIN_TRIANGLES
            && triangles as f64 >= MESH_TRIANGLE_SHARE * bounded as f64;
        Self {
            leaf_size: if large_mesh {
                MESH_LEAF_SIZE
            } else {
                Self::default().leaf_size
            },
            ..Self::default()
        }
    }

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

    pub(super) fn memory_budget_bytes(&self) -> u64 {
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
    /// A parameter outside [`crate::limits`] (a level past the deepest the
    /// walk's indices hold would give wrong answers, not an error).
    #[error(transparent)]
    Limit(#[from] LimitError),
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::DVec3;
    use crate::shapes::{Plane, Sphere, Triangle};

    #[test]
    fn large_meshes_get_larger_leaves_than_other_scenes() {
        let triangle = || {
            Shape::Triangle(
                Triangle::new([DVec3::ZERO, DVec3::X, DVec3::Y]).expect("a proper triangle"),
            )
        };
        let sphere = || Shape::Sphere(Sphere::new(DVec3::ZERO, 1.0));
        let plane = || Shape::Plane(Plane::new(DVec3::ZERO, DVec3::Y));
        let scene = |triangles: usize, spheres: usize, planes: usize| {
            let mut shapes: Vec<Shape> = (0..triangles).map(|_| triangle()).collect();
            shapes.extend((0..spheres).map(|_| sphere()));
            shapes.extend((0..planes).map(|_| plane()));
            OctreeParams::default_for(&shapes).leaf_size
        };
        let four = OctreeParams::default().leaf_size;
        assert_eq!(four, 4);
        let many = MESH_MIN_TRIANGLES;
        assert_eq!(scene(0, 0, 0), four);
        assert_eq!(scene(0, 0, 1), four);
        // A small mesh keeps the small leaves; a large one gets larger.
        assert_eq!(scene(many - 1, 0, 0), four);
        assert_eq!(scene(many, 0, 0), MESH_LEAF_SIZE);
        // Planes are not in the tree: they do not count.
        assert_eq!(scene(many, 0, 3), MESH_LEAF_SIZE);
        // Nine triangles in ten is a mesh; eight in ten is not.
        assert_eq!(scene(9 * many, many, 0), MESH_LEAF_SIZE);
        assert_eq!(scene(8 * many, 2 * many, 0), four);
        assert_eq!(scene(0, many, 0), four);
        // Only the leaf size depends on the shapes.
        let shapes: Vec<Shape> = (0..many).map(|_| triangle()).collect();
        assert_eq!(
            OctreeParams::default_for(&shapes),
            OctreeParams {
                leaf_size: MESH_LEAF_SIZE,
                ..OctreeParams::default()
            }
        );
    }
}
