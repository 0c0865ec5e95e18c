//! `glint render`: one scene to one PNG, with optional JSON statistics.

use std::io::IsTerminal;
use std::path::PathBuf;
use std::time::Instant;

use anyhow::{Context, Result};
use std::sync::Arc;

use glint::accel::Octree;
use glint::camera::CameraSpec;
use glint::render::{
    Accelerator, FinishedTile, LightBufferSource, PassInfo, PassOptions, PassWatch, RenderedFrame,
    Renderer, Reuse,
};
use glint::settings::{Accel, Overrides, RenderSettings, ViewMode};

use crate::common::{
    AccelArg, OctreeArgs, RulesArgs, Switch, load_scene, parse_pixel, parse_positive,
    parse_samples, thread_pool_here,
};

#[derive(clap::Args)]
pub struct RenderArgs {
    /// Scene file (.toml, .nff, or a Wavefront .obj framed on its own);
    /// not given with --from-png.
    #[arg(required_unless_present = "from_png", conflicts_with = "from_png")]
    pub scene: Option<PathBuf>,
    /// Output PNG (not needed with --trace-pixel): a `.png` file, written
    /// through a temporary file renamed into place (through symbolic links
    /// to their target); `-` for standard output; FIFOs and devices are
    /// written directly. The scene being rendered is never overwritten.
    #[arg(short, long, required_unless_present = "trace_pixel")]
    pub output: Option<PathBuf>,
    /// Image width in pixels (default: the scene's). At most 32768 a side,
    /// 268,435,456 pixels in all, and what fits in 80% of the available
    /// memory (the estimate is checked before rendering).
    #[arg(long, allow_negative_numbers = true, value_parser = parse_positive)]
    pub width: Option<u32>,
    /// Image height in pixels (default: the scene's); limits as for --width.
    #[arg(long, allow_negative_numbers = true, value_parser = parse_positive)]
    pub height: Option<u32>,
    /// Rays per pixel: 1 (pixel centre) or 16 (regular 4x4 grid); the SPD
    /// protocol shoots the pixel corners instead.
    #[arg(long, allow_negative_numbers = true, value_parser = parse_samples)]
    pub samples: Option<u32>,
    /// Anti-aliasing: off (1 sample), full (the 4x4 grid in every pixel) or
    /// adaptive (every pixel's centre, then the 4x4 grid only where
    /// neighbours differ: another material, a shadow edge, a visible
    /// contrast). `--samples 1|16` means off|full.
    #[arg(long, value_parser = crate::common::parse_aa, conflicts_with = "samples")]
    pub aa: Option<glint::settings::AntiAliasing>,
    /// Longest ray path; the eye ray is depth 1 (the SPD protocol fixes 5).
    #[arg(long, value_parser = crate::common::ray_depth)]
    pub max_depth: Option<u32>,
    #[command(flatten)]
    pub rules: RulesArgs,
    /// Use the octree (default: the scene's setting, on unless it says
    /// otherwise); `--accel` says the same and more.
    #[arg(long, value_enum)]
    pub octree: Option<Switch>,
    /// What ray queries go through: the octree, a BVH (to compare: the
    /// same image, other build and render times and work counts) or none
    /// (brute force). Default: the scene's octree setting.
    #[arg(long, value_enum)]
    pub accel: Option<AccelArg>,
    #[command(flatten)]
    pub octree_params: OctreeArgs,
    /// Draw materials' image textures (OBJ/MTL `map_Kd`, `map_d`; a TOML
    /// material's `texture`): on (the default, or the recorded choice with
    /// --from-png) or off, each textured material in its own colour with
    /// no cut-outs, to compare.
    #[arg(long, value_enum)]
    pub textures: Option<Switch>,
    /// Render threads (default: one per core; at most 8 per core).
    #[arg(long, default_value_t = 0, hide_default_value = true)]
    pub threads: usize,
    /// What the image shows: shaded, normals, depth, cost (intersection
    /// tests per pixel), cost-steps (traversal steps per pixel) or aa-need
    /// (|1 − 16 samples|). Default: shaded, or the recorded view with --from-png.
    #[arg(long, value_parser = |s: &str| s.parse::<ViewMode>())]
    pub view: Option<ViewMode>,
    /// Say nothing on success (otherwise one line on stderr: the file
    /// written, its size, the render time).
    #[arg(long, short)]
    pub quiet: bool,
    /// Print one JSON object of statistics on stdout. Its work counts are
    /// single rays' (packets do not count), so this render traces single
    /// rays: the same image, in more time.
    #[arg(long)]
    pub stats: bool,
    /// Render again the image an earlier glint PNG records (its embedded
    /// scene text and every setting); flags given as well override them.
    #[arg(long, value_name = "OLD.png")]
    pub from_png: Option<PathBuf>,
    /// Print the tree of rays that pixel X,Y's centre ray spawns as one JSON
    /// object on stdout; with -o the image is rendered and written too. X counts from the left,
    /// Y from the top, both from 0.
    #[arg(long, value_name = "X,Y", value_parser = parse_pixel)]
    pub trace_pixel: Option<(u32, u32)>,
    /// Draw the octree's cells over the image as wireframe boxes, coloured
    /// by how many primitives each references.
    #[arg(long, value_enum)]
    pub overlay: Option<OverlayKind>,
    /// Deepest octree level the overlay draws (deeper subtrees are drawn
    /// as one box at this level; at most 21). Default 4, or the recorded one
    /// with --from-png.
    #[arg(long, value_parser = crate::common::octree_depth)]
    pub overlay_depth: Option<u32>,
    /// The legend strip under diagnostic views (cost, cost-steps, aa-need,
    /// depth) and the octree overlay: on (the default, or the recorded
    /// choice with --from-png) or off, for an image exactly the render's
    /// size.
    #[arg(long, value_enum)]
    pub legend: Option<crate::common::Switch>,
    #[command(flatten)]
    pub sequence: crate::sequence::SequenceArgs,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum OverlayKind {
    Octree,
}

/// A render ready to go: the scene, its octree and every setting, checked.
pub(crate) struct Prepared {
    pub(crate) scene: glint::scene::Scene,
    pub(crate) scene_name: String,
    pub(crate) settings: RenderSettings,
    pub(crate) camera: CameraSpec,
    /// What every query goes through, as the settings choose.
    pub(crate) accel: Accelerator,
    /// The octree `--overlay octree` draws: the accelerator's, or one
    /// built for the overlay alone.
    overlay_octree: Option<Arc<Octree>>,
    overlay_depth: Option<u32>,
    legend: bool,
    /// The frame of a sequence a `--from-png` record says it renders.
    frame: Option<glint::export::RecordedFrame>,
    threads: usize,
    pub(crate) pool: rayon::ThreadPool,
    pub(crate) load_s: f64,
    /// Seconds to build the structure and the light buffer.
    pub(crate) build_s: f64,
    light_buffer_s: f64,
}

impl Prepared {
    /// The renderer of this job with `settings`, through its BVH if it has one.
    fn renderer(
        &self,
        settings: RenderSettings,
    ) -> Result<Renderer<'_>, glint::render::RenderError> {
        self.renderer_from(settings, &self.camera)
    }

    /// The renderer of this job with `settings` seen from `camera`.
    pub(crate) fn renderer_from(
        &self,
        settings: RenderSettings,
        camera: &CameraSpec,
    ) -> Result<Renderer<'_>, glint::render::RenderError> {
        Renderer::with_camera(&self.scene, &self.accel, settings, camera)
    }
}

pub fn run(args: &RenderArgs) -> Result<()> {
    args.sequence.check(args)?;
    let job = prepare(args)?;
    if args.sequence.is_sequence() {
        return crate::sequence::run(args, &job);
    }
    if let Some((x, y)) = args.trace_pixel {
        print_ray_tree(&job, x, y)?;
    }
    // With --trace-pixel alone the tree is all there is to do.
    let Some(output) = &args.output else {
        if args.trace_pixel.is_some() {
            return Ok(());
        }
        anyhow::bail!("give an output file with -o");
    };
    let (rendered, render_s) = render(&job, args.stats)?;
    let write_start = Instant::now();
    save(&job, &rendered.frame, output)?;
    let write_s = write_start.elapsed().as_secs_f64();
    report(args, &job, &rendered, output, (render_s, write_s))
}

/// Checks the output, loads the scene (or the recorded one), applies the
/// flags, builds the octree and checks the render fits in memory: every
/// refusal comes before any rendering.
fn prepare(args: &RenderArgs) -> Result<Prepared> {
    args.rules.check(args.max_depth, args.samples)?;
    // Check the output before any work: its name, and that it is not an
    // input (a sequence's frames are checked by name once named).
    if let Some(output) = args
        .output
        .as_ref()
        .filter(|_| !args.sequence.is_sequence())
    {
        let input = args.scene.as_deref().or(args.from_png.as_deref());
        let target = glint::export::check_output(output, input)?;
        if let Some(held) = glint::export::replaced_non_png(&target) {
            say!(
                "note: {} is not a PNG image ({held}); the render replaces it",
                output.display()
            );
        }
        if target == glint::export::OutputTarget::Stdout {
            anyhow::ensure!(
                !args.stats && args.trace_pixel.is_none(),
                "-o - writes the PNG to standard output, where --stats and --trace-pixel \
                 print their JSON: write the image to a file"
            );
            // Binary PNG bytes would garble the terminal.
            anyhow::ensure!(
                !std::io::stdout().is_terminal(),
                "-o - writes the PNG to standard output, which is a terminal here: \
                 redirect it (-o - > out.png) or pipe it into a program"
            );
        }
    }
    let pool = thread_pool_here(args.threads)?;
    let load_start = Instant::now();
    let mut overlay_depth = args.overlay.map(|_| {
        args.overlay_depth
            .unwrap_or(glint::limits::DEFAULT_OVERLAY_DEPTH)
    });
    let mut legend = true;
    let mut frame = None;
    let (mut scene, scene_name, mut settings, camera) = match (&args.from_png, &args.scene) {
        (Some(png), _) => {
            let restored = glint::export::restore(png)
                .with_context(|| format!("cannot render again what {} records", png.display()))?;
            for note in &restored.notes {
                say!("note: {note}");
            }
            overlay_depth = restored
                .overlay_depth
                .map(|d| args.overlay_depth.unwrap_or(d))
                .or(overlay_depth);
            legend = restored.legend;
            frame = restored.frame;
            (
                restored.scene,
                restored.scene_path,
                restored.settings,
                restored.camera,
            )
        }
        (None, Some(path)) => {
            let (scene, _) = load_scene(path)?;
            let settings = scene.render_settings();
            let camera = scene.camera;
            (scene, path.display().to_string(), settings, camera)
        }
        (None, None) => anyhow::bail!("give a scene file or --from-png"),
    };
    let load_s = load_start.elapsed().as_secs_f64();
    if let Some(switch) = args.legend {
        legend = switch.is_on();
    }
    let overrides = overrides(args)?;
    overrides.apply(&mut settings, &mut scene.octree_params);

    let threads = pool.current_num_threads();
    // A depth with no overlay to draw would be ignored without a word.
    anyhow::ensure!(
        args.overlay_depth.is_none() || overlay_depth.is_some(),
        "--overlay-depth sets how deep the octree overlay draws: add --overlay octree \
         (or render again a PNG that recorded an overlay, with --from-png)"
    );
    // `--stats` renders counting the accelerator's work, which the light
    // buffer would hide: there it is not built.
    let reuse = Reuse {
        light_buffer: if args.stats {
            LightBufferSource::Given(None)
        } else {
            LightBufferSource::Build
        },
        ..Reuse::default()
    };
    let accel = pool
        .install(|| Accelerator::build(&scene, &settings, reuse))
        .with_context(|| format!("cannot build the octree of {scene_name}"))?;
    let overlay_octree = match (overlay_depth, accel.octree()) {
        (None, _) => None,
        (Some(_), Some(tree)) => Some(Arc::clone(tree)),
        (Some(_), None) => Some(Arc::new(
            pool.install(|| scene.build_octree())
                .with_context(|| format!("cannot build the octree of {scene_name}"))?,
        )),
    };
    let (structure_s, light_buffer_s) = accel.build_seconds();
    if args.output.is_some() {
        // Validate before starting.
        Renderer::with_camera(&scene, &accel, settings, &camera)
            .with_context(|| format!("cannot render {scene_name}"))?;
        glint::render::memory::check_memory(
            &settings,
            accel.memory_bytes() + scene.texture_bytes(),
        )
        .with_context(|| format!("cannot render {scene_name}"))?;
    }
    Ok(Prepared {
        scene,
        scene_name,
        settings,
        camera,
        accel,
        overlay_octree,
        overlay_depth,
        legend,
        frame,
        threads,
        pool,
        load_s,
        build_s: structure_s,
        light_buffer_s,
    })
}

/// What the flags ask for instead of the scene's (or the record's) settings.
fn overrides(args: &RenderArgs) -> Result<Overrides> {
    let mut o = Overrides {
        width: args.width,
        height: args.height,
        anti_aliasing: crate::common::anti_aliasing(args.samples, args.aa),
        max_depth: args.max_depth,
        accel: AccelArg::resolve(args.accel, args.octree)?,
        octree: args.octree_params.overrides(),
        view: args.view,
        textures: args.textures.map(Switch::is_on),
        ..Overrides::default()
    };
    args.rules.add_to(&mut o);
    Ok(o)
}

/// Renders every pass of the frame with a progress bar on a terminal;
/// returns it and the seconds it took.
fn render(job: &Prepared, count_work: bool) -> Result<(RenderedFrame, f64)> {
    let renderer = job
        .renderer(job.settings)
        .with_context(|| format!("cannot render {}", job.scene_name))?;
    let bar = crate::common::terminal_bar(
        1,
        "{spinner} rendering [{bar:40}] {percent}% {elapsed} (eta {eta})",
    );
    let watch = ProgressBar { bar: bar.as_ref() };
    let options = PassOptions {
        count_work,
        progressive: false,
    };
    let start = Instant::now();
    let rendered = job
        .pool
        .install(|| renderer.render_frame(options, &watch))
        .context("the render was abandoned")?;
    let render_s = start.elapsed().as_secs_f64();
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    Ok((rendered, render_s))
}

/// Shows the frame's progress in tiles.
struct ProgressBar<'a> {
    bar: Option<&'a indicatif::ProgressBar>,
}

impl PassWatch for ProgressBar<'_> {
    fn tile_done(&self, pass: &PassInfo, _tile: &FinishedTile) {
        if let Some(b) = self.bar {
            b.set_length(pass.frame_tiles);
            b.inc(1);
        }
    }
}

/// Writes the frame with its record (and the overlay, if asked for).
fn save(
    job: &Prepared,
    frame: &glint::image::frame::Frame,
    output: &std::path::Path,
) -> Result<()> {
    save_from(job, frame, output, &job.camera, job.frame)
}

/// The record a frame seen from `camera` carries (`sequence`: where it
/// sits in its sequence), as [`save_from`] writes it.
pub(crate) fn record_of(
    job: &Prepared,
    camera: &CameraSpec,
    sequence: Option<glint::export::RecordedFrame>,
) -> glint::export::RenderRecord {
    let mut record =
        glint::export::render_record(&job.scene, &job.scene_name, camera, job.settings);
    record.settings.legend = job.legend;
    record.settings.frame = sequence;
    record.settings.overlay_depth = job.overlay_depth;
    record
}

/// Writes `frame`, seen from `camera`, with its record (and the overlay,
/// if asked for).
pub(crate) fn save_from(
    job: &Prepared,
    frame: &glint::image::frame::Frame,
    output: &std::path::Path,
    camera_spec: &CameraSpec,
    sequence: Option<glint::export::RecordedFrame>,
) -> Result<()> {
    let s = &job.settings;
    let mut record = record_of(job, camera_spec, sequence);
    let camera = glint::camera::Camera::new(camera_spec, s.width, s.height)?;
    let overlay = job
        .overlay_depth
        .zip(job.overlay_octree.as_deref())
        .map(|(depth, octree)| glint::export::OverlayRequest {
            octree,
            camera: &camera,
            depth,
        });
    glint::export::save_frame(frame, output, &mut record, overlay)?;
    Ok(())
}

/// The line on stderr, the notes about what the scene dropped, and the
/// `--stats` JSON.
fn report(
    args: &RenderArgs,
    job: &Prepared,
    rendered: &RenderedFrame,
    output: &std::path::Path,
    (render_s, write_s): (f64, f64),
) -> Result<()> {
    let (scene, settings) = (&job.scene, &job.settings);
    let (frame, counts) = (&rendered.frame, &rendered.counts);
    if !args.quiet {
        // The file's own size: cost views add their legend under the image.
        let (mut width, mut height) = (frame.width, frame.height);
        let written = match glint::export::OutputTarget::resolve(output)? {
            glint::export::OutputTarget::File(p) => {
                if let Some((w, h)) = png_size(&p) {
                    (width, height) = (w, h);
                }
                std::fs::metadata(&p)
                    .map(|m| format!(", {} KiB", m.len().div_ceil(1024)))
                    .unwrap_or_default()
            }
            _ => String::new(),
        };
        let light_buffer_s = job.light_buffer_s;
        let light_buffer_note = if job.accel.light_buffer().is_some() {
            format!("; light buffer {light_buffer_s:.3} s")
        } else {
            String::new()
        };
        say!(
            "wrote {} ({}x{}{written}) in {:.2} s: load {:.2} s, {}, render {:.2} s, write {:.2} s{light_buffer_note}",
            if output.as_os_str() == "-" {
                "standard output".to_string()
            } else {
                output.display().to_string()
            },
            width,
            height,
            job.load_s + job.build_s + light_buffer_s + render_s + write_s,
            job.load_s,
            match job.accel.kind() {
                Accel::Octree => format!("octree build {:.2} s", job.build_s),
                Accel::Bvh => format!("BVH build {:.2} s", job.build_s),
                Accel::BruteForce => "no accelerator (brute force)".to_string(),
            },
            render_s,
            write_s
        );
    }
    for note in scene.notes() {
        say!("note: {note}");
    }
    if counts.rays.primary > 0 && counts.rays.primary_hits == 0 {
        say!(
            "note: no eye ray hit anything: the picture is the background alone (the camera \
             looks away from the scene, or the scene is far smaller or larger than its view)"
        );
    }
    if let Some(octree) = job.accel.octree()
        && octree.stats().leaves_stopped_by_budget > 0
    {
        say!(
            "note: the octree build reached its memory budget of {} MiB (nodes, references and \
             the cells still to split, held at once while building; the finished tree takes {:.1} MiB): \
             {} cells stayed leaves; --octree-memory-budget raises it",
            scene.octree_params.memory_budget_mib,
            octree.stats().memory_bytes as f64 / (1024.0 * 1024.0),
            octree.stats().leaves_stopped_by_budget
        );
    }
    if !args.stats {
        return Ok(());
    }
    let times = glint::report::RenderTimes {
        load_s: job.load_s,
        build_s: job.build_s,
        render_s,
    };
    let stats = glint::report::RenderStats::new(
        &job.scene_name,
        scene,
        settings,
        job.threads,
        &job.accel,
        rendered,
        times,
    );
    out!("{}", serde_json::to_string_pretty(&stats)?)?;
    Ok(())
}

fn print_ray_tree(job: &Prepared, x: u32, y: u32) -> Result<()> {
    let settings = glint::report::trace_settings(job.settings);
    anyhow::ensure!(
        x < settings.width && y < settings.height,
        "{}",
        glint::report::PixelOutside {
            x,
            y,
            width: settings.width,
            height: settings.height
        }
    );
    let renderer = job
        .renderer(settings)
        .with_context(|| format!("cannot render {}", job.scene_name))?;
    let out = glint::report::TraceReport::new(&renderer, &job.scene, &job.scene_name, x, y)?;
    out!("{}", serde_json::to_string_pretty(&out)?)?;
    Ok(())
}

/// The width and height in a PNG's header, read without decoding pixels.
fn png_size(path: &std::path::Path) -> Option<(u32, u32)> {
    let file = std::fs::File::open(path).ok()?;
    let reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .ok()?;
    Some((reader.info().width, reader.info().height))
}
