//! `glint bench`'s measurement of one scene: the octree on against brute
//! force, interleaved repeats, medians, and the cost the tree predicts;
//! its JSON record ([`SceneBench`]) is `glint bench --format json`'s.

use std::sync::Arc;
use std::time::Instant;

use serde::Serialize;

use crate::accel::{Bvh, BvhStats, LightBufferStats, OctreeError, OctreeParams, OctreeStats};
use crate::render::{
    Accelerator, LightBufferSource, Prediction, RenderError, Renderer, Reuse, UnitCosts,
    sample_rays,
};
use crate::scene::Scene;
use crate::settings::{Accel, Protocol, RenderSettings};
use crate::simd::SimdLevel;
use crate::stats::published::SpdCounts;
use crate::stats::{RayCounts, RenderCounts};

/// One configuration's medians.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct Timing {
    /// Seconds for the whole image (for a row subset: scaled up, see `estimated`).
    pub render_s: f64,
    pub mrays_per_s: f64,
    pub intersection_tests_per_ray: f64,
    pub traversal_steps_per_ray: f64,
    pub leaves_visited_per_ray: f64,
    pub estimated: bool,
}

/// The JSON record of one scene; field names are a public interface.
#[derive(Clone, Debug, Serialize)]
pub struct SceneBench {
    pub scene: String,
    pub shapes: usize,
    pub width: u32,
    pub height: u32,
    pub samples: u32,
    pub max_depth: u32,
    pub threads: usize,
    /// The SIMD level the packets ran at (`glint info --simd` says why).
    pub simd: SimdLevel,
    pub repeats: u32,
    pub load_s: f64,
    pub build_s: f64,
    pub octree_params: OctreeParams,
    pub octree_stats: OctreeStats,
    pub octree_on: Timing,
    /// `octree_on` as predicted from the tree alone (docs/speed-and-accuracy.md,
    /// "Predicting an octree's cost"), at `unit_costs`.
    pub predicted: Prediction,
    /// `octree_on` as predicted from a sample of the render's own rays (a
    /// 64-pixel thumbnail traced through the tree, counted and timed).
    pub predicted_from_rays: Prediction,
    pub unit_costs: UnitCosts,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub octree_off: Option<Timing>,
    /// With `--accel bvh`: the same render through a BVH.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bvh: Option<BvhBench>,
    /// The light buffer that `octree_on`'s and `bvh`'s shadow rays asked
    /// first (shadows on; not for brute force, nor the counted passes):
    /// its build (median of the repeats, not in `build_s`) and what it
    /// holds.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub light_buffer: Option<LightBufferBench>,
    /// Brute force time over octree time, measured on the same rays.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub speedup: Option<f64>,
    /// Rows traced by the brute-force comparison: every n-th (1 = all).
    pub compared_rows_every: u32,
    /// Render time with work counting on over off (octree on, whole image).
    /// Counted renders trace single rays, uncounted ones packets where the
    /// SIMD level has them: the ratio is what `--stats` costs.
    pub counting_overhead: f64,
    /// Rays the image needs (all kinds).
    pub rays_total: u64,
    /// Rays by kind (eye rays, those that hit, shadow, reflection, refraction).
    pub rays: RayCounts,
    pub protocol: Protocol,
    /// The SPD's published counts for this scene (default SPD scenes at
    /// 512x512 under `--protocol spd` only).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub published: Option<SpdCounts>,
}

/// A light buffer's build (median of the repeats) and what it holds.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct LightBufferBench {
    pub build_s: f64,
    #[serde(flatten)]
    pub stats: LightBufferStats,
}

/// How a scene is benchmarked, besides its render settings.
/// A BVH's figures beside the octree's: its build (median of the
/// repeats), what it made, and its render's time and work counts.
#[derive(Clone, Copy, Debug, Serialize)]
pub struct BvhBench {
    pub build_s: f64,
    pub bvh_stats: BvhStats,
    #[serde(flatten)]
    pub timing: Timing,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BenchOptions {
    /// Timed runs of each configuration (at least 1); medians are reported.
    pub repeat: u32,
    /// Brute force traces at most about this many shape tests per repeat;
    /// beyond it, an evenly spaced subset of rows.
    pub brute_force_budget: f64,
    /// Time the octree only: no brute-force comparison.
    pub octree_only: bool,
    /// Also time the render through a BVH ([`SceneBench::bvh`]).
    pub bvh: bool,
}

#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    #[error(transparent)]
    Octree(#[from] OctreeError),
    #[error(transparent)]
    Render(#[from] RenderError),
    #[error("no repeats")]
    NoRepeats,
    /// The caller's `stop` said so, between two timed passes.
    #[error("the benchmark was stopped")]
    Stopped,
}

/// The median of timings: the middle one, or the mean of the middle two
/// (`NaN` for none).
pub fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    match n {
        0 => f64::NAN,
        _ if n % 2 == 1 => v[n / 2],
        _ => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    }
}

/// "4 min 20 s", "12 s", "0.3 s": a time left as a person reads it.
pub fn duration_text(seconds: f64) -> String {
    if seconds < 10.0 {
        format!("{seconds:.1} s")
    } else if seconds < 60.0 {
        format!("{seconds:.0} s")
    } else {
        let whole = seconds.round() as u64;
        format!("{} min {} s", whole / 60, whole % 60)
    }
}

fn timed<T>(f: impl FnOnce() -> T) -> (T, f64) {
    let start = Instant::now();
    let out = f();
    (out, start.elapsed().as_secs_f64())
}

/// Sees a benchmark run; both methods have defaults that do nothing.
pub trait BenchWatch {
    /// How far the benchmark got, one line for a person to read.
    fn say(&self, _line: &str) {}
    /// Asked before each timed pass: `true` ends the benchmark with
    /// [`BenchError::Stopped`].
    fn stop(&self) -> bool {
        false
    }
}

/// Watches nothing.
impl BenchWatch for () {}

/// Benchmarks `scene` (named `scene_name` as the user gave it, loaded in
/// `load_s` seconds) at `settings` on `pool`: builds its octree `repeat`
/// times, renders with it and by brute force, interleaved, telling `watch`.
pub fn bench_scene(
    scene: &Scene,
    scene_name: &str,
    load_s: f64,
    settings: RenderSettings,
    options: BenchOptions,
    pool: &rayon::ThreadPool,
    watch: &dyn BenchWatch,
) -> Result<SceneBench, BenchError> {
    let threads = pool.current_num_threads();
    let check = || {
        if watch.stop() {
            Err(BenchError::Stopped)
        } else {
            Ok(())
        }
    };
    let say = |line: String| watch.say(&line);
    let mut build_times = Vec::new();
    let mut octree = None;
    for _ in 0..options.repeat {
        check()?;
        let (tree, s) = timed(|| pool.install(|| scene.build_octree()));
        build_times.push(s);
        octree = Some(tree?);
    }
    let Some(octree) = octree else {
        return Err(BenchError::NoRepeats);
    };

    let through = |accel| {
        let mut s = settings;
        s.accel = accel;
        s
    };
    let (on, off) = (through(Accel::Octree), through(Accel::BruteForce));
    let mut bvh_build_times = Vec::new();
    let mut bvh = None;
    if options.bvh {
        for _ in 0..options.repeat {
            check()?;
            let (tree, s) = timed(|| pool.install(|| Bvh::build(&scene.shapes)));
            bvh_build_times.push(s);
            bvh = Some(Arc::new(tree));
        }
    }
    // The octree's accelerator `repeat` times, for the light buffer's
    // build time (the tree is reused); the BVH's shares its buffer.
    let octree = Arc::new(octree);
    let mut light_buffer_times = Vec::new();
    let mut accel_on = None;
    for _ in 0..options.repeat {
        check()?;
        let reuse = Reuse {
            octree: Some(Arc::clone(&octree)),
            ..Reuse::default()
        };
        let built = pool.install(|| Accelerator::build(scene, &on, reuse))?;
        light_buffer_times.push(built.build_seconds().1);
        accel_on = Some(built);
    }
    let Some(accel_on) = accel_on else {
        return Err(BenchError::NoRepeats);
    };
    let accel_off = Accelerator::build(scene, &off, Reuse::default())?;
    let accel_bvh = bvh
        .map(|tree| {
            let light_buffer = match accel_on.shared_light_buffer() {
                Some(b) => LightBufferSource::Given(Some(Arc::clone(b))),
                None => LightBufferSource::Build,
            };
            let reuse = Reuse {
                bvh: Some(tree),
                light_buffer,
                ..Reuse::default()
            };
            pool.install(|| Accelerator::build(scene, &through(Accel::Bvh), reuse))
        })
        .transpose()?;
    let renderer_on = Renderer::new(scene, &accel_on, on)?;
    let renderer_off = Renderer::new(scene, &accel_off, off)?;
    let renderer_bvh = accel_bvh
        .as_ref()
        .map(|a| Renderer::new(scene, a, through(Accel::Bvh)))
        .transpose()?;
    check()?;
    let counted_bvh = renderer_bvh
        .as_ref()
        .map(|r| pool.install(|| r.render(true, None).1));
    let unit_costs = UnitCosts::measure(&renderer_on, &octree)?;
    let ray_sample = sample_rays(&renderer_on, &octree)?;

    // One counted pass of each for the machine-independent figures.
    check()?;
    let (counted_on, counted_s) = timed(|| pool.install(|| renderer_on.render(true, None).1));
    let rays_total = counted_on.rays.total();
    let brute_tests = scene.shapes.len() as f64 * rays_total as f64;
    let every =
        ((brute_tests / options.brute_force_budget).ceil() as u32).clamp(1, settings.height);
    check()?;
    let (counted_off, counted_off_s) = timed(|| {
        (!options.octree_only).then(|| pool.install(|| renderer_off.trace_rows(every, true)))
    });
    // A repeat renders about what the counted passes did (plus the
    // counted octree pass again): enough to say how long the rest takes.
    let rows_note = if every > 1 {
        format!(" (rows 1/{every})")
    } else {
        String::new()
    };
    say(format!(
        "  counted passes: octree on {counted_s:.2} s{}; about {} left for this scene",
        if options.octree_only {
            String::new()
        } else {
            format!(", brute force {counted_off_s:.2} s{rows_note}")
        },
        duration_text(options.repeat as f64 * (2.0 * counted_s + counted_off_s))
    ));

    // Timed passes, interleaved so drift in machine speed hits both alike.
    let (mut full_on, mut rows_on, mut rows_off) = (Vec::new(), Vec::new(), Vec::new());
    let mut full_bvh = Vec::new();
    let mut counted_times = vec![counted_s];
    let repeats_started = Instant::now();
    for r in 0..options.repeat {
        if r > 0 {
            let per_repeat = repeats_started.elapsed().as_secs_f64() / r as f64;
            say(format!(
                "  repeat {}/{}: about {} left for this scene",
                r + 1,
                options.repeat,
                duration_text(per_repeat * (options.repeat - r) as f64)
            ));
        } else {
            say(format!("  repeat 1/{}", options.repeat));
        }
        check()?;
        full_on.push(timed(|| pool.install(|| renderer_on.render(false, None))).1);
        if let Some(renderer) = &renderer_bvh {
            check()?;
            full_bvh.push(timed(|| pool.install(|| renderer.render(false, None))).1);
        }
        if r > 0 {
            check()?;
            counted_times.push(timed(|| pool.install(|| renderer_on.render(true, None))).1);
        }
        if options.octree_only {
            continue;
        }
        if every > 1 {
            check()?;
            rows_on.push(timed(|| pool.install(|| renderer_on.trace_rows(every, false))).1);
        }
        check()?;
        rows_off.push(timed(|| pool.install(|| renderer_off.trace_rows(every, false))).1);
    }
    let on_s = median(full_on);
    let speedup = (!options.octree_only).then(|| {
        let on_rows_s = if every > 1 { median(rows_on) } else { on_s };
        median(rows_off.clone()) / on_rows_s
    });
    let per_ray = |c: &RenderCounts, x: u64| x as f64 / c.rays.total().max(1) as f64;
    let timing = |c: &RenderCounts, seconds: f64, rays_in_time: f64, estimated: bool| Timing {
        render_s: seconds,
        mrays_per_s: rays_in_time / seconds.max(1e-12) / 1e6,
        intersection_tests_per_ray: per_ray(c, c.work.intersection_tests),
        traversal_steps_per_ray: per_ray(c, c.work.traversal_steps),
        leaves_visited_per_ray: per_ray(c, c.work.leaves_visited),
        estimated,
    };
    let stem = std::path::Path::new(scene_name)
        .file_stem()
        .map_or(String::new(), |s| s.to_string_lossy().into_owned());
    Ok(SceneBench {
        scene: scene_name.to_owned(),
        shapes: scene.shapes.len(),
        width: settings.width,
        height: settings.height,
        samples: settings.samples,
        max_depth: settings.max_depth,
        threads,
        simd: SimdLevel::current(),
        repeats: options.repeat,
        load_s,
        build_s: median(build_times),
        octree_params: scene.octree_params,
        octree_stats: octree.stats(),
        octree_on: timing(&counted_on, on_s, rays_total as f64, false),
        predicted: unit_costs.predict(octree.predicted_cost(), rays_total, threads),
        predicted_from_rays: ray_sample.predict(rays_total, threads),
        unit_costs,
        // The whole-image estimate, with throughput measured on the subset.
        octree_off: counted_off
            .as_ref()
            .zip(speedup)
            .map(|(c, speedup)| Timing {
                render_s: on_s * speedup,
                ..timing(
                    c,
                    median(rows_off.clone()),
                    c.rays.total() as f64,
                    every > 1,
                )
            }),
        bvh: accel_bvh
            .as_ref()
            .and_then(Accelerator::bvh)
            .zip(counted_bvh.as_ref())
            .map(|(b, c)| BvhBench {
                build_s: median(bvh_build_times.clone()),
                bvh_stats: b.stats(),
                timing: timing(c, median(full_bvh.clone()), c.rays.total() as f64, false),
            }),
        light_buffer: match (accel_on.light_buffer(), &accel_bvh) {
            (Some(b), _) => Some(LightBufferBench {
                build_s: median(light_buffer_times.clone()),
                stats: b.stats(),
            }),
            (None, Some(a)) => a.light_buffer().map(|b| LightBufferBench {
                build_s: a.build_seconds().1,
                stats: b.stats(),
            }),
            (None, None) => None,
        },
        speedup,
        compared_rows_every: every,
        counting_overhead: median(counted_times) / on_s,
        rays_total,
        rays: counted_on.rays,
        protocol: settings.protocol,
        published: (settings.protocol == Protocol::Spd
            && (settings.width, settings.height) == (512, 512))
            .then(|| crate::stats::published::spd_counts(&stem))
            .flatten(),
    })
}
