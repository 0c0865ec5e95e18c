//! Adaptive anti-aliasing: the full 4x4 grid only where the picture needs
//! it. A first pass traces each pixel's centre and keeps, besides its
//! colour, a signature of what the eye ray met (the material hit, which
//! lights reach the point); a pixel is refined when its 3x3 neighbourhood
//! shows an edge: another material or the background, a shadow boundary,
//! or a displayed colour that differs by more than [`CONTRAST`]. Refined
//! pixels get exactly the value the full grid gives them; the others keep
//! their centre sample.
//!
//! The idea is Whitted's own (1980: subdivide where neighbouring samples
//! differ), here with the regular grid glint uses everywhere.

use rayon::prelude::*;

use crate::math::Color;
use crate::render::ray_tree::{RayKind, RayRecorder};

/// Largest difference, in 8-bit display steps on any channel, between
/// neighbouring centre samples that still counts as smooth: the largest
/// step that keeps a wide margin over the 45 dB against the full grid
/// that glint aims for (docs/notes/experiments.md, "Figures behind
/// constants").
pub const CONTRAST: u8 = 8;

/// What an eye ray met, for telling edges apart: the material of its first
/// hit (+1; 0 for the background) in the low 32 bits, the lights reaching
/// that point in the high 32 (light `i` as bit `i % 32`).
#[derive(Clone, Copy, Debug, Default)]
pub struct Signature {
    pub value: u64,
    /// Records of secondary rays are dropped: only the eye ray's hit counts.
    nested: bool,
}

impl RayRecorder for Signature {
    #[inline(always)]
    fn child(&self, _: RayKind, _: &crate::math::Ray, _: u32, _: f64) -> Self {
        Signature {
            value: 0,
            nested: true,
        }
    }

    #[inline(always)]
    fn material(&mut self, index: u32) {
        if !self.nested {
            self.value |= index as u64 + 1;
        }
    }

    #[inline(always)]
    fn light(&mut self, index: usize, lit: bool) {
        if !self.nested && lit {
            self.value |= 1 << (32 + index % 32);
        }
    }

    #[inline(always)]
    fn attach(&mut self, _child: Self, _color: Color) {}
}

/// Which pixels of a `width x height` first pass to refine: those whose 3x3
/// neighbourhood (clipped at the image's edge) holds another signature or
/// a displayed value (`rgb`, 3 bytes a pixel) more than [`CONTRAST`] away.
pub fn refine_mask(rgb: &[u8], signatures: &[u64], width: u32, height: u32) -> Vec<bool> {
    let (w, h) = (width as usize, height as usize);
    let differs = |a: usize, b: usize| {
        signatures[a] != signatures[b]
            || (0..3).any(|c| rgb[3 * a + c].abs_diff(rgb[3 * b + c]) > CONTRAST)
    };
    // Each pair of neighbours is compared once, as a bit of its first
    // pixel (right, down, down-right, down-left), rows in parallel; then a
    // pixel is marked by its own pairs and those its neighbours hold with
    // it. (Serially, over an 800x600 frame, this took 6 ms.)
    const RIGHT: u8 = 1;
    const DOWN: u8 = 2;
    const DOWN_RIGHT: u8 = 4;
    const DOWN_LEFT: u8 = 8;
    let row_len = w.max(1);
    let mut pairs = vec![0u8; w * h];
    pairs
        .par_chunks_mut(row_len)
        .enumerate()
        .for_each(|(y, row)| {
            for (x, bits) in row.iter_mut().enumerate() {
                let a = y * w + x;
                let mut b = 0;
                if x + 1 < w && differs(a, a + 1) {
                    b |= RIGHT;
                }
                if y + 1 < h {
                    if differs(a, a + w) {
                        b |= DOWN;
                    }
                    if x + 1 < w && differs(a, a + w + 1) {
                        b |= DOWN_RIGHT;
                    }
                    if x > 0 && differs(a, a + w - 1) {
                        b |= DOWN_LEFT;
                    }
                }
                *bits = b;
            }
        });
    let mut mask = vec![false; w * h];
    mask.par_chunks_mut(row_len)
        .enumerate()
        .for_each(|(y, row)| {
            for (x, marked) in row.iter_mut().enumerate() {
                let a = y * w + x;
                // The pair `bit` that pixel `nx` of the row above holds.
                let above = |nx: Option<usize>, bit: u8| {
                    y > 0 && nx.is_some_and(|nx| nx < w && pairs[(y - 1) * w + nx] & bit != 0)
                };
                *marked = pairs[a] != 0
                    || (x > 0 && pairs[a - 1] & RIGHT != 0)
                    || above(Some(x), DOWN)
                    || above(x.checked_sub(1), DOWN_RIGHT)
                    || above(Some(x + 1), DOWN_LEFT);
            }
        });
    mask
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edges_mark_both_sides_and_flat_regions_stay() {
        // 4x3: a vertical colour edge between columns 1 and 2, and one pixel
        // of another material in the bottom-left corner.
        let (w, h) = (4u32, 3u32);
        let mut rgb = vec![0u8; 36];
        for y in 0..3 {
            for x in 2..4 {
                rgb[3 * (y * 4 + x)] = 200;
            }
        }
        let mut signatures = vec![1u64; 12];
        signatures[8] = 2;
        let mask = refine_mask(&rgb, &signatures, w, h);
        let marked: Vec<usize> = (0..12).filter(|&i| mask[i]).collect();
        // Columns 1 and 2 everywhere; the corner pixel and its neighbours.
        assert_eq!(marked, vec![1, 2, 4, 5, 6, 8, 9, 10]);
        // A contrast of CONTRAST steps is smooth, one more is an edge.
        let c = CONTRAST;
        let flat = refine_mask(&[10, 10, 10, 10 + c, 10, 10 + c], &[1, 1], 2, 1);
        assert_eq!(flat, vec![false, false]);
        let edge = refine_mask(&[10, 10, 10, 11 + c, 10, 10], &[1, 1], 2, 1);
        assert_eq!(edge, vec![true, true]);
    }

    #[test]
    fn a_pixel_is_marked_by_any_differing_pair_it_is_in() {
        // Against the mask built pair by pair (right, down and both
        // diagonals, marking both pixels), on sparse random edges.
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = move || {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state
        };
        for (w, h) in [(1, 1), (1, 9), (9, 1), (2, 2), (7, 5), (33, 17)] {
            let n = w * h;
            let rgb: Vec<u8> = (0..3 * n)
                .map(|_| if next() % 29 == 0 { 200 } else { 100 })
                .collect();
            let signatures: Vec<u64> = (0..n).map(|_| (next() % 37 == 0) as u64).collect();
            let differs = |a: usize, b: usize| {
                signatures[a] != signatures[b]
                    || (0..3).any(|c| rgb[3 * a + c].abs_diff(rgb[3 * b + c]) > CONTRAST)
            };
            let mut pairwise = vec![false; n];
            for y in 0..h {
                for x in 0..w {
                    let a = y * w + x;
                    let right = (x + 1 < w).then_some(a + 1);
                    let below = (y + 1 < h).then_some(a + w);
                    let below_right = (y + 1 < h && x + 1 < w).then_some(a + w + 1);
                    let below_left = (y + 1 < h && x > 0).then(|| a + w - 1);
                    for b in [right, below, below_right, below_left]
                        .into_iter()
                        .flatten()
                    {
                        if differs(a, b) {
                            pairwise[a] = true;
                            pairwise[b] = true;
                        }
                    }
                }
            }
            let mask = refine_mask(&rgb, &signatures, w as u32, h as u32);
            assert_eq!(mask, pairwise, "{w}x{h}");
            if n > 100 {
                let marked = mask.iter().filter(|&&m| m).count();
                assert!(marked > 0 && marked < n, "{w}x{h}: {marked} marked");
            }
        }
        // One column and one row, each with an edge across it.
        let mut signatures = vec![0u64; 4];
        signatures[2..].fill(1);
        let line = [false, true, true, false];
        assert_eq!(refine_mask(&[100; 12], &signatures, 1, 4), line);
        assert_eq!(refine_mask(&[100; 12], &signatures, 4, 1), line);
    }
}
