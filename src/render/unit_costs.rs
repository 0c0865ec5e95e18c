//! What one traversal step, one intersection test and the rest of a ray
//! (its generation and shading) cost on this machine, measured on the
//! scene itself: with them, an octree's predicted work per ray becomes a
//! predicted render time, before the render. The work per ray comes from
//! the tree alone ([`Octree::predicted_cost`], the surface-area model) or
//! from a sample of the render's own rays ([`sample_rays`]).

use std::sync::Arc;
use std::time::Instant;

use serde::Serialize;

use crate::accel::{
    Octree, OctreeParams, PredictedCost, Primitives, WalkStack, closest_brute_force,
};
use crate::math::{Aabb, DVec3, Ray, orthonormal_basis};
use crate::shapes::{PreparedRay, Shape};
use crate::stats::{NoCounts, RenderCounts, WorkCounts};

use super::accelerator::{Accelerator, Reuse};
use super::renderer::{RenderError, Renderer};
use crate::settings::Accel;

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
    pub fn measure(renderer: &Renderer, octree: &Arc<Octree>) -> Result<Self, RenderError> {
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
        let accel = through_octree(renderer, octree)?;
        let thumbnail = thumbnail(renderer, &accel, 48)?;
        let on_one_thread = on_one_thread(&thumbnail);
        let mut counts = Default::default();
        let render_s = fastest_of_3(|| counts = on_one_thread(true));
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

/// The render `renderer` would make, at most `side` pixels on its longer
/// side and one sample per pixel, through `accel` ([`through_octree`]).
fn thumbnail<'a>(
    renderer: &Renderer<'a>,
    accel: &'a Accelerator,
    side: u32,
) -> Result<Renderer<'a>, RenderError> {
    let mut settings = renderer.settings;
    let scale = (side as f64 / settings.width.max(settings.height) as f64).min(1.0);
    settings.width = ((settings.width as f64 * scale).round() as u32).max(1);
    settings.height = ((settings.height as f64 * scale).round() as u32).max(1);
    settings.samples = 1;
    settings.adaptive = false;
    settings.accel = Accel::Octree;
    Renderer::with_camera(renderer.scene, accel, settings, &renderer.camera_spec)
}

/// `octree` (one over `renderer`'s scene) as the accelerator of its
/// thumbnails, without a light buffer: the sample measures the tree.
fn through_octree(renderer: &Renderer, octree: &Arc<Octree>) -> Result<Accelerator, RenderError> {
    let settings = crate::settings::RenderSettings {
        accel: Accel::Octree,
        ..renderer.settings
    };
    Ok(Accelerator::build(
        renderer.scene,
        &settings,
        Reuse::octree_alone(octree),
    )?)
}

/// Renders `thumbnail` (counted or not) on a pool of one thread, for
/// timings that do not depend on the machine's cores (on the caller's pool
/// if one cannot be made).
fn on_one_thread<'a>(thumbnail: &'a Renderer) -> impl Fn(bool) -> RenderCounts + 'a {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(1).build();
    move |counted| match &pool {
        Ok(pool) => pool.install(|| thumbnail.render(counted, None).1),
        Err(_) => thumbnail.render(counted, None).1,
    }
}

/// The longer side of the image [`sample_rays`] traces: 64 x 48 eye rays
/// on a 4:3 view, with their shadow and secondary rays.
pub const RAY_SAMPLE_SIDE: u32 = 64;

/// What a sample of the render's own rays does and costs through one tree.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct RaySample {
    /// Rays in the sample: eye, shadow and secondary.
    pub rays: u64,
    pub traversal_steps_per_ray: f64,
    pub intersection_tests_per_ray: f64,
    /// The sample rendered as the render runs (packets where the SIMD
    /// level has them, no counting), on one thread, the fastest of three.
    pub seconds_per_ray: f64,
    /// The time per ray of the sample at twice its side over the sample's
    /// own: a larger image's rays are more coherent (packets diverge less,
    /// neighbours share cache lines), so each doubling of the side costs
    /// less per ray (1 where the render is no larger than the sample).
    pub per_doubling: f64,
    /// Doublings from the sample's side to the render's, the render's
    /// side taken times the square root of its samples per pixel (their
    /// rays are as close as a larger image's).
    pub doublings: f64,
}

impl RaySample {
    /// The sample's time per ray carried to the render's size.
    pub fn seconds_per_ray_at_render(&self) -> f64 {
        self.seconds_per_ray * self.per_doubling.powf(self.doublings)
    }

    /// A render of `rays` rays on `threads` threads (taken as scaling
    /// perfectly), at the sample's time per ray.
    pub fn predict(&self, rays: u64, threads: usize) -> Prediction {
        Prediction {
            traversal_steps_per_ray: self.traversal_steps_per_ray,
            intersection_tests_per_ray: self.intersection_tests_per_ray,
            render_s: rays as f64 * self.seconds_per_ray_at_render() / threads.max(1) as f64,
        }
    }
}

/// A sample of the render's own rays through `octree`: the render
/// `renderer` would make, at most [`RAY_SAMPLE_SIDE`] pixels a side and one
/// sample per pixel, traced once with the walk's counters (the work per
/// ray) and timed as the render runs. Unlike the surface-area model it
/// sees what the view does: rays that stop at their first hit, that miss
/// the scene's box, that gather on the small part of the scene in view,
/// shadow rays that stop at the first blocker, the mailbox, and what
/// shading and packets cost on this machine. The pixel grid is coarser
/// than the render's, so edges weigh a little more. The counts are the
/// same on any number of threads; the time is taken on one.
pub fn sample_rays(renderer: &Renderer, octree: &Arc<Octree>) -> Result<RaySample, RenderError> {
    sample_rays_with(renderer, octree, None)
}

/// Bounds on [`RaySample::per_doubling`], against timing noise.
const PER_DOUBLING_RANGE: (f64, f64) = (0.5, 1.0);

/// [`sample_rays`], with the time per ray's change per doubling of the
/// side given (measured once for a scene and view, it holds for its other
/// trees: [`suggest_octree`]) or, when `None`, measured on a second
/// thumbnail at twice the side.
pub fn sample_rays_with(
    renderer: &Renderer,
    octree: &Arc<Octree>,
    per_doubling: Option<f64>,
) -> Result<RaySample, RenderError> {
    let accel = through_octree(renderer, octree)?;
    let thumbnail = thumbnail(renderer, &accel, RAY_SAMPLE_SIDE)?;
    let seconds_per_ray = |thumbnail: &Renderer| {
        let on_one_thread = on_one_thread(thumbnail);
        let mut rays = 0;
        let seconds = fastest_of_3(|| {
            rays = on_one_thread(false).rays.total();
        });
        seconds / rays.max(1) as f64
    };
    let counts = on_one_thread(&thumbnail)(true);
    let rays = counts.rays.total();
    let per_ray = |x: u64| x as f64 / rays.max(1) as f64;
    let side = |s: &crate::settings::RenderSettings| s.width.max(s.height) as f64;
    let render_side = side(&renderer.settings) * (renderer.settings.samples.max(1) as f64).sqrt();
    let doublings = (render_side / side(&thumbnail.settings)).log2().max(0.0);
    let seconds = seconds_per_ray(&thumbnail);
    let per_doubling = match per_doubling {
        Some(p) => p,
        None if doublings > 0.0 => {
            // Twice the side, or the render's own if that is smaller.
            let larger = self::thumbnail(renderer, &accel, 2 * RAY_SAMPLE_SIDE)?;
            let steps = (side(&larger.settings) / side(&thumbnail.settings)).log2();
            if steps < 0.5 {
                1.0
            } else {
                let ratio = seconds_per_ray(&larger) / seconds.max(f64::MIN_POSITIVE);
                ratio
                    .powf(1.0 / steps)
                    .clamp(PER_DOUBLING_RANGE.0, PER_DOUBLING_RANGE.1)
            }
        }
        None => 1.0,
    };
    Ok(RaySample {
        rays,
        traversal_steps_per_ray: per_ray(counts.work.traversal_steps),
        intersection_tests_per_ray: per_ray(counts.work.intersection_tests),
        seconds_per_ray: seconds,
        per_doubling,
        doublings,
    })
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
/// render, predicted from the tree alone and from a sample of the render's
/// rays.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct OctreeCandidate {
    pub params: OctreeParams,
    pub build_s: f64,
    pub predicted: Prediction,
    pub predicted_from_rays: Prediction,
}

impl OctreeCandidate {
    /// What the suggestion minimises: the build and the render predicted
    /// from the sample of rays (docs/speed-and-accuracy.md, "Predicting an
    /// octree's cost": it ranks settings across scenes, where the tree
    /// alone ranks them only within one).
    pub fn predicted_total_s(&self) -> f64 {
        self.build_s + self.predicted_from_rays.render_s
    }
}

/// The maximum depths and leaf sizes [`suggest_octree`] tries (with the
/// scene's other parameters): the SPD scenes' best settings lie inside.
pub const SUGGESTION_DEPTHS: [u32; 5] = [4, 6, 8, 10, 12];
pub const SUGGESTION_LEAF_SIZES: [u32; 5] = [1, 2, 4, 8, 16];

/// Builds the octree at every setting of the suggestion grid and predicts
/// the render `renderer` makes (`rays` rays): every candidate, and the
/// index of the one with the least build plus predicted render time. Of
/// the render it traces only [`sample_rays`]'s thumbnail per candidate.
/// `keep_going` is asked between builds (the viewer cancels through it).
pub fn suggest_octree(
    renderer: &Renderer,
    costs: &UnitCosts,
    rays: u64,
    threads: usize,
    keep_going: &dyn Fn() -> bool,
) -> Option<(Vec<OctreeCandidate>, usize)> {
    let base = renderer.scene.octree_params;
    let mut candidates = Vec::new();
    let mut per_doubling = None;
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
            let Ok(octree) = Octree::build(&renderer.scene.shapes, params).map(Arc::new) else {
                continue;
            };
            let build_s = start.elapsed().as_secs_f64();
            let Ok(sample) = sample_rays_with(renderer, &octree, per_doubling) else {
                continue;
            };
            // Measured on the first tree, it holds for the others.
            per_doubling = Some(sample.per_doubling);
            candidates.push(OctreeCandidate {
                params,
                build_s,
                predicted: costs.predict(octree.predicted_cost(), rays, threads),
                predicted_from_rays: sample.predict(rays, threads),
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::CameraSpec;
    use crate::material::{Light, Material};
    use crate::scene::{ImageSettings, Scene};
    use crate::shapes::Sphere;

    /// A 6x6x6 lattice of small spheres around the origin, seen from
    /// `eye` looking at `lookat`, `width` x `height` pixels.
    fn lattice(eye: DVec3, lookat: DVec3, width: u32, height: u32) -> Scene {
        let mut scene = Scene::empty(
            "lattice".into(),
            CameraSpec {
                eye,
                lookat,
                up: DVec3::Y,
                fov: 40.0,
            },
            ImageSettings {
                width,
                height,
                samples: 1,
                max_depth: 3,
                ..ImageSettings::default()
            },
        );
        scene.materials = vec![Material {
            reflectivity: 0.3,
            ..Material::default()
        }];
        scene.lights = vec![Light {
            position: DVec3::new(4.0, 9.0, 7.0),
            color: DVec3::ONE,
        }];
        for i in 0..216 {
            let p = DVec3::new((i % 6) as f64, (i / 6 % 6) as f64, (i / 36) as f64) - 2.5;
            scene.push(Shape::Sphere(Sphere::new(p, 0.3)), 0);
        }
        scene
    }

    #[test]
    fn the_ray_sample_of_a_thumbnail_sized_render_is_that_render() {
        // At 40x30 and one sample the thumbnail is the render itself: the
        // sample's work per ray is the counted render's, exactly.
        let scene = lattice(DVec3::new(3.0, 4.0, 12.0), DVec3::ZERO, 40, 30);
        let accel = crate::render::Accelerator::of_octree(&scene, scene.build_octree().unwrap());
        let renderer = Renderer::new(&scene, &accel, scene.render_settings()).unwrap();
        let counts = renderer.render(true, None).1;
        let rays = counts.rays.total() as f64;
        let sample = sample_rays(&renderer, accel.octree().unwrap()).unwrap();
        assert_eq!(sample.rays, counts.rays.total());
        assert_eq!(
            sample.traversal_steps_per_ray,
            counts.work.traversal_steps as f64 / rays
        );
        assert_eq!(
            sample.intersection_tests_per_ray,
            counts.work.intersection_tests as f64 / rays
        );
        assert!(sample.intersection_tests_per_ray > 0.0);
        // Nothing to carry to a larger size.
        assert_eq!((sample.doublings, sample.per_doubling), (0.0, 1.0));
        assert_eq!(sample.seconds_per_ray_at_render(), sample.seconds_per_ray);
    }

    #[test]
    fn the_ray_sample_is_carried_to_the_render_size_by_the_doublings_of_its_side() {
        // 320 pixels a side is 320 / 64 = 5 times the sample's, and 16
        // samples per pixel are 4 times more rays a side again.
        let scene = lattice(DVec3::new(3.0, 4.0, 12.0), DVec3::ZERO, 320, 240);
        let accel = crate::render::Accelerator::of_octree(&scene, scene.build_octree().unwrap());
        let mut settings = scene.render_settings();
        settings.samples = 16;
        let renderer = Renderer::new(&scene, &accel, settings).unwrap();
        let sample = sample_rays(&renderer, accel.octree().unwrap()).unwrap();
        assert!(
            (sample.doublings - 20f64.log2()).abs() < 1e-12,
            "{sample:?}"
        );
        assert!((0.5..=1.0).contains(&sample.per_doubling), "{sample:?}");
        let carried = sample.seconds_per_ray * sample.per_doubling.powf(sample.doublings);
        assert_eq!(sample.seconds_per_ray_at_render(), carried);
        assert_eq!(sample.predict(1000, 2).render_s, 1000.0 * carried / 2.0);
        // A factor given is used as given.
        let given = sample_rays_with(&renderer, accel.octree().unwrap(), Some(0.75)).unwrap();
        assert_eq!(given.per_doubling, 0.75);
    }

    #[test]
    fn the_ray_sample_sees_what_the_view_does_and_the_tree_alone_cannot() {
        // The same tree seen from a camera that looks away from it: no ray
        // reaches its box, so the sample counts no work at all, while the
        // surface-area model (view-independent) predicts the same as
        // before. Seen square on, the sample counts work, and fewer tests
        // per ray than the model's upper bound (rays stop at their first
        // hit).
        let towards = lattice(DVec3::new(3.0, 4.0, 12.0), DVec3::ZERO, 320, 240);
        let away = lattice(
            DVec3::new(3.0, 4.0, 12.0),
            DVec3::new(3.0, 4.0, 20.0),
            320,
            240,
        );
        let accel =
            crate::render::Accelerator::of_octree(&towards, towards.build_octree().unwrap());
        let sample = |scene: &Scene| {
            let renderer = Renderer::new(scene, &accel, scene.render_settings()).unwrap();
            sample_rays(&renderer, accel.octree().unwrap()).unwrap()
        };
        let (seen, unseen) = (sample(&towards), sample(&away));
        assert_eq!(unseen.traversal_steps_per_ray, 0.0);
        assert_eq!(unseen.intersection_tests_per_ray, 0.0);
        let model = accel.octree().unwrap().predicted_cost();
        assert!(seen.intersection_tests_per_ray > 0.0);
        assert!(
            seen.intersection_tests_per_ray < model.intersection_tests_per_ray,
            "{seen:?} {model:?}"
        );
    }
}
