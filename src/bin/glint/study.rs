//! `glint study`: how much accuracy each speed knob buys, measured.
//!
//! For each scene: anti-aliasing (1, 4, 16, 64 samples against a 256-sample
//! reference; adaptive against the full 4x4 grid), recursion depth (1 to 8 against 12), octree parameters, and
//! preview resolution (1/1, 1/2, 1/4 against the full-resolution image).
//! Writes `DIR/study.md` and difference images `DIR/*.png`.

use glint::settings::Accel;
use std::fmt::Write as _;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use anyhow::{Context, Result};
use glint::accel::{Octree, OctreeParams};
use glint::image::frame::Frame;
use glint::image::metrics::image_error;
use glint::math::DVec3;
use glint::render::{Accelerator, LightBufferSource, Renderer, Reuse};
use glint::scene::Scene;
use glint::settings::RenderSettings;

use crate::common::{
    check_scene_files, load_scene, median, parse_positive, parse_size, shell_quoted, thread_pool,
};

#[derive(clap::Args)]
pub struct StudyArgs {
    /// Scene files (.toml, .nff, or an .obj model on its own).
    #[arg(required = true)]
    pub scenes: Vec<PathBuf>,
    /// Output directory for study.md and the images.
    #[arg(long, default_value = "study")]
    pub out: PathBuf,
    /// Image size as WIDTHxHEIGHT (default: 320x240).
    #[arg(long, default_value = "320x240", value_parser = parse_size)]
    pub size: (u32, u32),
    /// Timed runs per configuration (the median is reported).
    #[arg(long, default_value_t = 3, allow_negative_numbers = true, value_parser = parse_positive)]
    pub repeat: u32,
    /// Render threads (default: one per core; at most 8 per core).
    #[arg(long, default_value_t = 0, hide_default_value = true)]
    pub threads: usize,
}

struct Study<'a> {
    scene: &'a Scene,
    octree: Arc<Octree>,
    /// Asked first by every timed render's shadow rays, as in a release render.
    light_buffer: Option<Arc<glint::accel::LightBuffer>>,

    repeat: u32,
    pool: rayon::ThreadPool,
}

impl Study<'_> {
    /// Median time and the frame of a render with `settings`.
    fn run(&self, settings: RenderSettings, octree: Option<&Arc<Octree>>) -> Result<(f64, Frame)> {
        self.run_times(settings, octree, self.repeat)
    }

    /// An untimed reference image: rendered once.
    fn reference(&self, settings: RenderSettings) -> Result<Frame> {
        Ok(self.run_times(settings, None, 1)?.1)
    }

    fn run_times(
        &self,
        settings: RenderSettings,
        octree: Option<&Arc<Octree>>,
        repeat: u32,
    ) -> Result<(f64, Frame)> {
        let reuse = Reuse {
            octree: Some(Arc::clone(octree.unwrap_or(&self.octree))),
            bvh: None,
            light_buffer: LightBufferSource::Given(self.light_buffer.clone()),
        };
        let accel = Accelerator::build(self.scene, &settings, reuse)?;
        let renderer = Renderer::new(self.scene, &accel, settings)?;
        let mut times = Vec::new();
        let mut frame = None;
        for _ in 0..repeat.max(1) {
            let start = Instant::now();
            let (f, _) = self.pool.install(|| renderer.render(false, None));
            times.push(start.elapsed().as_secs_f64());
            frame = Some(f);
        }
        Ok((median(times), frame.context("no repeats")?))
    }
}

/// Upsamples a frame by pixel replication to `width` x `height`, as the
/// viewer shows a reduced-resolution preview.
fn upsample(f: &Frame, width: u32, height: u32) -> Vec<DVec3> {
    let mut out = Vec::with_capacity((width * height) as usize);
    for y in 0..height {
        let sy = (y as u64 * f.height as u64 / height as u64) as u32;
        for x in 0..width {
            let sx = (x as u64 * f.width as u64 / width as u64) as u32;
            out.push(f.pixels[(sy * f.width + sx) as usize]);
        }
    }
    out
}

/// Writes `|a - b|` (sRGB-encoded difference, scaled by `gain`) as a PNG.
pub fn run(args: &StudyArgs) -> Result<()> {
    let (w, h) = args.size;
    check_scene_files(&args.scenes)?;
    std::fs::create_dir_all(&args.out)
        .with_context(|| format!("cannot create {}", args.out.display()))?;
    let mut md = String::new();
    writeln!(md, "# glint study\n")?;
    writeln!(
        md,
        "Regenerate with `glint study {} --out {} --size {} --repeat {}`. Times are {} on this machine \
         ({} threads); errors are against a reference render of the same scene.\n",
        args.scenes
            .iter()
            .map(|p| shell_quoted(&p.display().to_string()))
            .collect::<Vec<_>>()
            .join(" "),
        shell_quoted(&args.out.display().to_string()),
        format_args!("{w}x{h}"),
        args.repeat,
        if args.repeat == 1 {
            "single runs".to_string()
        } else {
            format!("medians of {} runs", args.repeat)
        },
        thread_pool(args.threads)?.current_num_threads()
    )?;
    let mut summary = Vec::new();
    let mut stems = std::collections::BTreeSet::new();
    for path in &args.scenes {
        let (scene, _) = load_scene(path)?;
        // Two scenes of one name (a/sphere.toml, b/sphere.toml) get their
        // own pictures and rows: sphere, sphere-2.
        let file_stem = path
            .file_stem()
            .map_or("scene".into(), |s| s.to_string_lossy().into_owned());
        let stem = (1..)
            .map(|k| match k {
                1 => file_stem.clone(),
                k => format!("{file_stem}-{k}"),
            })
            .find(|s| !stems.contains(s))
            .unwrap_or_default();
        stems.insert(stem.clone());
        say!("study {}", path.display());
        let mut base = scene.render_settings();
        (base.width, base.height) = (w, h);
        base.accel = Accel::Octree;
        let study = Study {
            octree: Arc::new(scene.build_octree()?),
            light_buffer: scene.build_light_buffer().map(Arc::new),
            scene: &scene,
            repeat: args.repeat,
            pool: thread_pool(args.threads)?,
        };
        writeln!(md, "## {}\n", path.display())?;

        // Anti-aliasing.
        let reference = study.reference(RenderSettings {
            samples: 256,
            ..base
        })?;
        writeln!(
            md,
            "### Anti-aliasing (reference: 256 samples, 16x16 grid)\n"
        )?;
        writeln!(
            md,
            "| samples | grid | time (s) | time vs 1 | RMSE shaded | PSNR shaded (dB) | RMSE displayed | PSNR displayed (dB) | pixels off by > 1/255 |"
        )?;
        writeln!(md, "|---:|---|---:|---:|---:|---:|---:|---:|---:|")?;
        let mut one = None;
        let mut t_one = 1.0;
        for samples in [1u32, 4, 16, 64] {
            let (t, f) = study.run(RenderSettings { samples, ..base }, None)?;
            if samples == 1 {
                t_one = t;
            }
            let e = image_error(&f.pixels, &reference.pixels, base.colors);
            let k = (samples as f64).sqrt() as u32;
            writeln!(
                md,
                "| {samples} | {k}x{k} | {t:.3} | {:.1}x | {:.4} | {:.1} | {:.4} | {:.1} | {:.1}% |",
                t / t_one,
                e.rmse_shaded,
                e.psnr_shaded,
                e.rmse_display,
                e.psnr_display,
                100.0 * e.visible_fraction
            )?;
            if samples == 1 {
                one = Some(f);
            } else if samples == 16
                && let Some(one) = &one
            {
                let need = args.out.join(format!("{stem}-aa-need.png"));
                // The same picture as `glint render --view aa-need`, legend included.
                glint::export::save_png(&Frame::aa_need(one, &f), &need, None)?;
                let e = image_error(&one.pixels, &f.pixels, base.colors);
                summary.push((
                    stem.clone(),
                    "1 vs 16 samples: pixels anti-aliasing changes".to_string(),
                    format!("{:.1}%", 100.0 * e.visible_fraction),
                ));
                summary.push((
                    stem.clone(),
                    "16 / 1 sample time".into(),
                    format!("{:.1}x", t / t_one),
                ));
            }
        }
        writeln!(
            md,
            "\n![anti-aliasing need]({stem}-aa-need.png) — |1 sample − 16 samples| in sRGB, gain 4.\n"
        )?;

        // Adaptive anti-aliasing against the full 4x4 grid.
        let full = RenderSettings {
            samples: 16,
            adaptive: false,
            ..base
        };
        let (t_full, f_full) = study.run(full, None)?;
        let adaptive = RenderSettings {
            adaptive: true,
            ..full
        };
        let (t_adaptive, f_adaptive) = study.run(adaptive, None)?;
        let refined = {
            let accel =
                Accelerator::build(study.scene, &adaptive, Reuse::octree_alone(&study.octree))?;
            let renderer = Renderer::new(study.scene, &accel, adaptive)?;
            study
                .pool
                .install(|| renderer.render(false, None).1)
                .refined_pixels
        };
        let e = image_error(&f_adaptive.pixels, &f_full.pixels, base.colors);
        let share = refined as f64 / (w as f64 * h as f64);
        writeln!(
            md,
            "### Adaptive anti-aliasing (reference: the full 4x4 grid)\n"
        )?;
        writeln!(
            md,
            "| mode | time (s) | time vs full | pixels refined | PSNR displayed (dB) | pixels off by > 1/255 |"
        )?;
        writeln!(md, "|---|---:|---:|---:|---:|---:|")?;
        writeln!(md, "| full | {t_full:.3} | 100% | 100% | inf | 0.0% |")?;
        writeln!(
            md,
            "| adaptive | {t_adaptive:.3} | {:.0}% | {:.1}% | {:.1} | {:.1}% |\n",
            100.0 * t_adaptive / t_full,
            100.0 * share,
            e.psnr_display,
            100.0 * e.visible_fraction
        )?;
        summary.push((
            stem.clone(),
            "adaptive AA: time vs full, pixels refined, PSNR vs full".into(),
            format!(
                "{:.0}%, {:.1}%, {:.1} dB",
                100.0 * t_adaptive / t_full,
                100.0 * share,
                e.psnr_display
            ),
        ));

        // Recursion depth.
        let deep = study.reference(RenderSettings {
            max_depth: 12,
            samples: 1,
            ..base
        })?;
        writeln!(md, "### Recursion depth (reference: depth 12, 1 sample)\n")?;
        writeln!(
            md,
            "| max depth | time (s) | RMSE displayed | PSNR displayed (dB) | pixels off by > 1/255 |"
        )?;
        writeln!(md, "|---:|---:|---:|---:|---:|")?;
        for depth in 1..=8 {
            let (t, f) = study.run(
                RenderSettings {
                    max_depth: depth,
                    samples: 1,
                    ..base
                },
                None,
            )?;
            let e = image_error(&f.pixels, &deep.pixels, base.colors);
            writeln!(
                md,
                "| {depth} | {t:.3} | {:.4} | {:.1} | {:.1}% |",
                e.rmse_display,
                e.psnr_display,
                100.0 * e.visible_fraction
            )?;
            if depth == 3 {
                summary.push((
                    stem.clone(),
                    "depth 3 vs 12: pixels off".into(),
                    format!("{:.1}%", 100.0 * e.visible_fraction),
                ));
            }
        }

        // Octree parameters.
        writeln!(md, "\n### Octree parameters (1 sample)\n")?;
        writeln!(
            md,
            "| max depth | leaf size | build (s) | render (s) | memory (KiB) | tests per ray |"
        )?;
        writeln!(md, "|---:|---:|---:|---:|---:|---:|")?;
        for max_depth in [4u32, 6, 8, 10, 12] {
            for leaf_size in [2u32, 8, 32] {
                let params = OctreeParams {
                    max_depth,
                    leaf_size,
                    ..scene.octree_params
                };
                let start = Instant::now();
                let tree = Arc::new(
                    study
                        .pool
                        .install(|| Octree::build(&scene.shapes, params))?,
                );
                let build = start.elapsed().as_secs_f64();
                let (t, _) = study.run(RenderSettings { samples: 1, ..base }, Some(&tree))?;
                let counted = RenderSettings { samples: 1, ..base };
                let accel = Accelerator::build(&scene, &counted, Reuse::octree_alone(&tree))?;
                let renderer = Renderer::new(&scene, &accel, counted)?;
                let counts = study.pool.install(|| renderer.render(true, None).1);
                writeln!(
                    md,
                    "| {max_depth} | {leaf_size} | {build:.4} | {t:.3} | {:.0} | {:.2} |",
                    tree.stats().memory_bytes as f64 / 1024.0,
                    counts.work.intersection_tests as f64 / counts.rays.total().max(1) as f64
                )?;
            }
        }

        // Preview resolution.
        writeln!(
            md,
            "\n### Preview resolution (1 sample; error of the upscaled preview against full resolution)\n"
        )?;
        writeln!(
            md,
            "| resolution | pixels | time to image (s) | RMSE displayed | PSNR displayed (dB) | pixels off by > 1/255 |"
        )?;
        writeln!(md, "|---|---:|---:|---:|---:|---:|")?;
        let full = one.as_ref().context("1-sample render")?;
        for d in [1u32, 2, 4] {
            let s = RenderSettings {
                samples: 1,
                width: (w / d).max(1),
                height: (h / d).max(1),
                ..base
            };
            let (t, f) = study.run(s, None)?;
            let up = upsample(&f, w, h);
            let e = image_error(&up, &full.pixels, base.colors);
            writeln!(
                md,
                "| 1/{d} | {}x{} | {t:.4} | {:.4} | {:.1} | {:.1}% |",
                s.width,
                s.height,
                e.rmse_display,
                e.psnr_display,
                100.0 * e.visible_fraction
            )?;
            if d == 4 {
                summary.push((
                    stem.clone(),
                    "1/4 preview: PSNR displayed".into(),
                    format!("{:.1} dB", e.psnr_display),
                ));
            }
        }
        writeln!(md)?;
    }
    let mut head = String::from("## Summary\n\n| scene | measure | value |\n|---|---|---:|\n");
    for (scene, what, value) in &summary {
        writeln!(head, "| {scene} | {what} | {value} |")?;
    }
    let out = args.out.join("study.md");
    let text = md.replacen("\n## ", &format!("\n{head}\n## "), 1);
    std::fs::write(&out, text).with_context(|| format!("cannot write {}", out.display()))?;
    say!("wrote {}", out.display());
    Ok(())
}
