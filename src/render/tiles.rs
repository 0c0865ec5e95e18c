//! The image as tiles: the unit of parallel work and progress, and how
//! their values are put back into a frame.

use std::sync::Mutex;

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

impl Tile {
    pub fn pixels(&self) -> usize {
        (self.width * self.height) as usize
    }

    /// Pixel coordinates row by row, from the top left.
    pub fn coordinates(&self) -> impl Iterator<Item = (u32, u32)> + use<> {
        let (x0, x1) = (self.x, self.x + self.width);
        (self.y..self.y + self.height).flat_map(move |j| (x0..x1).map(move |i| (i, j)))
    }
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

/// The SPD corner pass's bands: the corner rows `[start, end)` of each
/// band for an image `height` pixels high (which has `height + 1` rows of
/// corners): [`TILE`] rows each, the last one also holding the bottom edge
/// (corner row `height`).
pub fn corner_bands(height: u32) -> Vec<(u32, u32)> {
    let count = height.div_ceil(TILE).max(1);
    (0..count)
        .map(|k| {
            let start = k * TILE;
            let end = if k + 1 == count {
                height + 1
            } else {
                start + TILE
            };
            (start, end)
        })
        .collect()
}

/// A frame's rows in bands of [`TILE`] rows, each behind a lock of its
/// own, for the tiles [`tiles`] lists to be placed into as they finish: a
/// tile lies in one band, and tiles of different bands never wait for each
/// other.
pub struct TileBands<'a, T> {
    width: u32,
    bands: Vec<Mutex<&'a mut [T]>>,
}

impl<'a, T: Copy> TileBands<'a, T> {
    /// The bands of `frame`, `width` values a row.
    pub fn new(frame: &'a mut [T], width: u32) -> Self {
        let band = (width * TILE).max(1) as usize;
        Self {
            width,
            bands: frame.chunks_mut(band).map(Mutex::new).collect(),
        }
    }

    /// Copies `tile`'s row-major `values` into its place.
    pub fn place(&self, tile: &Tile, values: &[T]) {
        // A tile that panicked while copying wrote only its own columns;
        // the pass fails anyway, and the others need not panic as well.
        let mut band = self.bands[(tile.y / TILE) as usize]
            .lock()
            .unwrap_or_else(|e| e.into_inner());
        let within = Tile {
            y: tile.y % TILE,
            ..*tile
        };
        place_tile(&mut band, self.width, &within, values, 1);
    }
}

/// Copies a tile's row-major values into a frame-sized buffer of
/// `width`-pixel rows, `channels` values a pixel (1 for per-pixel values,
/// 4 for RGBA bytes).
pub fn place_tile<T: Copy>(frame: &mut [T], width: u32, tile: &Tile, values: &[T], channels: u32) {
    let row_len = (tile.width * channels) as usize;
    for row in 0..tile.height {
        let start = (((tile.y + row) * width + tile.x) * channels) as usize;
        let src = row as usize * row_len;
        frame[start..start + row_len].copy_from_slice(&values[src..src + row_len]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tiles_cover_the_image_once_in_row_major_order() {
        let all = tiles(40, 20);
        let mut seen = vec![0u32; 40 * 20];
        for t in &all {
            for (i, j) in t.coordinates() {
                seen[(j * 40 + i) as usize] += 1;
            }
        }
        assert!(seen.iter().all(|&n| n == 1));
        let corners: Vec<(u32, u32, u32, u32)> =
            all.iter().map(|t| (t.x, t.y, t.width, t.height)).collect();
        assert_eq!(
            corners,
            [
                (0, 0, 16, 16),
                (16, 0, 16, 16),
                (32, 0, 8, 16),
                (0, 16, 16, 4),
                (16, 16, 16, 4),
                (32, 16, 8, 4)
            ]
        );
    }

    #[test]
    fn a_placed_tile_lands_on_its_rows() {
        let mut frame = vec![0u8; 4 * 3 * 2];
        let tile = Tile {
            x: 1,
            y: 1,
            width: 2,
            height: 2,
        };
        place_tile(&mut frame, 4, &tile, &[1, 1, 2, 2, 3, 3, 4, 4], 2);
        assert_eq!(
            frame,
            [
                0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 2, 2, 0, 0, 0, 0, 3, 3, 4, 4, 0, 0
            ]
        );
    }

    #[test]
    fn tiles_placed_in_bands_are_the_tiles_placed_whole() {
        for (width, height) in [(1, 1), (16, 16), (17, 3), (40, 20), (37, 33)] {
            let all = tiles(width, height);
            let values: Vec<Vec<u32>> = (0..all.len() as u32)
                .map(|k| {
                    (0..all[k as usize].pixels() as u32)
                        .map(|p| k << 16 | p)
                        .collect()
                })
                .collect();
            let mut whole = vec![u32::MAX; (width * height) as usize];
            for (t, v) in all.iter().zip(&values) {
                place_tile(&mut whole, width, t, v, 1);
            }
            let mut banded = vec![u32::MAX; (width * height) as usize];
            let bands = TileBands::new(&mut banded, width);
            for (t, v) in all.iter().zip(&values).rev() {
                bands.place(t, v);
            }
            assert_eq!(banded, whole, "{width}x{height}");
            assert!(!whole.contains(&u32::MAX), "{width}x{height}");
        }
    }

    #[test]
    fn bands_hold_every_corner_row_once() {
        for height in [1, 15, 16, 17, 33, 512] {
            let b = corner_bands(height);
            assert_eq!(b[0].0, 0);
            assert_eq!(b.last().unwrap().1, height + 1);
            for pair in b.windows(2) {
                assert_eq!(pair[0].1, pair[1].0, "height {height}");
            }
            assert_eq!(b.len() as u32, height.div_ceil(TILE));
        }
    }
}
