//! Work counters. Tracing is generic over [`Counter`]: with [`NoCounts`]
//! every increment compiles to nothing, so counting costs only when asked for.
//! [`RenderCounts`] gathers what a render counted, tile by tile and in all.

pub mod published;
pub mod walk_record;

use walk_record::{CellVisit, QueryRecord, WalkEnd};

/// Receives one call per unit of work done for a ray.
pub trait Counter {
    /// Whether anything is counted. Havran's measures are the exact
    /// octree walk's, so only a counter that counts nothing lets a query
    /// take the faster wide walk (the same answers, other cells).
    const COUNTS: bool = true;
    #[inline(always)]
    fn intersection_test(&mut self) {}
    #[inline(always)]
    fn traversal_step(&mut self) {}
    #[inline(always)]
    fn leaf_visit(&mut self) {}
    /// Adds work counted elsewhere (the cost view counts per pixel).
    #[inline(always)]
    fn add_work(&mut self, _work: &WorkCounts) {}
    /// The same unit of work for `n` rays of a packet at once.
    #[inline(always)]
    fn add_lanes(&mut self, _tests: u32, _steps: u32, _leaves: u32) {}
    /// The walk entered a cell (or passed an empty octant); called beside
    /// `traversal_step`. Only [`WalkLog`](crate::accel::WalkLog) builds the visit.
    #[inline(always)]
    fn cell(&mut self, _visit: impl FnOnce() -> CellVisit) {}
    /// Shape `object` was tested, beside `intersection_test`: where the ray
    /// meets it, or `None`.
    #[inline(always)]
    fn tested(&mut self, _object: u32, _t: Option<f64>) {}
    /// Why the walk stopped.
    #[inline(always)]
    fn walk_end(&mut self, _end: WalkEnd) {}
    /// The query just finished, for explaining it ([`WalkLog`](crate::accel::WalkLog) only).
    #[inline(always)]
    fn take_query(&mut self) -> Option<QueryRecord> {
        None
    }
}

/// Counts nothing; the default.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoCounts;

impl Counter for NoCounts {
    const COUNTS: bool = false;
}

/// Havran's machine-independent measures, summed over rays: intersection
/// tests (N_IT), traversal steps, i.e. octree nodes entered (N_TS), and
/// leaves entered (N_ETS).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct WorkCounts {
    pub intersection_tests: u64,
    pub traversal_steps: u64,
    pub leaves_visited: u64,
}

impl Counter for WorkCounts {
    #[inline(always)]
    fn intersection_test(&mut self) {
        self.intersection_tests += 1;
    }
    #[inline(always)]
    fn traversal_step(&mut self) {
        self.traversal_steps += 1;
    }
    #[inline(always)]
    fn leaf_visit(&mut self) {
        self.leaves_visited += 1;
    }
    #[inline(always)]
    fn add_work(&mut self, work: &WorkCounts) {
        *self += *work;
    }
    #[inline(always)]
    fn add_lanes(&mut self, tests: u32, steps: u32, leaves: u32) {
        self.intersection_tests += tests as u64;
        self.traversal_steps += steps as u64;
        self.leaves_visited += leaves as u64;
    }
}

impl std::ops::AddAssign for WorkCounts {
    fn add_assign(&mut self, o: Self) {
        self.intersection_tests += o.intersection_tests;
        self.traversal_steps += o.traversal_steps;
        self.leaves_visited += o.leaves_visited;
    }
}

/// Rays cast, by kind.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct RayCounts {
    pub primary: u64,
    pub primary_hits: u64,
    pub shadow: u64,
    pub reflection: u64,
    pub refraction: u64,
    /// Refractions that failed (total internal reflection): no refraction
    /// ray was cast, the reflection ray took its weight. Not rays, so not
    /// in [`RayCounts::total`].
    pub total_internal_reflections: u64,
}

impl RayCounts {
    pub fn total(&self) -> u64 {
        self.primary + self.shadow + self.reflection + self.refraction
    }
}

impl std::ops::AddAssign for RayCounts {
    fn add_assign(&mut self, o: Self) {
        self.primary += o.primary;
        self.primary_hits += o.primary_hits;
        self.shadow += o.shadow;
        self.reflection += o.reflection;
        self.refraction += o.refraction;
        self.total_internal_reflections += o.total_internal_reflections;
    }
}

/// What a render counted: rays by kind, Havran's work measures, and the
/// samples that went wrong. Each tile counts its own; a pass and a whole
/// frame sum them in tile order, so totals never depend on the threads.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RenderCounts {
    pub rays: RayCounts,
    pub work: WorkCounts,
    /// Samples whose colour came out NaN or infinite (then shown black).
    /// Always zero unless something is wrong: tests assert it.
    pub nonfinite_samples: u64,
    /// Pixels adaptive anti-aliasing refined with the full grid.
    pub refined_pixels: u64,
}

impl std::ops::AddAssign for RenderCounts {
    fn add_assign(&mut self, o: Self) {
        self.refined_pixels += o.refined_pixels;
        self.rays += o.rays;
        self.work += o.work;
        self.nonfinite_samples += o.nonfinite_samples;
    }
}
