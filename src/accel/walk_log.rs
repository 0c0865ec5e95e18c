//! One ray's octree walk, step by step, for explaining it: which cells the
//! traversal entered (and the empty octants it passed), which primitives
//! each leaf tested with what answer, and why the walk stopped.
//!
//! The walk is told through [`Counter`](crate::stats::Counter)'s hooks,
//! called beside the counts they explain, so a [`WalkLog`] records the
//! very walk the renderer does; every other counter compiles them away.

use crate::stats::walk_record::{CellVisit, QueryRecord, StepKind, Tested, WalkEnd, WalkStep};
use crate::stats::{Counter, WorkCounts};

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
