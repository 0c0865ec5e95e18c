//! `glint view` (and `glint` with no arguments): the interactive viewer.

use std::path::PathBuf;

use anyhow::{Result, anyhow};
use glint::settings::{Overrides, ViewMode};
use glint::viewer::app::CompareSetting;
use glint::viewer::{GlintApp, SceneSource, ViewerOptions};

use crate::common::{RulesArgs, Switch, parse_pixel, parse_size};

#[derive(clap::Args)]
pub struct ViewArgs {
    /// Scene file (.toml, .nff, or a Wavefront .obj framed on its own); the
    /// built-in default scene if omitted.
    pub scene: Option<PathBuf>,
    /// Save a screenshot of the whole window once the final pass is on
    /// screen, then exit.
    #[arg(long)]
    pub screenshot: Option<PathBuf>,
    /// Frames to wait after the final pass before the screenshot.
    #[arg(long, default_value_t = 3, requires = "screenshot")]
    pub frames: u32,
    /// Initial view mode.
    #[arg(long, value_parser = |s: &str| s.parse::<ViewMode>())]
    pub view: Option<ViewMode>,
    /// Start with the octree on or off (default: the scene's setting).
    #[arg(long, value_enum)]
    pub octree: Option<Switch>,
    /// Start with this accelerator: octree, bvh or none (see `glint
    /// render --accel`; it must agree with --octree when both are given).
    #[arg(long, value_enum)]
    pub accel: Option<crate::common::AccelArg>,
    /// Start with anti-aliasing off, adaptive or full (`on` is full;
    /// default: the scene's).
    #[arg(long, value_parser = crate::common::parse_aa)]
    pub aa: Option<glint::settings::AntiAliasing>,
    /// Image size as WIDTHxHEIGHT (default: the scene's).
    #[arg(long, value_parser = parse_size)]
    pub size: Option<(u32, u32)>,
    /// Render threads (default: one per core; at most 8 per core).
    #[arg(long, default_value_t = 0, hide_default_value = true)]
    pub threads: usize,
    /// Window size as WIDTHxHEIGHT in points.
    #[arg(long, default_value = "1400x860", value_parser = parse_size)]
    pub window: (u32, u32),
    /// Start with the octree overlay drawn down to this level (0 to 21).
    #[arg(long, value_name = "DEPTH", value_parser = crate::common::octree_depth)]
    pub overlay_depth: Option<u32>,
    /// Start with pixel X,Y's ray tree inspected (from the top-left, from 0).
    #[arg(long, value_name = "X,Y", value_parser = parse_pixel)]
    pub inspect: Option<(u32, u32)>,
    /// With --inspect: start stepping through this ray's octree walk:
    /// `eye`, then the children's indices (`eye/0` is the eye ray's first
    /// secondary ray), and `/shadow/L` for the shadow ray to light L.
    #[arg(long, value_name = "RAY", requires = "inspect", value_parser = parse_walk)]
    pub walk: Option<glint::viewer::WalkTarget>,
    /// With --walk: the steps shown (default: the whole walk).
    #[arg(long, value_name = "N", requires = "walk")]
    pub walk_step: Option<usize>,
    /// Start with an A/B comparison: A is rendered with this setting
    /// flipped and pinned, then B renders as given.
    #[arg(long, value_enum)]
    pub compare: Option<CompareArg>,
    /// Show the comparison as |A - B| instead of a split (with --compare).
    #[arg(long, requires = "compare")]
    pub compare_difference: bool,
    /// Benchmark orbiting: once the first image is complete, drag the
    /// camera round for SECONDS with synthetic pointer events, then print
    /// one JSON object (previews shown, latency, the final pass's time)
    /// on stdout and exit.
    #[arg(long, value_name = "SECONDS", value_parser = bench_seconds, conflicts_with_all = ["screenshot", "compare"])]
    pub orbit_bench: Option<f64>,
    /// With --orbit-bench: pointer events per second (a mouse sends 60 to 125).
    #[arg(long, value_name = "HZ", default_value_t = 60.0, requires = "orbit_bench", value_parser = event_hz)]
    pub event_hz: f64,
    /// With --orbit-bench: write each preview shown during the drag into
    /// DIR as `preview_NNNN.png`, at the image's size as it was drawn, with
    /// the record of the final image at its camera (`glint render
    /// --from-png` renders what the preview stands for;
    /// benches/orbit_previews.py compares the two).
    #[arg(long, value_name = "DIR", requires = "orbit_bench")]
    pub save_previews: Option<PathBuf>,
    /// Start with the previews while moving coloured by where each pixel
    /// came from: a fresh ray, a point reused from earlier frames (by
    /// age), or filled from its neighbours (the render cache at work).
    #[arg(long)]
    pub preview_sources: bool,
    #[command(flatten)]
    pub rules: RulesArgs,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum CompareArg {
    Octree,
    Aa,
}

impl Default for ViewArgs {
    /// The same as `glint view` with no flags.
    fn default() -> Self {
        Self {
            scene: None,
            screenshot: None,
            frames: 3,
            view: None,
            octree: None,
            accel: None,
            aa: None,
            threads: 0,
            size: None,
            window: (1400, 860),
            overlay_depth: None,
            inspect: None,
            walk: None,
            walk_step: None,
            compare: None,
            compare_difference: false,
            orbit_bench: None,
            event_hz: 60.0,
            save_previews: None,
            preview_sources: false,
            rules: RulesArgs::default(),
        }
    }
}

pub fn run(args: &ViewArgs) -> Result<()> {
    crate::common::check_threads(args.threads)?;
    let source = match &args.scene {
        Some(p) => SceneSource::File(p.clone()),
        None => SceneSource::BuiltIn,
    };
    // Load once up front so a bad scene is a clear error, not a blank window.
    let scene = source.load()?;
    // The screenshot's path is checked as `glint render -o` checks its
    // output, before minutes of rendering: a PNG name in a folder that
    // takes a new file, never the scene itself.
    if let Some(shot) = &args.screenshot {
        // The error's source says why (no such folder, no permission).
        glint::export::check_output(shot, args.scene.as_deref())
            .map_err(|e| anyhow::Error::new(e).context("--screenshot"))?;
    }
    // The previews' folder too, before the drag: not after minutes of it.
    if let Some(dir) = &args.save_previews {
        std::fs::create_dir_all(dir)
            .map_err(|e| anyhow!("--save-previews {}: cannot create it: {e}", dir.display()))?;
    }
    let (min_w, min_h) = glint::limits::MIN_WINDOW;
    anyhow::ensure!(
        args.window.0 >= min_w && args.window.1 >= min_h,
        "--window {}x{} is smaller than the viewer can show ({min_w}x{min_h} at least)",
        args.window.0,
        args.window.1
    );
    let (w, h) = (args.window.0 as f32, args.window.1 as f32);
    let mut overrides = Overrides {
        width: args.size.map(|(w, _)| w),
        height: args.size.map(|(_, h)| h),
        anti_aliasing: args.aa,
        accel: crate::common::AccelArg::resolve(args.accel, args.octree)?,
        view: args.view,
        ..Overrides::default()
    };
    args.rules.add_to(&mut overrides);
    // The size the window will render, checked as the CLI checks it, and
    // against the viewer's own limit (it would clamp without a word).
    let mut settings = scene.render_settings();
    let mut params = scene.octree_params;
    overrides.apply(&mut settings, &mut params);
    settings.check()?;
    let side = glint::limits::MAX_VIEWER_SIDE;
    anyhow::ensure!(
        settings.width <= side && settings.height <= side,
        "the viewer renders at most {side} pixels a side, not {}x{}; use glint render for larger images",
        settings.width,
        settings.height
    );
    if let Some((x, y)) = args.inspect {
        anyhow::ensure!(
            x < settings.width && y < settings.height,
            "--inspect {x},{y} is outside the {}x{} image",
            settings.width,
            settings.height
        );
    }
    let screenshot_outcome = glint::viewer::screenshot::ScreenshotOutcome::default();
    let options = ViewerOptions {
        screenshot: args.screenshot.clone(),
        screenshot_outcome: screenshot_outcome.clone(),
        frames: args.frames,
        threads: args.threads,
        overrides,
        overlay_depth: args.overlay_depth,
        inspect: args.inspect,
        walk: args.walk.clone().map(|target| (target, args.walk_step)),
        compare: args.compare.map(|c| match c {
            CompareArg::Octree => CompareSetting::Octree,
            CompareArg::Aa => CompareSetting::AntiAliasing,
        }),
        compare_difference: args.compare_difference,
        show_sources: args.preview_sources,
        orbit_bench: args.orbit_bench.map(|seconds| {
            glint::viewer::orbit_bench::OrbitBenchOptions {
                seconds,
                event_hz: args.event_hz,
                save_previews: args.save_previews.clone(),
            }
        }),
    };
    // Without a display winit fails with its own source path in the
    // message: say what is missing and what works headless instead.
    let no_display = ["DISPLAY", "WAYLAND_DISPLAY", "WAYLAND_SOCKET"]
        .iter()
        .all(|v| std::env::var_os(v).is_none_or(|x| x.is_empty()));
    anyhow::ensure!(
        !no_display,
        "no display found (DISPLAY and WAYLAND_DISPLAY are unset): the viewer needs a window. \
         Render headless with `glint render SCENE -o out.png`, or run the viewer under a \
         virtual display: `xvfb-run -a glint view SCENE --screenshot out.png`"
    );
    let native = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_inner_size([w, h])
            .with_title("glint"),
        ..Default::default()
    };
    eframe::run_native(
        "glint",
        native,
        Box::new(move |cc| {
            let ctx = cc.egui_ctx.clone();
            let app = GlintApp::new(source, options, move || ctx.request_repaint())?;
            Ok(Box::new(app))
        }),
    )
    .map_err(|e| {
        // winit's words for a display that does not answer name its own
        // source file; say what the user can do instead.
        let text = e.to_string();
        if text.contains("X server") || text.contains("Wayland") || text.contains("EventLoopError")
        {
            let display = ["WAYLAND_DISPLAY", "DISPLAY"]
                .iter()
                .find_map(|v| {
                    std::env::var(v)
                        .ok()
                        .filter(|x| !x.is_empty())
                        .map(|x| format!("{v}={x}"))
                })
                .unwrap_or_default();
            anyhow!(
                "cannot open a window: no display answers at {display} ({}). Render headless \
                 with `glint render SCENE -o out.png`, or run the viewer under a virtual \
                 display: `xvfb-run -a glint view SCENE --screenshot out.png`",
                text.rsplit(": ").next().unwrap_or(&text).trim()
            )
        } else {
            anyhow!("the viewer window failed: {e}")
        }
    })?;
    let Some(path) = &args.screenshot else {
        return Ok(());
    };
    let outcome = screenshot_outcome
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .take();
    match outcome {
        Some(Ok(_)) => {
            say!("glint: saved window screenshot {}", path.display());
            Ok(())
        }
        Some(Err(e)) => Err(anyhow!("the screenshot {} failed: {e}", path.display())),
        None => Err(anyhow!(
            "the window closed before the screenshot {} was taken",
            path.display()
        )),
    }
}

/// `--orbit-bench`'s drag: more than nothing, at most ten minutes.
fn bench_seconds(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(s) if s > 0.0 && s <= 600.0 => Ok(s),
        _ => Err(format!(
            "{text:?}: give the drag's length in seconds, above 0 and at most 600"
        )),
    }
}

/// `--event-hz`: from one to a thousand events a second.
fn event_hz(text: &str) -> Result<f64, String> {
    match text.parse::<f64>() {
        Ok(hz) if (1.0..=1000.0).contains(&hz) => Ok(hz),
        _ => Err(format!(
            "{text:?}: give pointer events per second, from 1 to 1000"
        )),
    }
}

/// `eye[/K...][/shadow/L]` as a walk target.
fn parse_walk(text: &str) -> Result<glint::viewer::WalkTarget, String> {
    let bad = || {
        format!(
            "{text:?}: give eye, then child indices, then optionally shadow/LIGHT (e.g. eye/0/shadow/1)"
        )
    };
    let mut parts = text.split('/');
    if parts.next() != Some("eye") {
        return Err(bad());
    }
    let mut target = glint::viewer::WalkTarget::default();
    while let Some(part) = parts.next() {
        if part == "shadow" {
            let light = parts.next().and_then(|l| l.parse().ok()).ok_or_else(bad)?;
            if parts.next().is_some() {
                return Err(bad());
            }
            target.shadow = Some(light);
            break;
        }
        target.path.push(part.parse().map_err(|_| bad())?);
    }
    Ok(target)
}
