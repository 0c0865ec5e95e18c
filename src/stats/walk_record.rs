//! One ray's octree walk as recorded: the steps, why it ended, and the
//! query's Havran counts. [`WalkLog`](crate::accel::WalkLog) records them
//! through [`Counter`](crate::stats::Counter)'s hooks; this file holds the
//! records alone, so the counter and the octree can both name them.
//! Their JSON is part of `glint render --trace-pixel` (docs/inspection.md, "A
//! ray's walk through the octree"): add fields, never rename them.

use serde::Serialize;

/// What kind of step the walk took.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum StepKind {
    /// An inner node: the ray is split among the children it crosses.
    Inner,
    /// A leaf: its primitives are tested.
    Leaf,
    /// An empty octant the ray crosses: counted as entered (Havran's
    /// measure), nothing stored, nothing tested.
    Empty,
    /// A leaf the ray crosses outside the box of what it holds: counted
    /// as entered, nothing tested.
    Missed,
    /// Before the walk, the shapes without bounds (infinite planes),
    /// which no cell holds.
    Unbounded,
}

/// A cell as the walk enters it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CellVisit {
    pub kind: StepKind,
    /// Depth in the tree: the root is 0.
    pub depth: u32,
    pub min: [f64; 3],
    pub side: f64,
    /// The ray's parameters where it enters and leaves the cell.
    pub t_enter: f64,
    pub t_exit: f64,
}

/// Why a walk ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum WalkEnd {
    /// A hit nearer than the exit of the leaf it was found in: nothing
    /// further along can be nearer.
    HitInCell,
    /// The cells left to visit all start beyond the nearest hit.
    CellsBeyondHit,
    /// A shadow ray met an opaque surface: the light is blocked.
    Blocked,
    /// The cells left to visit all start beyond the light.
    CellsBeyondLight,
    /// The ray left the octree's root cell with no cell left to visit.
    LeftOctree,
    /// The ray never enters the octree's root cell (or the tree is empty).
    MissedOctree,
}

/// One primitive a step tested.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Tested {
    /// Index of the shape in the scene's shape list.
    pub object: u32,
    pub hit: bool,
    /// Where the ray meets it (the nearest crossing before the current
    /// limit), `null` on a miss.
    pub t: Option<f64>,
}

/// One step of a walk, as `--trace-pixel` prints it.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WalkStep {
    pub kind: StepKind,
    /// `null` for the unbounded shapes' step, as are the cell fields.
    pub depth: Option<u32>,
    pub min: Option<[f64; 3]>,
    pub max: Option<[f64; 3]>,
    pub t_enter: Option<f64>,
    pub t_exit: Option<f64>,
    /// The primitives tested, in order (leaves and the unbounded step; a
    /// primitive the ray's mailbox had tested already is not tested again).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub tested: Option<Vec<Tested>>,
}

impl WalkStep {
    pub(crate) fn cell(visit: CellVisit) -> Self {
        let max = visit.min.map(|m| m + visit.side);
        Self {
            kind: visit.kind,
            depth: Some(visit.depth),
            min: Some(visit.min),
            max: Some(max),
            t_enter: Some(visit.t_enter),
            t_exit: Some(visit.t_exit),
            tested: (visit.kind == StepKind::Leaf).then(Vec::new),
        }
    }
}

/// What one ray query did: its walk (`null` with the octree off, when
/// every primitive is tested in index order), why the walk ended, and
/// Havran's counts for this ray alone.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct QueryRecord {
    pub walk: Option<Vec<WalkStep>>,
    pub walk_end: Option<WalkEnd>,
    pub intersection_tests: u64,
    pub traversal_steps: u64,
    pub leaves_visited: u64,
}
