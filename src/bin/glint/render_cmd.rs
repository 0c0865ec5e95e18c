//! `glint render`: one scene to one PNG, with optional JSON statistics.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};
use glint::accel::{Octree, OctreeStats};
use glint::render::{RenderSettings, Renderer, ViewMode};
use glint::stats::RayCounts;
use serde::Serialize;

use crate::common::{OctreeArgs, Switch, load_scene, parse_positive, parse_samples, thread_pool};

#[derive(clap::Args)]
pub struct RenderArgs {
    /// Scene file (.toml or .nff).
    pub scene: PathBuf,
    /// Output PNG file.
    #[arg(short, long)]
    pub output: PathBuf,
    /// Image width in pixels (default: the scene's).
    #[arg(long, value_parser = parse_positive)]
    pub width: Option<u32>,
    /// Image height in pixels (default: the scene's).
    #[arg(long, value_parser = parse_positive)]
    pub height: Option<u32>,
    /// Rays per pixel: 1 (pixel centre) or 16 (regular 4x4 grid).
    #[arg(long, value_parser = parse_samples)]
    pub samples: Option<u32>,
    /// Longest ray path; the eye ray is depth 1.
    #[arg(long, value_parser = parse_positive)]
    pub max_depth: Option<u32>,
    /// Use the octree (default: the scene's setting, on unless it says otherwise).
    #[arg(long, value_enum)]
    pub octree: Option<Switch>,
    #[command(flatten)]
    pub octree_params: OctreeArgs,
    /// Render threads (default: one per core).
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    /// What the image shows.
    #[arg(long, default_value = "shaded", value_parser = |s: &str| s.parse::<ViewMode>())]
    pub view: ViewMode,
    /// Print one JSON object of statistics on stdout.
    #[arg(long)]
    pub stats: bool,
}

/// The `--stats` object. Its field names are a public interface: add
/// fields, never rename or repurpose them.
#[derive(Serialize)]
struct RenderStats {
    scene: String,
    width: u32,
    height: u32,
    samples: u32,
    max_depth: u32,
    threads: usize,
    octree: bool,
    octree_params: glint::accel::OctreeParams,
    view: ViewMode,
    load_s: f64,
    build_s: f64,
    render_s: f64,
    rays: RaysJson,
    mrays_per_s: f64,
    intersection_tests_per_ray: f64,
    traversal_steps_per_ray: f64,
    leaves_visited_per_ray: f64,
    nonfinite_samples: u64,
    dropped_degenerate_triangles: usize,
    #[serde(skip_serializing_if = "Option::is_none")]
    octree_stats: Option<OctreeStats>,
}

#[derive(Serialize)]
struct RaysJson {
    #[serde(flatten)]
    counts: RayCounts,
    total: u64,
}

pub fn run(args: &RenderArgs) -> Result<()> {
    let (mut scene, load_s) = load_scene(&args.scene)?;
    args.octree_params.apply(&mut scene.octree_params);
    let mut settings = RenderSettings::from_scene(&scene);
    settings.width = args.width.unwrap_or(settings.width);
    settings.height = args.height.unwrap_or(settings.height);
    settings.samples = args.samples.unwrap_or(settings.samples);
    settings.max_depth = args.max_depth.unwrap_or(settings.max_depth);
    settings.use_octree = args.octree.map_or(settings.use_octree, Switch::is_on);
    settings.view = args.view;

    let pool = thread_pool(args.threads)?;
    let threads = pool.current_num_threads();
    let build_start = Instant::now();
    let octree = if settings.use_octree {
        pool.install(|| Octree::build(&scene.shapes, scene.octree_params))
    } else {
        Octree::build(&[], scene.octree_params)
    };
    let build_s = build_start.elapsed().as_secs_f64();

    let renderer = Renderer::new(&scene, &octree, settings)
        .with_context(|| format!("cannot render {}", args.scene.display()))?;
    let bar = std::io::stderr().is_terminal().then(|| {
        let bar = indicatif::ProgressBar::new(1);
        bar.set_style(
            indicatif::ProgressStyle::with_template(
                "{spinner} rendering [{bar:40}] {percent}% {elapsed} (eta {eta})",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
            .progress_chars("=> "),
        );
        bar
    });
    let progress = |done: u64, total: u64| {
        if let Some(b) = &bar {
            b.set_length(total);
            b.set_position(done);
        }
    };
    let render_start = Instant::now();
    let (frame, counts) = pool.install(|| renderer.render(args.stats, Some(&progress)));
    let render_s = render_start.elapsed().as_secs_f64();
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    frame
        .save_png(&args.output)
        .with_context(|| format!("cannot write {}", args.output.display()))?;

    if scene.dropped_triangles > 0 {
        eprintln!(
            "note: {} degenerate triangles were skipped",
            scene.dropped_triangles
        );
    }
    if args.stats {
        let total = counts.rays.total();
        let per_ray = |x: u64| {
            if total > 0 {
                x as f64 / total as f64
            } else {
                0.0
            }
        };
        let stats = RenderStats {
            scene: args.scene.display().to_string(),
            width: settings.width,
            height: settings.height,
            samples: settings.samples,
            max_depth: settings.max_depth,
            threads,
            octree: settings.use_octree,
            octree_params: scene.octree_params,
            view: settings.view,
            load_s,
            build_s,
            render_s,
            rays: RaysJson {
                counts: counts.rays,
                total,
            },
            mrays_per_s: total as f64 / render_s.max(1e-9) / 1e6,
            intersection_tests_per_ray: per_ray(counts.work.intersection_tests),
            traversal_steps_per_ray: per_ray(counts.work.traversal_steps),
            leaves_visited_per_ray: per_ray(counts.work.leaves_visited),
            nonfinite_samples: counts.nonfinite_samples,
            dropped_degenerate_triangles: scene.dropped_triangles,
            octree_stats: settings.use_octree.then(|| octree.stats()),
        };
        println!("{}", serde_json::to_string_pretty(&stats)?);
    }
    Ok(())
}
