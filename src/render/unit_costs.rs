//! What one traversal step, one intersection test and the rest of a ray
//! (its generation and shading) cost on this machine, measured on the
//! scene itself: with them, an octree's [predicted
//! cost](crate::accel::Octree::predicted_cost) becomes a predicted render
//! time, before the render.

use std::time::Instant;

use serde::Serialize;

use crate::accel::{
    Octree, OctreeParams, PredictedCost, Primitives, WalkStack, closest_brute_force,
};
use crate::math::{Aabb, DVec3, Ray, orthonormal_basis};
use crate::shapes::{PreparedRay, Shape};
use crate::stats::{NoCounts, WorkCounts};

use super::renderer::{RenderError, Renderer};

/// Nanoseconds per unit of work, on one thread.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct UnitCosts {
    pub step_ns: f64,
    pub test_ns: f64,
    /// Everything else a ray costs: generating it, shading its hit.
    pub ray_ns: f64,
}

/// A predicted render: the work per ray from the tree alone and the time
/// it would take at these unit costs.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct Prediction {
    pub traversal_steps_per_ray: f64,
    pub intersection_tests_per_ray: f64,
    pub render_s: f64,
}

impl UnitCosts {
    /// Measures the costs on one thread: intersection tests by brute force
    /// over up to 64 of the scene's shapes, traversal steps by walking
    /// `octree` with random lines (less their tests), and the rest of a
    /// ray from a thumbnail render of the scene (less its steps and
    /// tests). Takes some tens of milliseconds.
    pub fn measure(renderer: &Renderer, octree: &Octree) -> Result<Self, RenderError> {
        let shapes = &renderer.scene.shapes;
        let lines: Vec<PreparedRay> = random_lines(octree.bounds(), 2048)
            .into_iter()
            .map(PreparedRay::new)
            .collect();
        let sample: Vec<Shape> = if shapes.len() <= 64 {
            shapes.to_vec()
        } else {
            (0..64)
                .map(|i| shapes[i * shapes.len() / 64].clone())
                .collect()
        };
        let test_ns = if sample.is_empty() {
            0.0
        } else {
            let prims = Primitives::opaque(&sample);
            let seconds = fastest_of_3(|| {
                for ray in &lines {
                    std::hint::black_box(closest_brute_force(
                        &prims,
                        ray,
                        f64::INFINITY,
                        &mut NoCounts,
                    ));
                }
            });
            seconds * 1e9 / (lines.len() * sample.len()) as f64
        };
        let prims = Primitives::opaque(shapes);
        let mut stack = WalkStack::default();
        let mut walked = WorkCounts::default();
        let walk_s = fastest_of_3(|| {
            walked = WorkCounts::default();
            for ray in &lines {
                std::hint::black_box(octree.closest(
                    &prims,
                    ray,
                    f64::INFINITY,
                    &mut stack,
                    &mut walked,
                ));
            }
        });
        let step_ns = positive(walk_s * 1e9 - walked.intersection_tests as f64 * test_ns)
            / walked.traversal_steps.max(1) as f64;

        // A thumbnail of the render, one thread, for what else a ray costs.
        let mut settings = renderer.settings;
        let scale = (48.0 / settings.width.max(settings.height) as f64).min(1.0);
        settings.width = ((settings.width as f64 * scale).round() as u32).max(1);
        settings.height = ((settings.height as f64 * scale).round() as u32).max(1);
        settings.samples = 1;
        settings.adaptive = false;
        let thumbnail =
            Renderer::with_camera(renderer.scene, octree, settings, &renderer.camera_spec)?;
        let one_thread = rayon::ThreadPoolBuilder::new().num_threads(1).build();
        let mut counts = Default::default();
        let render_s = fastest_of_3(|| {
            counts = match &one_thread {
                Ok(pool) => pool.install(|| thumbnail.render(true, None).1),
                Err(_) => thumbnail.render(true, None).1,
            };
        });
        let rays = counts.rays.total().max(1) as f64;
        let work = counts.work;
        let ray_ns = positive(
            render_s * 1e9
                - work.traversal_steps as f64 * step_ns
                - work.intersection_tests as f64 * test_ns,
        ) / rays;
        Ok(Self {
            step_ns,
            test_ns,
            ray_ns,
        })
    }

    /// The render time of `rays` rays at `cost` per ray on `threads`
    /// threads (taken as scaling perfectly).
    pub fn predict(&self, cost: PredictedCost, rays: u64, threads: usize) -> Prediction {
        let per_ray_ns = self.ray_ns
            + cost.traversal_steps_per_ray * self.step_ns
            + cost.intersection_tests_per_ray * self.test_ns;
        Prediction {
            traversal_steps_per_ray: cost.traversal_steps_per_ray,
            intersection_tests_per_ray: cost.intersection_tests_per_ray,
            render_s: rays as f64 * per_ray_ns * 1e-9 / threads.max(1) as f64,
        }
    }
}

fn positive(x: f64) -> f64 {
    if x > 0.0 { x } else { 0.0 }
}

/// The shortest of three timed runs of `work` (the least disturbed).
fn fastest_of_3(mut work: impl FnMut()) -> f64 {
    (0..3)
        .map(|_| {
            let start = Instant::now();
            work();
            start.elapsed().as_secs_f64()
        })
        .fold(f64::INFINITY, f64::min)
}

/// `count` isotropic random lines near `bounds` (Crofton's measure: a
/// uniform direction, then a uniform point of the plane across it, within
/// the box's diagonal of its centre), as rays starting outside it.
/// Deterministic.
pub fn random_lines(bounds: Aabb, count: usize) -> Vec<Ray> {
    if bounds.is_empty() {
        return Vec::new();
    }
    let (centre, reach) = (
        bounds.center(),
        (bounds.max - bounds.min).length().max(1e-300),
    );
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut uniform = move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    };
    (0..count)
        .map(|_| {
            let z = 2.0 * uniform() - 1.0;
            let phi = std::f64::consts::TAU * uniform();
            let r = (1.0 - z * z).max(0.0).sqrt();
            let dir = DVec3::new(r * phi.cos(), r * phi.sin(), z);
            let (u, v) = orthonormal_basis(dir);
            let (a, b) = (
                reach * (2.0 * uniform() - 1.0),
                reach * (2.0 * uniform() - 1.0),
            );
            Ray::new(centre + a * u + b * v - 2.0 * reach * dir, dir)
        })
        .collect()
}

/// One octree setting tried for a suggestion: its build, timed, and its
/// render, predicted.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct OctreeCandidate {
    pub params: OctreeParams,
    pub build_s: f64,
    pub predicted: Prediction,
}

impl OctreeCandidate {
    /// What the suggestion minimises.
    pub fn predicted_total_s(&self) -> f64 {
        self.build_s + self.predicted.render_s
    }
}

/// The maximum depths and leaf sizes [`suggest_octree`] tries (with the
/// scene's other parameters): the SPD scenes' best settings lie inside.
pub const SUGGESTION_DEPTHS: [u32; 5] = [4, 6, 8, 10, 12];
pub const SUGGESTION_LEAF_SIZES: [u32; 5] = [1, 2, 4, 8, 16];

/// Builds the octree at every setting of the suggestion grid and predicts
/// its render of `rays` rays: every candidate, and the index of the one
/// with the least build plus predicted render time. Renders nothing.
/// `keep_going` is asked between builds (the viewer cancels through it).
pub fn suggest_octree(
    shapes: &[Shape],
    base: OctreeParams,
    costs: &UnitCosts,
    rays: u64,
    threads: usize,
    keep_going: &dyn Fn() -> bool,
) -> Option<(Vec<OctreeCandidate>, usize)> {
    let mut candidates = Vec::new();
    for max_depth in SUGGESTION_DEPTHS {
        for leaf_size in SUGGESTION_LEAF_SIZES {
            if !keep_going() {
                return None;
            }
            let params = OctreeParams {
                max_depth,
                leaf_size,
                ..base
            };
            let start = Instant::now();
            // Over the budget a build is refused: not a candidate.
            let Ok(octree) = Octree::build(shapes, params) else {
                continue;
            };
            candidates.push(OctreeCandidate {
                params,
                build_s: start.elapsed().as_secs_f64(),
                predicted: costs.predict(octree.predicted_cost(), rays, threads),
            });
        }
    }
    let best = (0..candidates.len()).min_by(|&a, &b| {
        candidates[a]
            .predicted_total_s()
            .total_cmp(&candidates[b].predicted_total_s())
    })?;
    Some((candidates, best))
}
