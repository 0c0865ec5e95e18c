//! What one tile of a pass computes and what it gives back, shared by the
//! one-ray-at-a-time path (`sampling`) and the packet path (`packets`).

use crate::math::DVec3;
use crate::settings::ViewMode;
use crate::stats::RenderCounts;

/// What one tile of a pass computes.
#[derive(Clone, Copy)]
pub(super) enum TileJob<'a> {
    /// One ray through each pixel's centre; with `signatures`, what each
    /// ray met is kept for adaptive anti-aliasing.
    Centre { signatures: bool },
    /// The full grid in every pixel.
    Grid,
    /// The full grid where `mask` (frame-sized, row-major) marks the pixel,
    /// the one-sample value (`first`, frame-sized) elsewhere.
    Refine {
        first: &'a [DVec3],
        mask: &'a [bool],
    },
    /// The SPD protocol's corner rays: the tile is in corner coordinates
    /// (an image of `w x h` pixels has `(w + 1) x (h + 1)` corners), and
    /// each value is one corner's sample.
    Corners,
}

/// A finished tile: its pixels row-major, the signatures of a centre pass
/// that keeps them, and what it counted.
pub(super) struct TileOutput {
    pub values: Vec<DVec3>,
    pub signatures: Vec<u64>,
    pub counts: RenderCounts,
}

/// A pixel's samples as they arrive: their sum and their number.
#[derive(Clone, Copy, Default)]
pub(super) struct PixelSum {
    sum: DVec3,
    n: u32,
}

impl PixelSum {
    #[inline]
    pub(super) fn add(&mut self, sample: DVec3) {
        self.sum += sample;
        self.n += 1;
    }

    /// The pixel: the samples' mean; for the depth view the mean distance
    /// of those that hit (`x` sums distances, `y` hits) and the share that
    /// hit; for the cost views their sum (`cost_sum`) or mean.
    pub(super) fn value(&self, view: ViewMode, cost_sum: bool) -> DVec3 {
        let n = self.n.max(1) as f64;
        match view {
            ViewMode::Depth if self.sum.y > 0.0 => {
                DVec3::new(self.sum.x / self.sum.y, self.sum.y / n, 0.0)
            }
            ViewMode::Depth => DVec3::ZERO,
            ViewMode::Cost | ViewMode::CostSteps if cost_sum => self.sum,
            _ => self.sum / n,
        }
    }
}

thread_local! {
    /// Scratch space (walk stacks, shadow crossings) left by this thread's
    /// earlier tiles. Setting it up is tens of kilobytes of stores, more
    /// than the walks of a 1-sample tile's rays cost in the pass
    /// measured (bunny, normals view); kept, it is set up once per thread.
    static SPARE_SCRATCH: std::cell::RefCell<Vec<Box<dyn std::any::Any>>> =
        const { std::cell::RefCell::new(Vec::new()) };
}

/// Scratch space of type `T` this thread used before, or a new one; give
/// it back with [`keep_scratch`]. Scratch holds nothing a query reads
/// before writing, so the pixels do not depend on its past. (No closure:
/// the packet path's tile loop must stay inlined into the function
/// compiled for the SIMD level.)
pub(super) fn spare_scratch<T: Default + 'static>() -> Box<T> {
    SPARE_SCRATCH
        .with_borrow_mut(|spare| {
            let i = spare.iter().position(|s| s.is::<T>())?;
            spare.swap_remove(i).downcast::<T>().ok()
        })
        .unwrap_or_default()
}

/// Keeps `scratch` for this thread's next tile.
pub(super) fn keep_scratch<T: 'static>(scratch: Box<T>) {
    SPARE_SCRATCH.with_borrow_mut(|spare| spare.push(scratch));
}
