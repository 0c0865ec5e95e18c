//! The image as tiles: the unit of parallel work and progress, and how
//! their results are put back together (summing counts in tile order, so
//! totals never depend on the thread schedule).

use crate::frame::Frame;
use crate::math::DVec3;
use crate::settings::RenderSettings;
use crate::stats::{RayCounts, WorkCounts};

/// Square tile edge in pixels: the unit of parallel work and of progress.
pub const TILE: u32 = 16;

/// A rectangle of pixels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tile {
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
}

/// Tiles covering a `width` x `height` image in row-major order.
pub fn tiles(width: u32, height: u32) -> Vec<Tile> {
    let mut out = Vec::new();
    for y in (0..height).step_by(TILE as usize) {
        for x in (0..width).step_by(TILE as usize) {
            out.push(Tile {
                x,
                y,
                width: TILE.min(width - x),
                height: TILE.min(height - y),
            });
        }
    }
    out
}

/// Per-tile work, summed in tile order so totals never depend on threads.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct TileCounts {
    pub rays: RayCounts,
    pub work: WorkCounts,
    /// Samples whose colour came out NaN or infinite (then shown black).
    /// Always zero unless something is wrong: tests assert it.
    pub nonfinite_samples: u64,
    /// Pixels adaptive anti-aliasing refined with the full grid.
    pub refined_pixels: u64,
}

impl std::ops::AddAssign for TileCounts {
    fn add_assign(&mut self, o: Self) {
        self.refined_pixels += o.refined_pixels;
        self.rays += o.rays;
        self.work += o.work;
        self.nonfinite_samples += o.nonfinite_samples;
    }
}

/// Copies a tile's row-major values into a frame-sized buffer.
pub fn place_tile<T: Copy>(frame: &mut [T], width: u32, tile: &Tile, values: &[T]) {
    for row in 0..tile.height {
        let start = ((tile.y + row) * width + tile.x) as usize;
        let src = (row * tile.width) as usize;
        frame[start..start + tile.width as usize]
            .copy_from_slice(&values[src..src + tile.width as usize]);
    }
}

/// Puts rendered tiles together into a frame, summing their counts in tile
/// order (so totals never depend on the thread schedule).
pub fn assemble_tiles(
    settings: &RenderSettings,
    tiles: &[Tile],
    results: impl IntoIterator<Item = (Vec<DVec3>, TileCounts)>,
) -> (Frame, TileCounts) {
    let (width, height) = (settings.width, settings.height);
    let mut pixels = vec![DVec3::ZERO; (width * height) as usize];
    let mut counts = TileCounts::default();
    for (tile, (values, c)) in tiles.iter().zip(results) {
        counts += c;
        place_tile(&mut pixels, width, tile, &values);
    }
    let frame = Frame {
        width,
        height,
        view: settings.view,
        colors: settings.colors,
        pixels,
    };
    (frame, counts)
}
