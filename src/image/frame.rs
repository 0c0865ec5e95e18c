//! A rendered image and how it becomes pixels: the frame's per-view
//! content, its 8-bit encoding, the legend of the diagnostic views, and the
//! aa-need difference. Writing files is [`crate::export`]'s (which uses
//! frames; frames never use it).

use std::sync::Mutex;

use rayon::prelude::*;

use crate::color::{ColorConvention, to_byte};
use crate::math::{Color, DVec3};
use crate::settings::ViewMode;

/// Gain of the aa-need view: a difference of 1/4 shows at full brightness.
pub const AA_NEED_GAIN: f64 = 4.0;

/// A rendered image: linear RGB for [`ViewMode::Shaded`] and
/// [`ViewMode::Normals`]; for [`ViewMode::Depth`] the mean distance in `x`
/// and the fraction of samples that hit in `y`; for the cost views the
/// pixel's intersection tests, traversal steps and leaves visited in `x`,
/// `y`, `z` (summed over its samples and every ray they spawned); for
/// [`ViewMode::AaNeed`] the absolute sRGB difference per channel.
#[derive(Clone, Debug, PartialEq)]
pub struct Frame {
    pub width: u32,
    pub height: u32,
    pub view: ViewMode,
    /// How shaded values are written (see [`ColorConvention`]).
    pub colors: ColorConvention,
    pub pixels: Vec<DVec3>,
}

/// One pixel of a frame, as its view means it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Pixel {
    /// Shaded colour (shading values: linear light or display values).
    Color(Color),
    /// The geometric normal facing the camera, as `(n + 1) / 2`.
    Normal(DVec3),
    /// Mean distance of the samples that hit, and the share that hit.
    Depth { distance: f64, coverage: f64 },
    /// Intersection tests, traversal steps and leaves entered of every ray
    /// the pixel spawned.
    Work { tests: f64, steps: f64, leaves: f64 },
    /// |1 sample - 16 samples| per channel, as displayed.
    Difference(DVec3),
}

impl Frame {
    /// Pixel `index` (row-major from the top) as its view means it: the one
    /// place that reads the raw per-pixel triple.
    pub fn pixel(&self, index: usize) -> Pixel {
        let p = self.pixels[index];
        match self.view {
            ViewMode::Shaded => Pixel::Color(p),
            ViewMode::Normals => Pixel::Normal(p),
            ViewMode::Depth => Pixel::Depth {
                distance: p.x,
                coverage: p.y,
            },
            ViewMode::Cost | ViewMode::CostSteps => Pixel::Work {
                tests: p.x,
                steps: p.y,
                leaves: p.z,
            },
            ViewMode::AaNeed => Pixel::Difference(p),
        }
    }
}

/// The nearest visible distance among depth-view pixels (0 if none hit).
pub fn nearest_depth(pixels: &[DVec3]) -> f64 {
    pixels
        .iter()
        .filter(|p| p.y > 0.0)
        .map(|p| p.x)
        .fold(f64::INFINITY, f64::min)
        .clamp(0.0, f64::MAX)
}

/// Grey level of a depth-view pixel: `near / distance`, so the nearest
/// visible point is white and the shade falls off with distance towards
/// black at the horizon. (A linear ramp to the farthest point fails on
/// infinite planes, whose far end is at the horizon and would wash out
/// everything else.) Misses are black; partly covered pixels fade.
pub fn depth_shade(p: DVec3, near: f64) -> f64 {
    if p.y <= 0.0 || !(p.x > 0.0) {
        0.0
    } else {
        (near / p.x).clamp(0.0, 1.0) * p.y
    }
}

/// Smallest, largest and mean per-pixel cost of a cost view.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CostSummary {
    pub min: f64,
    pub max: f64,
    pub mean: f64,
}

/// The count a cost-view pixel shows.
pub fn cost_value(p: DVec3, view: ViewMode) -> f64 {
    if view == ViewMode::CostSteps {
        p.y
    } else {
        p.x
    }
}

/// Position of `value` on the colour map for a frame whose costs span `range`.
pub fn cost_shade(value: f64, (min, max): (f64, f64)) -> f64 {
    if max > min {
        (value - min) / (max - min)
    } else {
        0.0
    }
}

fn format_count(v: f64) -> String {
    if v.fract() == 0.0 && v.abs() < 1e9 {
        format!("{v:.0}")
    } else {
        format!("{v:.1}")
    }
}

/// A distance for the depth legend: three significant digits, in
/// exponent form outside 0.01 to 10^6 (tiny and huge scenes alike).
fn format_distance(v: f64) -> String {
    if (0.01..1e6).contains(&v) {
        let decimals = (2 - v.log10().floor() as i32).clamp(0, 4) as usize;
        format!("{v:.decimals$}")
    } else {
        format!("{v:.2e}")
    }
}

/// Encodes the tiles of a pass for display before the pass is complete:
/// depth is normalised by the nearest distance seen so far, cost by the
/// range seen so far (the finished pass's frame replaces them with the
/// exact picture); the other views encode exactly as [`Frame::to_rgb8`].
pub struct TileEncoder {
    view: ViewMode,
    colors: ColorConvention,
    /// Nearest and farthest value seen so far (depth: distances; cost: counts).
    range: Mutex<(f64, f64)>,
}

impl TileEncoder {
    pub fn new(view: ViewMode, colors: ColorConvention) -> Self {
        Self {
            view,
            colors,
            range: Mutex::new((f64::INFINITY, f64::NEG_INFINITY)),
        }
    }

    /// RGB8 of a tile's values, row-major.
    pub fn rgb(&self, values: &[DVec3]) -> Vec<u8> {
        let view = self.view;
        match view {
            ViewMode::Cost | ViewMode::CostSteps => {
                let range = {
                    let mut r = self.range.lock().unwrap_or_else(|e| e.into_inner());
                    for v in values {
                        let c = cost_value(*v, view);
                        r.0 = r.0.min(c);
                        r.1 = r.1.max(c);
                    }
                    *r
                };
                values
                    .iter()
                    .flat_map(|v| {
                        crate::image::legend::viridis(cost_shade(cost_value(*v, view), range))
                    })
                    .collect()
            }
            ViewMode::Depth => {
                let near = {
                    let mut r = self.range.lock().unwrap_or_else(|e| e.into_inner());
                    if values.iter().any(|v| v.y > 0.0) {
                        r.0 = r.0.min(nearest_depth(values));
                    }
                    r.0
                };
                values
                    .iter()
                    .flat_map(|v| [to_byte(depth_shade(*v, near)); 3])
                    .collect()
            }
            _ => Frame {
                width: values.len() as u32,
                height: 1,
                view,
                colors: self.colors,
                pixels: values.to_vec(),
            }
            .to_rgb8(),
        }
    }
}

/// RGB8 to opaque RGBA8.
pub fn rgb_to_rgba(rgb: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(rgb.len() / 3 * 4);
    for p in rgb.chunks_exact(3) {
        out.extend_from_slice(&[p[0], p[1], p[2], 255]);
    }
    out
}

/// RGBA8 without its alpha, as a PNG of glint's stores it.
pub fn rgba_to_rgb(rgba: &[u8]) -> Vec<u8> {
    rgba.chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect()
}

impl Frame {
    /// 8-bit RGB, row-major from the top: the shaded view encoded by its
    /// colour convention (sRGB for linear light), normals raw, depth
    /// normalised to the visible range.
    pub fn to_rgb8(&self) -> Vec<u8> {
        // Frame-wide values first, then every pixel on its own, in parallel
        // (the sRGB encoding of an 800x600 frame is 1.4 million table lookups).
        let near = (self.view == ViewMode::Depth).then(|| nearest_depth(&self.pixels));
        let range = self.cost_summary().map_or((0.0, 0.0), |c| (c.min, c.max));
        // The view and colour convention matched once a chunk, not once a
        // pixel: each arm's loop is compiled for its own encoding.
        let mut out = vec![0u8; self.pixels.len() * 3];
        out.par_chunks_mut(3 * 4096)
            .zip(self.pixels.par_chunks(4096))
            .for_each(|(bytes, pixels)| match (self.view, self.colors) {
                (ViewMode::Shaded, ColorConvention::Linear) => {
                    encode_channels(bytes, pixels, |c| ColorConvention::Linear.byte(c))
                }
                (ViewMode::Shaded, ColorConvention::Display) => {
                    encode_channels(bytes, pixels, to_byte)
                }
                (ViewMode::Normals, _) => encode_channels(bytes, pixels, to_byte),
                (ViewMode::AaNeed, _) => {
                    encode_channels(bytes, pixels, |c| to_byte(c * AA_NEED_GAIN))
                }
                (ViewMode::Depth, _) => encode_pixels(bytes, pixels, |p| {
                    [to_byte(depth_shade(p, near.unwrap_or(0.0))); 3]
                }),
                (ViewMode::Cost | ViewMode::CostSteps, _) => encode_pixels(bytes, pixels, |p| {
                    crate::image::legend::viridis(cost_shade(cost_value(p, self.view), range))
                }),
            });
        out
    }

    /// The per-pixel cost of a cost view: its smallest, largest and mean.
    pub fn cost_summary(&self) -> Option<CostSummary> {
        if !self.view.is_cost() || self.pixels.is_empty() {
            return None;
        }
        let values = self.pixels.iter().map(|p| cost_value(*p, self.view));
        let (mut min, mut max, mut sum) = (f64::INFINITY, 0.0f64, 0.0);
        for v in values {
            min = min.min(v);
            max = max.max(v);
            sum += v;
        }
        Some(CostSummary {
            min,
            max,
            mean: sum / self.pixels.len() as f64,
        })
    }

    /// The 1-sample picture's difference from the 16-sample one, as the
    /// [`ViewMode::AaNeed`] view: `|display(one) − display(sixteen)|` per
    /// channel (sRGB-encoded values for linear frames).
    pub fn aa_need(one: &Frame, sixteen: &Frame) -> Frame {
        let enc = |v: DVec3| sixteen.colors.encode_rgb(v);
        Frame {
            width: sixteen.width,
            height: sixteen.height,
            view: ViewMode::AaNeed,
            colors: sixteen.colors,
            pixels: one
                .pixels
                .iter()
                .zip(&sixteen.pixels)
                .map(|(p, q)| (enc(*p) - enc(*q)).abs())
                .collect(),
        }
    }

    /// What the legend strip of a diagnostic view says (none for the
    /// pictures that explain themselves).
    pub fn legend(&self) -> Option<crate::image::legend::Legend> {
        use crate::image::legend::{Legend, Ramp};
        match self.view {
            ViewMode::Cost | ViewMode::CostSteps => {
                let c = self.cost_summary()?;
                let what = if self.view == ViewMode::Cost {
                    "intersection tests"
                } else {
                    "traversal steps"
                };
                Some(Legend {
                    low: format_count(c.min),
                    high: format_count(c.max),
                    caption: format!("{what} per pixel, mean {}", format_count(c.mean)),
                    ramp: Ramp::Viridis,
                })
            }
            ViewMode::AaNeed => {
                let visible = self
                    .pixels
                    .iter()
                    .filter(|p| p.max_element() > 1.0 / 255.0)
                    .count() as f64
                    / self.pixels.len().max(1) as f64;
                Some(Legend {
                    low: "0".into(),
                    high: format!("{:.2}", 1.0 / AA_NEED_GAIN),
                    caption: format!(
                        "|1-16 spp| x{AA_NEED_GAIN}: {:.1}% px > 1/255",
                        100.0 * visible
                    ),
                    ramp: Ramp::Grey,
                })
            }
            ViewMode::Depth => {
                // The shade is near / distance (see `depth_shade`), so the
                // bar runs from black at the horizon to white at the
                // nearest point, mid-grey at twice its distance.
                let near = nearest_depth(&self.pixels);
                (near > 0.0 && near.is_finite()).then(|| Legend {
                    low: "far".into(),
                    high: format_distance(near),
                    caption: format!(
                        "grey = nearest / distance, mid-grey at {}",
                        format_distance(2.0 * near)
                    ),
                    ramp: Ramp::Grey,
                })
            }
            _ => None,
        }
    }

    /// The RGB8 picture as written to PNG: [`Frame::to_rgb8`] with the
    /// legend strip appended for the diagnostic views. Returns the height.
    pub fn to_annotated_rgb8(&self) -> (Vec<u8>, u32) {
        let mut rgb = self.to_rgb8();
        let height = match self.legend() {
            Some(legend) => {
                crate::image::legend::append_legend(&mut rgb, self.width, self.height, &legend)
            }
            None => self.height,
        };
        (rgb, height)
    }
}

/// An RGBA image scaled to `w x h` by nearest neighbour (opaque black when
/// there is nothing to scale).
pub fn resample_rgba(rgba: &[u8], from_w: u32, from_h: u32, w: u32, h: u32) -> Vec<u8> {
    let mut out = vec![0u8; (w * h * 4) as usize];
    let usable = from_w > 0 && from_h > 0 && rgba.len() == (from_w * from_h * 4) as usize;
    for y in 0..h {
        for x in 0..w {
            let dst = ((y * w + x) * 4) as usize;
            if usable {
                let sx = (x as u64 * from_w as u64 / w as u64) as u32;
                let sy = (y as u64 * from_h as u64 / h as u64) as u32;
                let src = ((sy * from_w + sx) * 4) as usize;
                out[dst..dst + 4].copy_from_slice(&rgba[src..src + 4]);
            } else {
                out[dst + 3] = 255;
            }
        }
    }
    out
}

/// Each pixel as three bytes by `encode`, the loop inlined for it.
#[inline(always)]
fn encode_pixels(bytes: &mut [u8], pixels: &[DVec3], encode: impl Fn(DVec3) -> [u8; 3]) {
    for (b, p) in bytes.chunks_exact_mut(3).zip(pixels) {
        b.copy_from_slice(&encode(*p));
    }
}

/// Each channel of each pixel as a byte by `byte`.
#[inline(always)]
fn encode_channels(bytes: &mut [u8], pixels: &[DVec3], byte: impl Fn(f64) -> u8) {
    encode_pixels(bytes, pixels, |p| [byte(p.x), byte(p.y), byte(p.z)]);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resampling_picks_the_nearest_source_pixel() {
        // A 2x2 image of four colours, doubled: each becomes a 2x2 block.
        let rgba: Vec<u8> = (0..4u8).flat_map(|k| [k, 10 * k, 20 * k, 255]).collect();
        let big = resample_rgba(&rgba, 2, 2, 4, 4);
        let at = |x: usize, y: usize| big[(y * 4 + x) * 4];
        let blocks: Vec<u8> = (0..4)
            .flat_map(|y| (0..4).map(move |x| (x, y)))
            .map(|(x, y)| at(x, y))
            .collect();
        assert_eq!(blocks, [0, 0, 1, 1, 0, 0, 1, 1, 2, 2, 3, 3, 2, 2, 3, 3]);
        // Halved back: the top-left pixel of each block.
        assert_eq!(resample_rgba(&big, 4, 4, 2, 2), rgba);
        // Nothing usable (a buffer of another size): opaque black.
        assert_eq!(resample_rgba(&rgba, 3, 3, 1, 1), [0, 0, 0, 255]);
    }

    #[test]
    fn a_tile_of_the_shaded_view_encodes_like_the_whole_frame() {
        let values = [
            DVec3::new(0.0, 0.5, 1.0),
            DVec3::new(2.0, -1.0, 0.25),
            DVec3::splat(0.0031308),
        ];
        let encoder = TileEncoder::new(ViewMode::Shaded, ColorConvention::Linear);
        let tile = rgb_to_rgba(&encoder.rgb(&values));
        // sRGB encoding (IEC 61966-2-1) of each channel, clamped to [0, 1].
        let srgb = |x: f64| {
            let x = x.clamp(0.0, 1.0);
            let e = if x <= 0.0031308 {
                12.92 * x
            } else {
                1.055 * x.powf(1.0 / 2.4) - 0.055
            };
            (e * 255.0).round() as u8
        };
        let expected: Vec<u8> = values
            .iter()
            .flat_map(|v| [srgb(v.x), srgb(v.y), srgb(v.z), 255])
            .collect();
        assert_eq!(tile, expected);
        assert_eq!(rgba_to_rgb(&tile), encoder.rgb(&values));
    }

    #[test]
    fn depth_tiles_are_normalised_by_the_nearest_distance_seen_so_far() {
        let encoder = TileEncoder::new(ViewMode::Depth, ColorConvention::Linear);
        // Distance 4, then a tile whose nearest point is at 2.
        let far = [DVec3::new(4.0, 1.0, 0.0), DVec3::ZERO];
        assert_eq!(encoder.rgb(&far), [255, 255, 255, 0, 0, 0]);
        let near = [DVec3::new(2.0, 1.0, 0.0)];
        assert_eq!(encoder.rgb(&near), [255, 255, 255]);
        // The first tile again: now half as bright.
        assert_eq!(encoder.rgb(&far)[0], 128);
    }
}
