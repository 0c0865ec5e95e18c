//! What the worker reports of each finished pass: the timing panel's and
//! the frame budget's figures.

use super::Preview;
use crate::stats::RayCounts;

/// Which pass produced a buffer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PassKind {
    Preview(Preview),
    OneSample,
    SixteenSamples,
    /// The SPD protocol's one pass: rays through the pixel corners.
    Corners,
}

impl PassKind {
    /// How the viewer names a pass of the library's engine.
    pub(super) fn of(pass: crate::render::PassKind, preview: Option<Preview>) -> Self {
        use crate::render::PassKind as Engine;
        match (pass, preview) {
            (_, Some(p)) => PassKind::Preview(p),
            (Engine::OneSample, None) => PassKind::OneSample,
            (Engine::Grid | Engine::Refine, None) => PassKind::SixteenSamples,
            (Engine::Corners, None) => PassKind::Corners,
        }
    }

    pub fn label(self) -> String {
        match self {
            PassKind::Preview(p) => format!("preview {}", p.describe()),
            PassKind::OneSample => "1 sample".into(),
            PassKind::SixteenSamples => "16 samples".into(),
            PassKind::Corners => "SPD corners".into(),
        }
    }
}

/// A finished pass, for the timing panel and plot.
#[derive(Clone, Copy, Debug)]
pub struct PassRecord {
    pub generation: u64,
    pub kind: PassKind,
    pub seconds: f64,
    pub rays: RayCounts,
    pub octree: bool,
    pub anti_aliasing: bool,
    pub width: u32,
    pub height: u32,
    /// Seconds since the worker started, when the pass finished.
    pub finished_at: f64,
    /// For a 16-sample pass: the error of the same generation's 1-sample
    /// pass against it (what anti-aliasing changed).
    pub one_sample_error: Option<crate::metrics::ImageError>,
    /// For an adaptive 16-sample pass: the pixels it refined (the rest kept
    /// their 1-sample value).
    pub refined_pixels: Option<u64>,
    /// What the pass showed, and the settings that decide its time apart
    /// from anti-aliasing (passes are compared only when these agree).
    pub view: crate::settings::ViewMode,
    pub max_depth: u32,
    pub protocol: crate::settings::Protocol,
    /// Shown from the pass cache, not rendered again: `seconds` is the
    /// time the pass took when it was rendered.
    pub from_cache: bool,
}
