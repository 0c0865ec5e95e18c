//! One ray's octree walk, step by step, for explaining it: which cells the
//! traversal entered (and the empty octants it passed), which primitives
//! each leaf tested with what answer, and why the walk stopped.
//!
//! The walk is told through [`Counter`](crate::stats::Counter)'s hooks,
//! called beside the counts they explain, so a [`WalkLog`] records the
//! very walk the renderer does; every other counter compiles them away.
//! Its JSON is part of `glint render --trace-pixel` (README, "A ray's walk
//! through the octree"): add fields, never rename them.

use serde::Serialize;

use crate::stats::{Counter, WorkCounts};

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
    fn cell(visit: CellVisit) -> Self {
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

/// A [`Counter`] that records each query's walk; [`Counter::take_query`]
/// hands over the one just finished and starts the next.
#[derive(Debug, Default)]
pub struct WalkLog {
    use_octree: bool,
    steps: Vec<WalkStep>,
    /// Empty octants are counted when their parent is split, before the
    /// ray reaches them: they wait here, nearest first, until a cell that
    /// starts at or after their exit is entered.
    pending_empty: Vec<WalkStep>,
    end: Option<WalkEnd>,
    counts: WorkCounts,
}

impl WalkLog {
    pub fn new(use_octree: bool) -> Self {
        Self {
            use_octree,
            ..Self::default()
        }
    }

    /// Moves the empty octants the ray has passed before `t` into the walk.
    fn flush_empty_before(&mut self, t: f64) {
        let passed = self
            .pending_empty
            .iter()
            .take_while(|s| s.t_exit.is_some_and(|exit| exit <= t))
            .count();
        self.steps.extend(self.pending_empty.drain(..passed));
    }
}

impl Counter for WalkLog {
    fn intersection_test(&mut self) {
        self.counts.intersection_test();
    }
    fn traversal_step(&mut self) {
        self.counts.traversal_step();
    }
    fn leaf_visit(&mut self) {
        self.counts.leaf_visit();
    }

    fn cell(&mut self, visit: impl FnOnce() -> CellVisit) {
        let visit = visit();
        let step = WalkStep::cell(visit);
        if visit.kind == StepKind::Empty {
            let at = self
                .pending_empty
                .partition_point(|s| s.t_enter.is_some_and(|t| t <= visit.t_enter));
            self.pending_empty.insert(at, step);
        } else {
            self.flush_empty_before(visit.t_enter);
            self.steps.push(step);
        }
    }

    fn tested(&mut self, object: u32, t: Option<f64>) {
        if !self.use_octree {
            return;
        }
        let tested = Tested {
            object,
            hit: t.is_some(),
            t,
        };
        // Tests before any cell are of the unbounded shapes.
        if self.steps.last().is_none_or(|s| s.tested.is_none()) {
            self.steps.push(WalkStep {
                kind: StepKind::Unbounded,
                depth: None,
                min: None,
                max: None,
                t_enter: None,
                t_exit: None,
                tested: Some(Vec::new()),
            });
        }
        if let Some(list) = self.steps.last_mut().and_then(|s| s.tested.as_mut()) {
            list.push(tested);
        }
    }

    fn walk_end(&mut self, end: WalkEnd) {
        self.end = Some(end);
    }

    fn take_query(&mut self) -> Option<QueryRecord> {
        // Empty octants counted but never reached (the walk stopped first)
        // still cost a step: they come last.
        let pending = std::mem::take(&mut self.pending_empty);
        self.steps.extend(pending);
        let record = QueryRecord {
            walk: self.use_octree.then(|| std::mem::take(&mut self.steps)),
            walk_end: if self.use_octree { self.end } else { None },
            intersection_tests: self.counts.intersection_tests,
            traversal_steps: self.counts.traversal_steps,
            leaves_visited: self.counts.leaves_visited,
        };
        *self = Self::new(self.use_octree);
        Some(record)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn visit(kind: StepKind, t_enter: f64, t_exit: f64) -> CellVisit {
        CellVisit {
            kind,
            depth: 1,
            min: [0.0; 3],
            side: 1.0,
            t_enter,
            t_exit,
        }
    }

    #[test]
    fn empty_octants_take_their_place_along_the_ray() {
        let mut log = WalkLog::new(true);
        log.cell(|| visit(StepKind::Inner, 0.0, 4.0));
        // Counted farthest first, when the root is split.
        log.cell(|| visit(StepKind::Empty, 3.0, 4.0));
        log.cell(|| visit(StepKind::Empty, 1.0, 2.0));
        log.cell(|| visit(StepKind::Leaf, 0.0, 1.0));
        log.tested(7, Some(0.5));
        log.tested(8, None);
        log.cell(|| visit(StepKind::Leaf, 2.0, 3.0));
        let record = log.take_query().unwrap();
        let walk = record.walk.unwrap();
        let kinds: Vec<_> = walk.iter().map(|s| (s.kind, s.t_enter.unwrap())).collect();
        assert_eq!(
            kinds,
            [
                (StepKind::Inner, 0.0),
                (StepKind::Leaf, 0.0),
                (StepKind::Empty, 1.0),
                (StepKind::Leaf, 2.0),
                (StepKind::Empty, 3.0),
            ]
        );
        assert_eq!(
            walk[1].tested.as_deref().unwrap(),
            [
                Tested {
                    object: 7,
                    hit: true,
                    t: Some(0.5)
                },
                Tested {
                    object: 8,
                    hit: false,
                    t: None
                },
            ]
        );
        assert_eq!(walk[1].max, Some([1.0; 3]));
        assert!(walk[2].tested.is_none(), "empty octants test nothing");
        // The next query starts afresh.
        assert_eq!(log.take_query().unwrap().walk.unwrap(), []);
    }

    #[test]
    fn tests_before_any_cell_are_the_unbounded_shapes() {
        let mut log = WalkLog::new(true);
        log.tested(0, Some(2.0));
        log.walk_end(WalkEnd::MissedOctree);
        let record = log.take_query().unwrap();
        let walk = record.walk.unwrap();
        assert_eq!(walk.len(), 1);
        assert_eq!(walk[0].kind, StepKind::Unbounded);
        assert_eq!(walk[0].depth, None);
        assert_eq!(record.walk_end, Some(WalkEnd::MissedOctree));
        // Without the octree there is no walk, only counts.
        let mut off = WalkLog::new(false);
        off.intersection_test();
        off.tested(0, None);
        let record = off.take_query().unwrap();
        assert_eq!((record.walk, record.intersection_tests), (None, 1));
    }
}
