//! `glint bench`: octree on against off, interleaved repeats, medians.

use glint::settings::Accel;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use anyhow::{Result, bail};
use glint::accel::{Octree, OctreeStats};
use glint::render::{Accelerator, LightBufferSource, Prediction, Renderer, Reuse, UnitCosts};
use glint::report::{SceneBench, duration_text};
use glint::settings::{Overrides, RenderSettings};
use serde::Serialize;

use crate::common::{
    AccelArg, OctreeArgs, RulesArgs, check_scene_files, load_scene, median, parse_positive,
    parse_samples, parse_size, thread_pool_here,
};

#[derive(clap::Args)]
pub struct BenchArgs {
    /// Scene files (.toml, .nff, or an .obj model on its own).
    #[arg(required = true)]
    pub scenes: Vec<PathBuf>,
    /// Image size as WIDTHxHEIGHT (default: each scene's own).
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Rays per pixel: 1 or 16 (default: each scene's own); the SPD
    /// protocol shoots the pixel corners instead.
    #[arg(long, allow_negative_numbers = true, value_parser = parse_samples)]
    pub samples: Option<u32>,
    /// Anti-aliasing: off, adaptive or full (see `glint render --aa`).
    #[arg(long, value_parser = crate::common::parse_aa, conflicts_with = "samples")]
    pub aa: Option<glint::settings::AntiAliasing>,
    /// Longest ray path (default: each scene's own; the SPD protocol fixes 5).
    #[arg(long, value_parser = crate::common::ray_depth)]
    pub max_depth: Option<u32>,
    #[command(flatten)]
    pub rules: RulesArgs,
    /// Timed runs of each configuration; medians are reported.
    #[arg(long, default_value_t = 3, allow_negative_numbers = true, value_parser = parse_positive)]
    pub repeat: u32,
    #[command(flatten)]
    pub octree_params: OctreeArgs,
    /// Render threads (default: one per core; at most 8 per core).
    #[arg(long, default_value_t = 0, hide_default_value = true)]
    pub threads: usize,
    /// Output format.
    #[arg(long, value_enum, default_value = "markdown")]
    pub format: Format,
    /// Brute force traces at most about this many shape tests per repeat;
    /// beyond it, it traces an evenly spaced subset of rows (both
    /// configurations then time the same rows, and the output says so).
    #[arg(long, default_value_t = 4e9)]
    pub brute_force_budget: f64,
    /// Time the octree only: no brute-force comparison (`octree_off` and
    /// `speedup` are then left out of the JSON).
    #[arg(long)]
    pub octree_only: bool,
    /// What to time, comma-separated: the octree always, and beside it
    /// `none` (brute force, the default) and `bvh` (a BVH: its build,
    /// memory, work counts and render in a `bvh` object and a second
    /// table). `--accel octree` alone is `--octree-only`.
    #[arg(long, value_delimiter = ',', value_enum, default_value = "octree,none")]
    pub accel: Vec<AccelArg>,
    /// What the image shows (default: shaded); `normals` and `depth`
    /// trace eye rays only.
    #[arg(long, value_parser = |s: &str| s.parse::<glint::settings::ViewMode>())]
    pub view: Option<glint::settings::ViewMode>,
    /// Instead of octree on/off, sweep the octree parameters: every
    /// combination of these maximum depths, leaf sizes and cost-driven
    /// on/off, octree on, one row each (medians of `--repeat` runs).
    #[arg(long)]
    pub sweep: bool,
    /// Maximum depths for `--sweep` (each 0 to 21).
    #[arg(long, value_delimiter = ',', default_value = "6,8,10,12", value_parser = crate::common::octree_depth, requires = "sweep")]
    pub sweep_depths: Vec<u32>,
    /// Leaf sizes for `--sweep` (each at least 1).
    #[arg(long, value_delimiter = ',', default_value = "2,4,8,16", value_parser = crate::common::parse_positive, requires = "sweep")]
    pub sweep_leaf_sizes: Vec<u32>,
    /// Maximum duplication factors for `--sweep` (each 1 to 8; default: the scene's).
    #[arg(long, value_delimiter = ',', value_parser = clap::value_parser!(u32).range(1..=8), requires = "sweep")]
    pub sweep_max_duplications: Vec<u32>,
    /// Cost-driven settings for `--sweep`.
    #[arg(
        long,
        value_delimiter = ',',
        value_enum,
        default_value = "on,off",
        requires = "sweep"
    )]
    pub sweep_cost_driven: Vec<crate::common::Switch>,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Format {
    Json,
    Markdown,
}

fn timed<T>(f: impl FnOnce() -> T) -> (T, f64) {
    let start = Instant::now();
    let out = f();
    (out, start.elapsed().as_secs_f64())
}

pub fn run(args: &BenchArgs) -> Result<()> {
    args.rules.check(args.max_depth, args.samples)?;
    anyhow::ensure!(
        args.accel.contains(&AccelArg::Octree),
        "glint bench always times the octree: list it in --accel (e.g. --accel octree,bvh)"
    );
    anyhow::ensure!(
        !args.sweep || !args.accel.contains(&AccelArg::Bvh),
        "--sweep varies the octree's parameters; --accel bvh goes with a plain bench"
    );
    check_scene_files(&args.scenes)?;
    if args.sweep {
        return sweep(args);
    }
    let pool = thread_pool_here(args.threads)?;
    let mut results = Vec::new();
    for path in &args.scenes {
        let (mut scene, load_s) = load_scene(path)?;
        let settings = bench_settings(args, &mut scene);
        say!(
            "bench {} ({} shapes, {}x{}, {} spp, {} repeats)",
            path.display(),
            scene.shapes.len(),
            settings.width,
            settings.height,
            settings.samples,
            args.repeat
        );

        let options = glint::report::BenchOptions {
            repeat: args.repeat,
            brute_force_budget: args.brute_force_budget,
            octree_only: args.octree_only || !args.accel.contains(&AccelArg::None),
            bvh: args.accel.contains(&AccelArg::Bvh),
        };
        let name = path.display().to_string();
        results.push(glint::report::bench_scene(
            &scene,
            &name,
            load_s,
            settings,
            options,
            &pool,
            &SayProgress,
        )?);
    }
    match args.format {
        Format::Json => out!("{}", serde_json::to_string_pretty(&results)?)?,
        Format::Markdown => {
            out_str!("{}", markdown(&results))?;
            if results.iter().any(|r| r.published.is_some()) {
                out_str!("\n{}", counts_markdown(&results))?;
            }
            if results.iter().any(|r| r.bvh.is_some()) {
                out_str!("\n{}", bvh_markdown(&results))?;
            }
        }
    }
    Ok(())
}

/// Progress lines on standard error; a benchmark is never stopped early.
struct SayProgress;

impl glint::report::BenchWatch for SayProgress {
    fn say(&self, line: &str) {
        say!("{line}");
    }
}

/// A scene file's stem, as the published tables name the SPD scenes.
fn stem(path: &std::path::Path) -> String {
    path.file_stem()
        .map_or(String::new(), |s| s.to_string_lossy().into_owned())
}

/// The octree beside the BVH (`--accel bvh`): build, memory, work per ray
/// and render time of each.
fn bvh_markdown(results: &[SceneBench]) -> String {
    let mut s = String::from(
        "| scene | build octree (s) | build BVH (s) | octree MiB | BVH MiB | steps/ray octree | steps/ray BVH | tests/ray octree | tests/ray BVH | render octree (s) | render BVH (s) |\n\
         |---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    let mib = |bytes: u64| bytes as f64 / (1u64 << 20) as f64;
    for r in results {
        let Some(b) = &r.bvh else { continue };
        let name = std::path::Path::new(&r.scene)
            .file_name()
            .map_or(r.scene.clone(), |n| n.to_string_lossy().into_owned());
        s.push_str(&format!(
            "| {name} | {:.3} | {:.3} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1} | {:.3} | {:.3} |\n",
            r.build_s,
            b.build_s,
            mib(r.octree_stats.memory_bytes),
            mib(b.bvh_stats.memory_bytes),
            r.octree_on.traversal_steps_per_ray,
            b.timing.traversal_steps_per_ray,
            r.octree_on.intersection_tests_per_ray,
            b.timing.intersection_tests_per_ray,
            r.octree_on.render_s,
            b.timing.render_s,
        ));
    }
    s
}

fn markdown(results: &[SceneBench]) -> String {
    let mut s = String::from(
        "| scene | shapes | size | spp | build (s) | octree on (s) | octree off (s) | speedup | Mrays/s (on) | N_IT | N_TS | N_ETS | N_IT Havran best | counting overhead |\n\
         |---|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    for r in results {
        let name = std::path::Path::new(&r.scene)
            .file_name()
            .map_or(r.scene.clone(), |n| n.to_string_lossy().into_owned());
        let off = match &r.octree_off {
            None => "–".to_string(),
            Some(off) if off.estimated => format!(
                "{:.2} (est., rows 1/{})",
                off.render_s, r.compared_rows_every
            ),
            Some(off) => format!("{:.2}", off.render_s),
        };
        let speedup = r.speedup.map_or("–".to_string(), |x| format!("{x:.1}x"));
        let havran =
            glint::stats::published::havran_best_nit(&stem(std::path::Path::new(&r.scene)))
                .map_or("".to_string(), |x| format!("{x:.2}"));
        s.push_str(&format!(
            "| {} | {} | {}x{} | {} | {:.3} | {:.3} | {} | {} | {:.2} | {:.2} | {:.2} | {:.2} | {} | {:.2}x |\n",
            name,
            r.shapes,
            r.width,
            r.height,
            if r.protocol == glint::settings::Protocol::Spd {
                "corners".to_string()
            } else {
                r.samples.to_string()
            },
            r.build_s,
            r.octree_on.render_s,
            off,
            speedup,
            r.octree_on.mrays_per_s,
            r.octree_on.intersection_tests_per_ray,
            r.octree_on.traversal_steps_per_ray,
            r.octree_on.leaves_visited_per_ray,
            havran,
            r.counting_overhead,
        ));
    }
    s
}

/// glint's ray counts beside the SPD's published ones, with the relative
/// difference.
fn counts_markdown(results: &[SceneBench]) -> String {
    let mut s = String::from(
        "| scene | eye rays | eye rays that hit (SPD) | diff | reflection (SPD) | diff | refraction (SPD) | diff | shadow (SPD) | diff |\n\
         |---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n",
    );
    let cell = |ours: u64, theirs: u64| {
        let diff = if theirs == 0 {
            if ours == 0 {
                "0%".to_string()
            } else {
                "n/a".to_string()
            }
        } else {
            format!(
                "{:+.1}%",
                100.0 * (ours as f64 - theirs as f64) / theirs as f64
            )
        };
        (format!("{ours} ({theirs})"), diff)
    };
    for r in results {
        let Some(p) = r.published else { continue };
        let name = std::path::Path::new(&r.scene)
            .file_stem()
            .map_or(r.scene.clone(), |n| n.to_string_lossy().into_owned());
        let (a, da) = cell(r.rays.primary_hits, p.eye_hits);
        let (b, db) = cell(r.rays.reflection, p.reflection);
        let (c, dc) = cell(r.rays.refraction, p.refraction);
        let (d, dd) = cell(r.rays.shadow, p.shadow);
        s.push_str(&format!(
            "| {name} | {} | {a} | {da} | {b} | {db} | {c} | {dc} | {d} | {dd} |\n",
            r.rays.primary
        ));
    }
    s
}

/// One row of a parameter sweep.
#[derive(Serialize)]
struct SweepRow {
    scene: String,
    octree_params: glint::accel::OctreeParams,
    build_s: f64,
    render_s: f64,
    mrays_per_s: f64,
    intersection_tests_per_ray: f64,
    traversal_steps_per_ray: f64,
    leaves_visited_per_ray: f64,
    octree_stats: OctreeStats,
    /// The render as predicted from the tree alone, before it ran.
    predicted: Prediction,
    /// The render as predicted from a sample of its own rays (a 64-pixel
    /// thumbnail traced through the tree), before it ran.
    predicted_from_rays: Prediction,
    /// glint's suggestion for this scene (the viewer's "Suggest a
    /// setting"): the least build (measured) plus render predicted from
    /// the sample of rays, the prediction that ranks renders as they run.
    suggested: bool,
    /// The same as `suggested`, under its older name.
    suggested_from_rays: bool,
    /// The least build plus render predicted from the tree alone (what
    /// `suggested` once marked; docs/cli.md): the surface-area model,
    /// blind to the view.
    suggested_from_tree: bool,
    /// This scene's setting with the least measured build plus render time.
    fastest: bool,
    /// On the suggested and the fastest rows, when they differ: their
    /// build plus render timed again, the two interleaved, the median of
    /// [`again_rounds`] rounds. The sweep's least time is the least of many
    /// noisy figures, so it is biased low; timed side by side, the two
    /// compare fairly. `null` on other rows.
    timed_again_s: Option<f64>,
}

/// Rounds of the side-by-side timing: more than the sweep's repeats, as two
/// settings' times are compared, not placed.
fn again_rounds(repeat: u32) -> u32 {
    (2 * repeat + 1).max(5)
}

fn sweep(args: &BenchArgs) -> Result<()> {
    let pool = thread_pool_here(args.threads)?;
    let mut rows = Vec::new();
    if args.format == Format::Markdown {
        out!(
            "| scene | cost-driven | max depth | leaf size | max duplication | build (s) | render (s) | predicted render (s) | N_IT | predicted N_IT | N_TS | predicted N_TS | N_ETS | nodes | memory (KiB) | from rays: render (s) | N_IT | N_TS |"
        )?;
        out!(
            "|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|"
        )?;
    }
    let threads = pool.current_num_threads();
    for path in &args.scenes {
        let (mut scene, _) = load_scene(path)?;
        let mut settings = bench_settings(args, &mut scene);
        settings.accel = Accel::Octree;
        say!("sweep {}", path.display());
        // Every setting's shadow rays ask the same light buffer first, as
        // a render's do: the sweep varies only the tree.
        // (A one-leaf tree's renderer ignores it.)
        let light_buffer = pool.install(|| scene.build_light_buffer()).map(Arc::new);
        let through = |octree: &Arc<Octree>| {
            let reuse = Reuse {
                octree: Some(Arc::clone(octree)),
                bvh: None,
                light_buffer: LightBufferSource::Given(light_buffer.clone()),
            };
            Accelerator::build(&scene, &settings, reuse)
        };
        // Unit costs once per scene, on its own octree setting, and how
        // the time per ray changes with the image's size (the scene's and
        // view's, as "Suggest a setting" takes it).
        let (unit_costs, per_doubling) = {
            let octree = Arc::new(pool.install(|| scene.build_octree())?);
            let accel = through(&octree)?;
            let renderer = Renderer::new(&scene, &accel, settings)?;
            let sample = glint::render::sample_rays(&renderer, &octree)?;
            (
                UnitCosts::measure(&renderer, &octree)?,
                Some(sample.per_doubling),
            )
        };
        let first_row = rows.len();
        let duplications = if args.sweep_max_duplications.is_empty() {
            vec![scene.octree_params.max_duplication]
        } else {
            args.sweep_max_duplications.clone()
        };
        let mut combinations = Vec::new();
        for c in &args.sweep_cost_driven {
            for &d in &args.sweep_depths {
                for &l in &args.sweep_leaf_sizes {
                    for &x in &duplications {
                        combinations.push((c.is_on(), d, l, x));
                    }
                }
            }
        }
        let sweep_started = std::time::Instant::now();
        let count = combinations.len();
        for (k, (cost_driven, max_depth, leaf_size, max_duplication)) in
            combinations.into_iter().enumerate()
        {
            let left = if k > 0 {
                let per = sweep_started.elapsed().as_secs_f64() / k as f64;
                format!(
                    "; about {} left for this scene",
                    duration_text(per * (count - k) as f64)
                )
            } else {
                String::new()
            };
            say!(
                "  {}/{count}: depth {max_depth}, leaf {leaf_size}, duplication {max_duplication}, cost-driven {}{left}",
                k + 1,
                if cost_driven { "on" } else { "off" }
            );
            let params = glint::accel::OctreeParams {
                max_depth,
                leaf_size,
                cost_driven,
                max_duplication,
                ..scene.octree_params
            };
            let (mut builds, mut renders) = (Vec::new(), Vec::new());
            let mut tree = None;
            for _ in 0..args.repeat {
                let (t, s) = timed(|| pool.install(|| Octree::build(&scene.shapes, params)));
                builds.push(s);
                tree = Some(t?);
            }
            let Some(octree) = tree.map(Arc::new) else {
                bail!("no repeats")
            };
            // The prediction comes first: it needs the tree, not the render
            // (the ray count, which the octree does not change, excepted).
            let predicted_cost = octree.predicted_cost();
            let accel = through(&octree)?;
            let renderer = Renderer::new(&scene, &accel, settings)?;
            let ray_sample = glint::render::sample_rays_with(&renderer, &octree, per_doubling)?;
            let counts = pool.install(|| renderer.render(true, None).1);
            for _ in 0..args.repeat {
                renders.push(timed(|| pool.install(|| renderer.render(false, None))).1);
            }
            let render_s = median(renders);
            let total = counts.rays.total().max(1) as f64;
            let row = SweepRow {
                scene: path.display().to_string(),
                octree_params: params,
                build_s: median(builds),
                render_s,
                mrays_per_s: total / render_s.max(1e-12) / 1e6,
                intersection_tests_per_ray: counts.work.intersection_tests as f64 / total,
                traversal_steps_per_ray: counts.work.traversal_steps as f64 / total,
                leaves_visited_per_ray: counts.work.leaves_visited as f64 / total,
                octree_stats: octree.stats(),
                predicted: unit_costs.predict(predicted_cost, counts.rays.total(), threads),
                predicted_from_rays: ray_sample.predict(counts.rays.total(), threads),
                suggested: false,
                suggested_from_rays: false,
                suggested_from_tree: false,
                fastest: false,
                timed_again_s: None,
            };
            if args.format == Format::Markdown {
                print_sweep_row(&row)?;
            }
            rows.push(row);
        }
        mark_suggested_and_fastest(&mut rows[first_row..]);
        let scene_rows = &mut rows[first_row..];
        let suggested = scene_rows.iter().position(|r| r.suggested);
        let fastest = scene_rows.iter().position(|r| r.fastest);
        if let (Some(s), Some(f)) = (suggested, fastest)
            && s != f
        {
            say!("  timing the suggested and the fastest settings again, side by side");
            let rounds = again_rounds(args.repeat);
            let mut times = [Vec::new(), Vec::new()];
            for _ in 0..rounds {
                for (k, row) in [s, f].into_iter().enumerate() {
                    let params = scene_rows[row].octree_params;
                    let (octree, build_s) =
                        timed(|| pool.install(|| Octree::build(&scene.shapes, params)));
                    let octree = Arc::new(octree?);
                    let accel = through(&octree)?;
                    let renderer = Renderer::new(&scene, &accel, settings)?;
                    let render_s = timed(|| pool.install(|| renderer.render(false, None))).1;
                    times[k].push(build_s + render_s);
                }
            }
            let [again_s, again_f] = times.map(median);
            scene_rows[s].timed_again_s = Some(again_s);
            scene_rows[f].timed_again_s = Some(again_f);
        }
        if args.format == Format::Markdown {
            print_suggestion(&rows[first_row..], args.repeat)?;
        }
    }
    if args.format == Format::Json {
        out!("{}", serde_json::to_string_pretty(&rows)?)?;
    }
    Ok(())
}

/// Marks the rows with the least predicted build + render (from the rays:
/// the suggestion; from the tree alone) and the one with the least
/// measured build + render (the first of equals).
fn mark_suggested_and_fastest(rows: &mut [SweepRow]) {
    let least = |rows: &[SweepRow], cost: fn(&SweepRow) -> f64| {
        (0..rows.len()).min_by(|&a, &b| cost(&rows[a]).total_cmp(&cost(&rows[b])))
    };
    if let Some(i) = least(rows, |r| r.build_s + r.predicted.render_s) {
        rows[i].suggested_from_tree = true;
    }
    if let Some(i) = least(rows, |r| r.build_s + r.predicted_from_rays.render_s) {
        rows[i].suggested = true;
        rows[i].suggested_from_rays = true;
    }
    if let Some(i) = least(rows, |r| r.build_s + r.render_s) {
        rows[i].fastest = true;
    }
}

/// Lines under a scene's sweep: the suggested settings (from a sample of
/// the render's rays, and from the tree alone), and how their measured
/// times compare with the sweep's best.
fn print_suggestion(rows: &[SweepRow], repeat: u32) -> anyhow::Result<()> {
    let Some(f) = rows.iter().find(|r| r.fastest) else {
        return Ok(());
    };
    let describe = |r: &SweepRow| {
        format!(
            "max depth {}, leaf size {}, max duplication {}, cost-driven {}",
            r.octree_params.max_depth,
            r.octree_params.leaf_size,
            r.octree_params.max_duplication,
            if r.octree_params.cost_driven {
                "on"
            } else {
                "off"
            }
        )
    };
    let measured = |r: &SweepRow| r.build_s + r.render_s;
    out!(
        "\nThe sweep's fastest for {}: {}: {:.3} s measured (build + render).",
        f.scene,
        describe(f),
        measured(f)
    )?;
    for (label, chosen) in [
        (
            "from a sample of the render's rays",
            rows.iter().find(|r| r.suggested),
        ),
        (
            "from the tree alone",
            rows.iter().find(|r| r.suggested_from_tree),
        ),
    ] {
        if let Some(s) = chosen {
            out!(
                "Suggested {label} (least build + predicted render): {}: {:.3} s measured ({:.2}x).",
                describe(s),
                measured(s),
                measured(s) / measured(f).max(1e-12)
            )?;
        }
    }
    let suggested = rows.iter().find(|r| r.suggested);
    if let Some((again_s, again_f)) = suggested.and_then(|s| s.timed_again_s.zip(f.timed_again_s)) {
        out!(
            "Timed again side by side (medians of {} rounds): the suggestion {:.3} s, the fastest {:.3} s ({:.2}x).",
            again_rounds(repeat),
            again_s,
            again_f,
            again_s / again_f.max(1e-12)
        )?;
    }
    out!()
}

fn print_sweep_row(r: &SweepRow) -> anyhow::Result<()> {
    let name = std::path::Path::new(&r.scene)
        .file_name()
        .map_or(r.scene.clone(), |n| n.to_string_lossy().into_owned());
    out!(
        "| {} | {} | {} | {} | {} | {:.3} | {:.3} | {:.3} | {:.2} | {:.2} | {:.2} | {:.2} | {:.2} | {} | {:.0} | {:.3} | {:.2} | {:.2} |",
        name,
        if r.octree_params.cost_driven {
            "on"
        } else {
            "off"
        },
        r.octree_params.max_depth,
        r.octree_params.leaf_size,
        r.octree_params.max_duplication,
        r.build_s,
        r.render_s,
        r.predicted.render_s,
        r.intersection_tests_per_ray,
        r.predicted.intersection_tests_per_ray,
        r.traversal_steps_per_ray,
        r.predicted.traversal_steps_per_ray,
        r.leaves_visited_per_ray,
        r.octree_stats.nodes,
        r.octree_stats.memory_bytes as f64 / 1024.0,
        r.predicted_from_rays.render_s,
        r.predicted_from_rays.intersection_tests_per_ray,
        r.predicted_from_rays.traversal_steps_per_ray
    )
}

/// The scene's settings with the command line's overrides applied (and its
/// octree parameters to the scene).
fn bench_settings(args: &BenchArgs, scene: &mut glint::scene::Scene) -> RenderSettings {
    let mut overrides = Overrides {
        width: args.size.map(|(w, _)| w),
        height: args.size.map(|(_, h)| h),
        anti_aliasing: crate::common::anti_aliasing(args.samples, args.aa),
        max_depth: args.max_depth,
        octree: args.octree_params.overrides(),
        view: args.view,
        ..Overrides::default()
    };
    args.rules.add_to(&mut overrides);
    let mut settings = scene.render_settings();
    overrides.apply(&mut settings, &mut scene.octree_params);
    settings
}
