//! What the worker reports of each finished pass: the timing panel's and
//! the frame budget's figures.

use super::Preview;
use crate::stats::RayCounts;

/// Which pass produced a buffer: one of the engine's passes
/// ([`crate::render::PassKind`]), traced at a drag preview's reduced
/// settings or at the frame's own.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ShownPass {
    pub pass: crate::render::PassKind,
    pub preview: Option<Preview>,
}

impl ShownPass {
    /// A pass at the frame's own settings.
    pub fn full(pass: crate::render::PassKind) -> Self {
        Self {
            pass,
            preview: None,
        }
    }

    /// A drag preview (a 1-sample pass at reduced settings).
    pub fn drag_preview(preview: Preview) -> Self {
        Self {
            pass: crate::render::PassKind::OneSample,
            preview: Some(preview),
        }
    }

    /// A full pass of the 4x4 grid, everywhere or where the picture needs
    /// it (the two are one series: the same anti-aliasing, as a user sees).
    pub fn is_grid(self) -> bool {
        use crate::render::PassKind as Engine;
        self.preview.is_none() && matches!(self.pass, Engine::Grid | Engine::Refine)
    }

    pub fn label(self) -> String {
        use crate::render::PassKind as Engine;
        match (self.preview, self.pass) {
            (Some(p), _) => format!("preview {}", p.describe()),
            (None, Engine::OneSample) => "1 sample".into(),
            (None, Engine::Grid | Engine::Refine) => {
                format!("{} samples", crate::settings::AntiAliasing::SAMPLES)
            }
            (None, Engine::Corners) => "SPD corners".into(),
        }
    }
}

/// A finished pass, for the timing panel and plot.
#[derive(Clone, Copy, Debug)]
pub struct PassRecord {
    pub generation: u64,
    pub kind: ShownPass,
    pub seconds: f64,
    pub rays: RayCounts,
    /// What the pass's ray queries went through.
    pub accel: crate::settings::Accel,
    pub anti_aliasing: bool,
    pub width: u32,
    pub height: u32,
    /// Seconds since the worker started, when the pass finished.
    pub finished_at: f64,
    /// For a 16-sample pass: the error of the same generation's 1-sample
    /// pass against it (what anti-aliasing changed).
    pub one_sample_error: Option<crate::image::metrics::ImageError>,
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
    /// For a render-cache preview: what it was made of.
    pub reuse: Option<crate::render::render_cache::PreviewSummary>,
}
