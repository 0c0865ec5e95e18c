//! The viewer's start-up options: what the command line asks of the window.

use std::path::PathBuf;

use crate::settings::Overrides;
use crate::viewer::orbit_bench::OrbitBenchOptions;
use crate::viewer::pixel::WalkTarget;
use crate::viewer::screenshot::ScreenshotOutcome;
use crate::viewer::state::CompareSetting;

/// Start-up options of the viewer.
#[derive(Clone, Debug, Default)]
pub struct ViewerOptions {
    /// Save a screenshot of the whole window here once the final pass is on
    /// screen, then exit.
    pub screenshot: Option<PathBuf>,
    /// Where the screenshot's success or failure is reported.
    pub screenshot_outcome: ScreenshotOutcome,
    /// Frames to wait after the final pass before the screenshot.
    pub frames: u32,
    /// Render threads (0 = one per core).
    pub threads: usize,
    /// Initial settings that differ from the scene's (size, view, octree,
    /// anti-aliasing, protocol, colours, sides).
    pub overrides: Overrides,
    /// Start with the octree overlay drawn down to this level.
    pub overlay_depth: Option<u32>,
    /// Start with this pixel's ray tree inspected.
    pub inspect: Option<(u32, u32)>,
    /// And this ray's octree walk shown, to this many steps (`None`: all).
    pub walk: Option<(WalkTarget, Option<usize>)>,
    /// Start by comparing against the image with this setting flipped:
    /// A is rendered with it flipped and pinned, then B as given.
    pub compare: Option<CompareSetting>,
    /// Show the comparison as a difference rather than a split.
    pub compare_difference: bool,
    /// Orbit the scene with synthetic pointer events once its first image
    /// is complete, print the benchmark's report on stdout, then exit.
    pub orbit_bench: Option<OrbitBenchOptions>,
    /// Start with the previews while moving coloured by where each pixel
    /// came from.
    pub show_sources: bool,
}
