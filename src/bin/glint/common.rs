//! Pieces shared by the subcommands.

use std::path::Path;
use std::time::Instant;

use anyhow::{Context, Result};
use glint::scene::Scene;
use glint::settings::{AntiAliasing, OctreeOverrides, Overrides};

/// `on` / `off`, as the command line spells a switch.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Switch {
    On,
    Off,
}

impl Switch {
    pub fn is_on(self) -> bool {
        self == Switch::On
    }
}

/// What ray queries go through, as `--accel` names it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum AccelArg {
    /// The octree (glint's default).
    Octree,
    /// A bounding volume hierarchy (binned SAH), to compare with the octree.
    Bvh,
    /// Brute force: every shape for every ray.
    None,
}

impl AccelArg {
    /// `--accel` and the older `--octree on|off` together: either alone,
    /// or both when they agree; `None` when neither is given (the scene's
    /// setting).
    pub fn resolve(
        accel: Option<AccelArg>,
        octree: Option<Switch>,
    ) -> Result<Option<glint::settings::Accel>> {
        let named = accel.map(AccelArg::accel);
        let switched = octree.map(|s| glint::settings::Accel::from_octree_switch(s.is_on()));
        match (named, switched) {
            (Some(a), Some(s)) if a != s => anyhow::bail!(
                "--octree {} and --accel {} disagree: give one of them",
                if s == glint::settings::Accel::Octree {
                    "on"
                } else {
                    "off"
                },
                a.name()
            ),
            (a, s) => Ok(a.or(s)),
        }
    }

    pub fn accel(self) -> glint::settings::Accel {
        match self {
            AccelArg::Octree => glint::settings::Accel::Octree,
            AccelArg::Bvh => glint::settings::Accel::Bvh,
            AccelArg::None => glint::settings::Accel::BruteForce,
        }
    }
}

pub use glint::report::median;

/// Loads a scene and reports how long it took.
/// The progress bar on the terminal, if one is shown: the Ctrl+C handler
/// silences it before ending its line, so no redraw from a render thread
/// lands after that line end.
static TERMINAL_BAR: std::sync::Mutex<Option<indicatif::ProgressBar>> = std::sync::Mutex::new(None);

/// A progress bar of `len` steps drawn with `template`, when stderr is a
/// terminal; `None` otherwise (a log or a pipe gets no redraws).
pub fn terminal_bar(len: u64, template: &str) -> Option<indicatif::ProgressBar> {
    use std::io::IsTerminal;
    if !std::io::stderr().is_terminal() {
        return None;
    }
    let bar = indicatif::ProgressBar::new(len);
    bar.set_style(
        indicatif::ProgressStyle::with_template(template)
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar())
            .progress_chars("=> "),
    );
    if let Ok(mut shown) = TERMINAL_BAR.lock() {
        *shown = Some(bar.clone());
    }
    Some(bar)
}

/// Stops the shown progress bar drawing and ends its line (on a terminal),
/// so the shell's prompt starts on a line of its own after Ctrl+C.
pub fn end_terminal_line() {
    use std::io::IsTerminal;
    // `try_lock`: the handler must not wait on a thread it interrupts.
    if let Ok(mut shown) = TERMINAL_BAR.try_lock()
        && let Some(bar) = shown.take()
    {
        bar.set_draw_target(indicatif::ProgressDrawTarget::hidden());
    }
    if std::io::stderr().is_terminal() {
        say!("");
    }
}

pub fn load_scene(path: &Path) -> Result<(Scene, f64)> {
    let start = Instant::now();
    let scene = glint::scene::load(path)?;
    Ok((scene, start.elapsed().as_secs_f64()))
}

/// Checks, before any scene is timed, that every scene file of a
/// multi-scene command can be opened and read as a scene, so a mistyped
/// or broken last file fails at once rather than after the others were
/// measured (and with no results). A single scene is only opened here:
/// the command reads it next anyway.
pub fn check_scene_files(paths: &[std::path::PathBuf]) -> Result<()> {
    for path in paths {
        let kind = std::fs::metadata(path)
            .with_context(|| format!("cannot read scene file {}", path.display()))?;
        anyhow::ensure!(
            kind.is_file(),
            "cannot read scene file {}: not a regular file",
            path.display()
        );
    }
    if paths.len() > 1 {
        for path in paths {
            glint::scene::load(path).with_context(|| {
                format!(
                    "nothing was timed: {} cannot be read as a scene",
                    path.display()
                )
            })?;
        }
    }
    Ok(())
}

/// `word` as a POSIX shell reads it back: as it is when it holds only
/// characters no shell treats specially, else in single quotes (a quote
/// inside written `'\''`), so a printed command can be pasted.
pub fn shell_quoted(word: &str) -> String {
    let plain = !word.is_empty()
        && word
            .bytes()
            .all(|b| b.is_ascii_alphanumeric() || b"_./-+,:=@%".contains(&b));
    if plain {
        word.to_owned()
    } else {
        format!("'{}'", word.replace('\'', "'\\''"))
    }
}

pub use glint::limits::MAX_THREADS_PER_CORE;

/// Refuses more than [`MAX_THREADS_PER_CORE`] threads per core.
pub fn check_threads(threads: usize) -> Result<()> {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    let limit = MAX_THREADS_PER_CORE * cores;
    anyhow::ensure!(
        threads <= limit,
        "--threads {threads} is more than {MAX_THREADS_PER_CORE} per core: this machine has {cores} \
         cores, so at most {limit} (0, the default, is one per core)"
    );
    Ok(())
}

/// A rayon pool with `threads` workers (0 = one per core), at most
/// [`MAX_THREADS_PER_CORE`] per core.
pub fn thread_pool(threads: usize) -> Result<rayon::ThreadPool> {
    build_pool(threads, rayon::ThreadPoolBuilder::new())
}

fn build_pool(threads: usize, builder: rayon::ThreadPoolBuilder) -> Result<rayon::ThreadPool> {
    check_threads(threads)?;
    builder
        .num_threads(threads)
        .build()
        .context("cannot start the render threads")
}

/// Like [`thread_pool`], with the calling thread as one of the workers, for
/// a command that makes one pool and waits on it: its work starts on this
/// thread at once instead of after a new thread wakes (for a two-shape
/// scene's octree, most of the build's time), and `threads` counts this
/// thread too. The pool lives until the process ends.
pub fn thread_pool_here(threads: usize) -> Result<rayon::ThreadPool> {
    build_pool(
        threads,
        rayon::ThreadPoolBuilder::new().use_current_thread(),
    )
}

pub fn parse_samples(s: &str) -> std::result::Result<u32, String> {
    match s {
        "1" => Ok(1),
        "16" => Ok(glint::settings::AntiAliasing::SAMPLES),
        _ => Err(format!("samples must be 1 or 16, got `{s}`")),
    }
}

/// `off`, `adaptive` or `full` (and the viewer's older `on` for full).
pub fn parse_aa(s: &str) -> std::result::Result<AntiAliasing, String> {
    match s {
        "on" => Ok(AntiAliasing::Full),
        _ => s.parse(),
    }
}

/// `WIDTHxHEIGHT`, both at least 1.
pub fn parse_size(s: &str) -> std::result::Result<(u32, u32), String> {
    let (w, h) = s
        .split_once(['x', 'X'])
        .ok_or_else(|| format!("expected WIDTHxHEIGHT, got `{s}`"))?;
    Ok((parse_positive(w)?, parse_positive(h)?))
}

/// `X,Y` pixel coordinates.
pub fn parse_pixel(s: &str) -> std::result::Result<(u32, u32), String> {
    let (x, y) = s
        .split_once(',')
        .ok_or_else(|| format!("expected X,Y, got `{s}`"))?;
    let n = |v: &str| {
        v.trim()
            .parse::<u32>()
            .map_err(|_| format!("expected X,Y as whole numbers, got `{s}`"))
    };
    Ok((n(x)?, n(y)?))
}

pub fn parse_positive(s: &str) -> std::result::Result<u32, String> {
    match s.parse::<u32>() {
        Ok(n) if n > 0 => Ok(n),
        _ => Err(format!("expected a whole number of at least 1, got `{s}`")),
    }
}

/// How rays are cast and colours shaded; unset ones keep the scene's.
#[derive(clap::Args, Clone, Copy, Debug, Default)]
pub struct RulesArgs {
    /// The rules rays are cast by: glint (pixel centres or a regular grid)
    /// or spd (the SPD test protocol: rays through the 513x513 pixel
    /// corners of a 512x512 image, depth 5, a reflection ray from every
    /// reflective or transmitting surface, opaque surfaces one-sided).
    #[arg(long, value_parser = |s: &str| s.parse::<glint::settings::Protocol>())]
    pub protocol: Option<glint::settings::Protocol>,
    /// Colour convention: linear (shade in linear light, write sRGB; the
    /// default for TOML scenes) or display (shade display values, write
    /// them unchanged; the default for NFF scenes).
    #[arg(long, value_parser = |s: &str| s.parse::<glint::color::ColorConvention>())]
    pub colors: Option<glint::color::ColorConvention>,
    /// Sidedness: two (every surface seen from both sides; glint's default)
    /// or one (opaque surfaces seen from outside only; the SPD protocol's
    /// default, which keeps patches with vertex normals two-sided).
    #[arg(long, value_parser = |s: &str| s.parse::<glint::settings::Sides>())]
    pub sides: Option<glint::settings::Sides>,
}

impl RulesArgs {
    /// Refuses settings the SPD protocol fixes itself.
    pub fn check(&self, max_depth: Option<u32>, samples: Option<u32>) -> Result<()> {
        if self.protocol == Some(glint::settings::Protocol::Spd) {
            anyhow::ensure!(
                max_depth.is_none(),
                "--protocol spd fixes the ray depth at 5: drop --max-depth"
            );
            anyhow::ensure!(
                samples.is_none(),
                "--protocol spd shoots the pixel corners (each pixel the mean of four): drop --samples"
            );
        }
        Ok(())
    }

    /// Puts the flags into `overrides`.
    pub fn add_to(&self, overrides: &mut Overrides) {
        overrides.protocol = self.protocol;
        overrides.colors = self.colors;
        overrides.sides = self.sides;
    }
}

/// The anti-aliasing asked for by `--samples 1|16` (off or full) or `--aa`.
pub fn anti_aliasing(samples: Option<u32>, aa: Option<AntiAliasing>) -> Option<AntiAliasing> {
    aa.or(samples.map(|n| {
        if n > 1 {
            AntiAliasing::Full
        } else {
            AntiAliasing::Off
        }
    }))
}

/// An octree level, 0 to [`glint::limits::MAX_OCTREE_DEPTH`]: what scene
/// files and export records accept, so whatever a command writes reads back.
pub fn octree_depth(text: &str) -> Result<u32, String> {
    let max = glint::limits::MAX_OCTREE_DEPTH;
    match text.trim().parse::<u32>() {
        Ok(d) if d <= max => Ok(d),
        _ => Err(format!(
            "expected an octree level from 0 to {max}, got `{text}`"
        )),
    }
}

/// A `--max-depth`: refused by the command-line parser whether it is 0 or
/// past the limit (65 was refused later, with another exit code).
pub fn ray_depth(text: &str) -> Result<u32, String> {
    let max = glint::limits::MAX_RAY_DEPTH;
    match text.trim().parse::<u32>() {
        Ok(d) if (1..=max).contains(&d) => Ok(d),
        _ => Err(format!(
            "expected a ray depth from 1 to {max}, got `{text}`"
        )),
    }
}

/// Octree parameters on the command line; unset ones keep the scene's.
#[derive(clap::Args, Clone, Copy, Debug, Default)]
pub struct OctreeArgs {
    /// Deepest octree level (root = 0; at most 21).
    #[arg(long, allow_negative_numbers = true, value_parser = octree_depth)]
    pub octree_max_depth: Option<u32>,
    /// References up to which a node stays a leaf (default: 8 for a large
    /// mesh, at least 20,000 triangles; 4 otherwise).
    #[arg(long, allow_negative_numbers = true, value_parser = parse_positive)]
    pub octree_leaf_size: Option<u32>,
    /// Let the surface-area cost estimate stop subdivision early.
    #[arg(long, value_enum)]
    pub octree_cost_driven: Option<Switch>,
    /// Keep a node a leaf when its children would hold more than this many
    /// times its references (1 to 8; 8 never stops a split).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=8))]
    pub octree_max_duplication: Option<u32>,
    /// Memory budget of the octree in MiB (nodes and references, counted
    /// while it is built); past it, nodes stay leaves, which is correct but
    /// slower. Default 128.
    #[arg(long, value_name = "MIB", value_parser = clap::value_parser!(u32).range(1..=glint::limits::MAX_MEMORY_BUDGET_MIB as i64))]
    pub octree_memory_budget: Option<u32>,
}

impl OctreeArgs {
    pub fn overrides(&self) -> OctreeOverrides {
        OctreeOverrides {
            max_depth: self.octree_max_depth,
            leaf_size: self.octree_leaf_size,
            cost_driven: self.octree_cost_driven.map(Switch::is_on),
            max_duplication: self.octree_max_duplication,
            memory_budget_mib: self.octree_memory_budget,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::shell_quoted;

    #[test]
    fn printed_paths_paste_back_into_a_shell() {
        assert_eq!(shell_quoted("out/a-1.png"), "out/a-1.png");
        assert_eq!(shell_quoted("sp ace é/out ü.png"), "'sp ace é/out ü.png'");
        assert_eq!(shell_quoted("it's.png"), "'it'\\''s.png'");
        assert_eq!(shell_quoted(""), "''");
    }
}
