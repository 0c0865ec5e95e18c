//! What the worker keeps for render-cache previews between jobs.

use crate::render::render_cache::{PreviewSummary, RenderCache};

/// The render cache and what it knows of the display, kept from preview
/// to preview.
pub(super) struct ReuseState {
    pub(super) cache: RenderCache,
    /// The generation the cache's points were last updated in: a finished
    /// full pass of a newer one seeds it again (exact, anti-aliased
    /// colours are better points than an earlier preview's).
    pub(super) generation: u64,
    /// The cache keeps a point for every `scale x scale` pixels
    /// ([`ReuseState::adapt`]).
    pub(super) scale: u32,
    /// Seconds a preview spends besides its fresh rays (moving the
    /// points, filling, showing), as last measured: the rays get the rest.
    pub(super) overhead: f64,
    /// Previews in a row that had time and rays to spare (a finer scale is
    /// tried after a few).
    pub(super) easy: u32,
    /// The enlarged picture or source view, before it goes on screen.
    pub(super) shown: Vec<u8>,
}

impl Default for ReuseState {
    fn default() -> Self {
        Self {
            cache: Default::default(),
            generation: 0,
            scale: 3,
            overhead: 0.0,
            easy: 0,
            shown: Vec::new(),
        }
    }
}

/// The coarsest scale of the render cache: a point for every 4 x 4 pixels.
const MAX_REUSE_SCALE: u32 = 4;

impl ReuseState {
    /// The scale for the next preview after one that took `seconds` of
    /// its `target`, with `summary`: coarser at once when the fresh rays
    /// could not keep up (more than 2 % of the pixels had to be filled) or
    /// the preview overran its time; finer after a few previews that left
    /// rays and time to spare.
    pub(super) fn adapt(&mut self, seconds: f64, target: f64, summary: &PreviewSummary) -> u32 {
        let pixels = summary.pixels().max(1) as f64;
        let unreached = summary.gaps_filled as f64 / pixels;
        if unreached > 0.02 || seconds > 1.4 * target {
            self.easy = 0;
            return (self.scale + 1).min(MAX_REUSE_SCALE);
        }
        if unreached < 0.002 && seconds < 0.9 * target && summary.fresh as f64 > 0.1 * pixels {
            self.easy += 1;
            if self.easy >= 8 {
                self.easy = 0;
                return (self.scale - 1).max(1);
            }
        } else {
            self.easy = 0;
        }
        self.scale
    }
}
