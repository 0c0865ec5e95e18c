//! The render cache (Walter, Drettakis and Parker 1999): previews that keep
//! the picture while the camera, a light or a material changes, on a CPU's
//! few cores, over the whole image and with the scene's own shading
//! (reflections, refraction, shadows, its depth). The cache's size is its
//! renderer's: a caller short of time keeps a point for every block of
//! pixels ([`shrink`], [`enlarge`]).
//!
//! Every pixel of the last preview, or of the finished image the first one
//! starts from, is kept as a shaded point: where its eye ray hit and the
//! colour seen from there. A new view reprojects the points
//! (`reproject.rs`: the nearest in each pixel shows, and one with nearer
//! points of one surface on two opposite sides is taken as seen through a
//! gap and dropped), spends the frame's time on fresh eye rays
//! (`trace.rs`: first the pixels no point reached, then those an edit
//! changed, then in turn an interleaved sixteenth of the image, the
//! points whose colour depends on the eye before the others, as frameless
//! rendering updates pixels in a spread order: Bishop et al. 1994), and
//! fills what is still empty from the farthest of its neighbours
//! (`fill.rs`: a gap just uncovered shows what lies behind the edge that
//! uncovered it). A filled pixel is kept as a point too, at the depth it
//! was filled from, so the picture does not thin out between frames where
//! rays are scarce. Fresh and filled points take the sub-pixel place of
//! the points around them, so a surface's points keep one spacing as they
//! move.
//!
//! Which terms are reused: a point's ambient and diffuse light, with its
//! shadows, belongs to the surface and stays right from any eye; its
//! highlights and what its mirror and glass rays see move with the eye. So
//! the points of materials that reflect, refract or shine are re-traced
//! first, every pixel within sixteen frames when the budget allows; a
//! purely diffuse point after them. Edits re-trace what
//! they change where the cache can know it: a changed material, the pixels
//! whose ray trees met it (known exactly for points traced here, and for
//! seeded points on materials that spawn no secondary rays; every other
//! point is assumed to have met it); a moved or recoloured light, or a
//! changed transparent material (whose shadows the cache does not track),
//! every pixel that hit a surface.
//!
//! Where the approximation shows: a mirror or glass point not yet traced
//! again shows what it saw from an older eye (reflections lag a frame or
//! two behind a fast orbit); a reprojected point sits up to half a pixel
//! off its pixel's centre, so edges are slightly ragged until re-traced; a
//! filled pixel is a blend of its neighbours; an edited material or light
//! shows its old colour where the frame's time did not reach.
//!
//! Previews are approximations and are never written as renders: once the
//! motion stops, the usual passes give the exact picture.
//!
//! Cost: a preview touches every pixel a few times, so its passes are
//! fused, its points small (24 bytes) and kept in pixel order, its
//! tallies sampled, and every buffer is kept from frame to frame (a fresh
//! allocation of a frame's size costs as much as the work done in it: its
//! pages are faulted in anew).

mod fill;
mod point;
mod reproject;
mod trace;

use crate::settings::Accel;
use std::sync::Arc;
use std::time::{Duration, Instant};

use rayon::prelude::*;

use crate::material::{Light, Material};
use crate::math::{Color, DVec3};
use crate::settings::{RenderSettings, ViewMode};
use crate::shapes::Shape;
use crate::stats::RayCounts;

use super::Renderer;
pub use point::PixelSource;
use point::{Pixels, Point, reset};

/// Largest image the render cache keeps points for: it holds about 100
/// bytes a pixel (up to three points, the depth test's buffers, the
/// picture), so 200 MB at this size (a 1920x1080 image fits); the depth
/// test's keys hold a point's index in 24 bits.
pub const MAX_PIXELS: u64 = 1 << 21;

/// Whether the render cache serves previews of frames with `settings`: the
/// shaded view (the other views show what a ray met, not light that
/// could be reused) under glint's own rules (the SPD's corner rays have no
/// pixel centres to keep), up to [`MAX_PIXELS`].
pub fn serves(settings: &RenderSettings) -> bool {
    settings.view == ViewMode::Shaded
        && !settings.corner_rays()
        && u64::from(settings.width) * u64::from(settings.height) <= MAX_PIXELS
}

/// What one preview is made of.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct PreviewSummary {
    pub fresh: u64,
    pub reprojected: u64,
    pub stale: u64,
    pub filled: u64,
    /// Points dropped as seen through a gap in a nearer surface.
    pub occluded: u64,
    /// Pixels no point reached, and those of them no fresh ray reached
    /// either (filled from their neighbours).
    pub gaps: u64,
    pub gaps_filled: u64,
    /// The median age of the reprojected points, in frames.
    pub median_age: u8,
    /// The cache was filled from a finished image first.
    pub seeded: bool,
    /// The cache kept a point for every `scale x scale` pixels of the
    /// picture shown (set by its user; 0: not said).
    pub scale: u32,
    /// Rays the fresh pixels traced.
    pub rays: RayCounts,
    /// Seconds spent seeding (0 when not), reprojecting, tracing and
    /// filling.
    pub seed_seconds: f64,
    pub reproject_seconds: f64,
    pub trace_seconds: f64,
    pub fill_seconds: f64,
}

impl PreviewSummary {
    /// Pixels in the preview.
    pub fn pixels(&self) -> u64 {
        self.fresh + self.reprojected + self.stale + self.filled
    }

    /// E.g. "1/2 resolution, 12 % fresh rays, 85 % reused (median age 3),
    /// 3 % filled".
    pub fn describe(&self) -> String {
        let all = self.pixels().max(1) as f64;
        let share = |n: u64| {
            let p = 100.0 * n as f64 / all;
            if n > 0 && p < 1.0 {
                "<1".to_string()
            } else {
                format!("{p:.0}")
            }
        };
        let mut s = match self.scale {
            0 | 1 => String::new(),
            k => format!("1/{k} resolution, "),
        };
        s += &format!(
            "{} % fresh rays, {} % reused (median age {}), {} % filled",
            share(self.fresh),
            share(self.reprojected),
            self.median_age,
            share(self.filled)
        );
        if self.stale > 0 {
            s.push_str(&format!(", {} % awaiting the edit", share(self.stale)));
        }
        s
    }
}

/// What the kept points were shaded with: a preview of anything else
/// re-traces what differs, or starts over.
#[derive(Clone)]
struct Basis {
    /// The geometry (shared, so compared by address).
    shapes: Arc<Vec<Shape>>,
    shape_colors: Arc<Vec<u32>>,
    lights: Vec<Light>,
    materials: Vec<Material>,
    background: Color,
    ambient: Color,
    /// The settings that decide a pixel's colour besides the camera.
    settings: RenderSettings,
}

impl Basis {
    fn of(renderer: &Renderer) -> Self {
        let scene = renderer.scene;
        let mut settings = *renderer.settings();
        // The samples and accelerator change nothing a preview shows.
        settings.samples = 1;
        settings.adaptive = false;
        settings.accel = Accel::Octree;
        Self {
            shapes: Arc::clone(&scene.shapes),
            shape_colors: Arc::clone(&scene.shape_colors),
            lights: scene.lights.clone(),
            materials: scene.materials.clone(),
            background: scene.image.background,
            ambient: scene.image.ambient,
            settings,
        }
    }

    /// Whether points shaded with `self` can stand in `other`'s picture
    /// after the changes [`Basis::changes`] finds.
    fn compatible(&self, other: &Basis) -> bool {
        Arc::ptr_eq(&self.shapes, &other.shapes)
            && Arc::ptr_eq(&self.shape_colors, &other.shape_colors)
            && self.settings == other.settings
            && self.background == other.background
            && self.ambient == other.ambient
            && self.lights.len() == other.lights.len()
            && self.materials.len() == other.materials.len()
    }

    /// What changed from `self` to `other`: whether every surface point
    /// may have (a light changed, or a transparent material, whose
    /// shadows dim what lies behind it: the cache does not know which
    /// shadow rays crossed it), and the materials that did (bit `m % 32`).
    fn changes(&self, other: &Basis) -> (bool, u32) {
        let mut everything = self.lights != other.lights;
        let mut materials = 0u32;
        for (m, (a, b)) in self.materials.iter().zip(&other.materials).enumerate() {
            if a != b {
                materials |= 1 << (m % 32);
                everything |= a.transparency > 0.0 || b.transparency > 0.0;
            }
        }
        (everything, materials)
    }
}

/// The render cache: a shaded point for each pixel of the last preview.
#[derive(Default)]
pub struct RenderCache {
    width: u32,
    height: u32,
    anchor: DVec3,
    /// The last preview's pixels, and the next one's being made.
    pixels: Pixels,
    next: Pixels,
    /// Frames made, wrapping: points are aged by it.
    frame: u16,
    basis: Option<Basis>,
    reproject: reproject::Scratch,
    trace: trace::Scratch,
    fill: fill::Scratch,
}

/// How long a preview's fresh rays may take.
#[derive(Clone, Copy, Debug)]
pub struct PreviewBudget {
    /// From the first fresh ray: no chunk of rays starts after this.
    pub rays: Duration,
}

impl RenderCache {
    /// Whether the cache holds points `renderer` can reuse (else the next
    /// preview must be seeded).
    pub fn can_serve(&self, renderer: &Renderer) -> bool {
        let s = renderer.settings();
        self.width == s.width
            && self.height == s.height
            && self
                .basis
                .as_ref()
                .is_some_and(|b| b.compatible(&Basis::of(renderer)))
    }

    /// Forgets every point.
    pub fn clear(&mut self) {
        self.pixels.points.clear();
        self.basis = None;
    }

    /// The last preview: RGBA8, `width x height`.
    pub fn image(&self) -> (&[u8], u32, u32) {
        (&self.pixels.rgba, self.width, self.height)
    }

    /// Where each pixel of the last preview came from.
    pub fn sources(&self) -> Vec<PixelSource> {
        let now = self.frame;
        self.pixels
            .points
            .par_iter()
            .map(|p| p.source(now))
            .collect()
    }

    /// Fills the cache from a finished image of `renderer`'s scene,
    /// settings and camera: `rgba` (RGBA8, the image as shown) gives the
    /// colours, an eye ray through each pixel's centre the points.
    /// Returns the seconds it took.
    pub fn seed(&mut self, renderer: &Renderer, rgba: &[u8]) -> f64 {
        let start = Instant::now();
        let s = renderer.settings();
        self.width = s.width;
        self.height = s.height;
        self.anchor = renderer.camera().eye;
        trace::seed_points(
            renderer,
            self.anchor,
            rgba,
            self.frame,
            &mut self.pixels.points,
        );
        self.basis = Some(Basis::of(renderer));
        start.elapsed().as_secs_f64()
    }

    /// The preview of `renderer`'s view, then in [`RenderCache::image`]:
    /// the kept points reprojected into it, fresh rays where they matter
    /// most for `budget`, the rest filled. Seeds from `seed` first (a
    /// finished image, RGBA8 as shown, of that renderer's view) when the
    /// cache cannot serve this view and the seed can.
    pub fn preview(
        &mut self,
        renderer: &Renderer,
        seed: Option<(&Renderer, &[u8])>,
        budget: PreviewBudget,
    ) -> PreviewSummary {
        let mut summary = PreviewSummary::default();
        let basis = Basis::of(renderer);
        let (width, height) = (renderer.settings().width, renderer.settings().height);
        let reusable = self.basis.as_ref().is_some_and(|b| b.compatible(&basis))
            && (self.width, self.height) == (width, height);
        if !reusable {
            self.clear();
            if let Some((seed_renderer, rgba)) = seed
                && Basis::of(seed_renderer).compatible(&basis)
                && rgba.len() == 4 * (width * height) as usize
            {
                summary.seed_seconds = self.seed(seed_renderer, rgba);
                summary.seeded = true;
            } else {
                self.width = width;
                self.height = height;
                self.anchor = renderer.camera().eye;
                self.basis = Some(basis.clone());
            }
        }
        // Edits since the points were shaded: what they touched is stale.
        if let Some(old) = &self.basis {
            let (everything, materials) = old.changes(&basis);
            if everything || materials != 0 {
                mark_stale(&mut self.pixels.points, everything, materials);
            }
        }
        self.basis = Some(basis);
        self.frame = self.frame.wrapping_add(1);
        let now = self.frame;

        let start = Instant::now();
        let frame = reproject::reproject(
            &self.pixels.points,
            self.anchor,
            renderer.camera(),
            &mut self.next,
            &mut self.reproject,
        );
        summary.occluded = frame.occluded;
        summary.gaps = frame.gaps.len() as u64;
        summary.reproject_seconds = start.elapsed().as_secs_f64();

        let start = Instant::now();
        let traced = trace::trace_in_turn(
            renderer,
            self.anchor,
            &self.next.points,
            frame.gaps,
            frame.phase,
            now,
            start + budget.rays,
            &mut self.trace,
        );
        summary.rays = traced.rays;
        for &(pixel, point, depth) in &traced.points {
            let p = pixel as usize;
            self.next.points[p] = point;
            self.next.depth[p] = depth;
            self.next.rgba[4 * p..4 * p + 3].copy_from_slice(&point.rgb);
        }
        summary.trace_seconds = start.elapsed().as_secs_f64();

        let start = Instant::now();
        summary.gaps_filled = fill::fill(
            &mut self.next,
            frame.gaps,
            frame.phase,
            renderer.camera(),
            self.anchor,
            now,
            &mut self.fill,
        );
        std::mem::swap(&mut self.pixels, &mut self.next);
        tally(&self.pixels.points, now, &mut summary);
        summary.fill_seconds = start.elapsed().as_secs_f64();
        summary
    }

    /// The last preview coloured by where each pixel came from: fresh rays
    /// green, reused points from blue (new) to violet (old), stale points
    /// orange, filled pixels red; each shaded by the picture's own
    /// brightness so the scene stays recognisable. Written into `out`
    /// (RGBA8).
    pub fn source_colors(&self, out: &mut Vec<u8>) {
        let now = self.frame;
        reset(out, self.pixels.rgba.len(), 255);
        out.par_chunks_mut(4)
            .zip(self.pixels.rgba.par_chunks(4))
            .zip(self.pixels.points.par_iter())
            .for_each(|((px, rgba), point)| {
                let tint: [f32; 3] = match point.source(now) {
                    PixelSource::Fresh => [0.2, 0.9, 0.3],
                    PixelSource::Reprojected { age } => {
                        let t = (f32::from(age.min(30)) / 30.0).sqrt();
                        [0.25 + 0.45 * t, 0.45 - 0.3 * t, 1.0 - 0.25 * t]
                    }
                    PixelSource::Stale => [1.0, 0.6, 0.1],
                    PixelSource::Filled => [1.0, 0.15, 0.1],
                };
                let [r, g, b] = [rgba[0], rgba[1], rgba[2]].map(f32::from);
                let shade = 0.35 + 0.65 * (0.3 * r + 0.59 * g + 0.11 * b) / 255.0;
                for c in 0..3 {
                    px[c] = (255.0 * tint[c] * shade).round().clamp(0.0, 255.0) as u8;
                }
            });
    }
}

/// Every how many pixels (along a row, and a different row each time) a
/// preview's tallies count: a sixteenth of the pixels gives the shares to
/// well under a percent.
const TALLY_STRIDE: usize = 16;

/// How many pixels of a preview come from each source, and the reused
/// points' median age, counted on a sample of the pixels ([`TALLY_STRIDE`])
/// and scaled to the whole picture.
fn tally(points: &[Point], now: u16, summary: &mut PreviewSummary) {
    // Reprojected points by age, then fresh, stale and filled pixels.
    let counts = points
        .par_chunks(TALLY_STRIDE * 4096)
        .map(|chunk| {
            let mut c = [0u64; 259];
            for p in chunk.iter().step_by(TALLY_STRIDE) {
                let k = match p.source(now) {
                    PixelSource::Reprojected { age } => usize::from(age),
                    PixelSource::Fresh => 256,
                    PixelSource::Stale => 257,
                    PixelSource::Filled => 258,
                };
                c[k] += 1;
            }
            c
        })
        .reduce(
            || [0u64; 259],
            |mut a, b| {
                for (x, y) in a.iter_mut().zip(b) {
                    *x += y;
                }
                a
            },
        );
    let sampled: u64 = counts.iter().sum();
    let scale = |n: u64| (n as f64 * points.len() as f64 / sampled.max(1) as f64).round() as u64;
    summary.fresh = scale(counts[256]);
    summary.stale = scale(counts[257]);
    summary.filled = scale(counts[258]);
    summary.reprojected =
        (points.len() as u64).saturating_sub(summary.fresh + summary.stale + summary.filled);
    let reused: u64 = counts[..256].iter().sum();
    let mut below = 0;
    for (age, &n) in counts[..256].iter().enumerate() {
        below += n;
        if 2 * below > reused {
            summary.median_age = age as u8;
            break;
        }
    }
}

/// Marks the points an edit changed: with `everything`, every surface
/// point; else those whose ray trees met one of `materials`.
fn mark_stale(points: &mut [Point], everything: bool, materials: u32) {
    points.par_iter_mut().for_each(|p| {
        if !p.is(Point::BACKGROUND | Point::NOTHING) && (everything || p.touched & materials != 0) {
            p.flags |= Point::STALE;
        }
    });
}

/// `rgba` (RGBA8, `width x height`) averaged over blocks of `factor x
/// factor` pixels (the last ones clipped at the edges): a finished image
/// made the size of a cache that keeps a point for every such block.
pub fn shrink(rgba: &[u8], (width, height): (u32, u32), factor: u32) -> Vec<u8> {
    let (w, h, f) = (width as usize, height as usize, factor.max(1) as usize);
    let (sw, sh) = (w.div_ceil(f), h.div_ceil(f));
    let mut out = vec![255u8; 4 * sw * sh];
    out.par_chunks_mut(4 * sw).enumerate().for_each(|(y, row)| {
        for (x, px) in row.chunks_exact_mut(4).enumerate() {
            let (mut sum, mut n) = ([0u32; 3], 0);
            for j in f * y..(f * y + f).min(h) {
                for i in f * x..(f * x + f).min(w) {
                    for c in 0..3 {
                        sum[c] += u32::from(rgba[4 * (j * w + i) + c]);
                    }
                    n += 1;
                }
            }
            for c in 0..3 {
                px[c] = ((sum[c] + n / 2) / n.max(1)) as u8;
            }
        }
    });
    out
}

/// `rgba` (RGBA8, `from`) enlarged to `to` into `out`, interpolated
/// bilinearly between the centres of the pixels (as a texture is drawn
/// larger); `smooth` false takes the nearest pixel instead (for the source
/// view, whose colours are labels). Weights in 1/256ths, the same for
/// every row and column of a size: a frame's enlargement is a few table
/// look-ups and integer multiplications a channel.
pub fn enlarge(rgba: &[u8], from: (u32, u32), to: (u32, u32), smooth: bool, out: &mut Vec<u8>) {
    let (fw, fh) = (from.0 as usize, from.1 as usize);
    let (w, h) = (to.0 as usize, to.1 as usize);
    reset(out, 4 * w * h, 255);
    if fw == 0 || fh == 0 || rgba.len() < 4 * fw * fh {
        return;
    }
    // For each output column (row): the two source columns (rows) and the
    // second one's weight.
    let taps = |n: usize, m: usize| -> Vec<(usize, usize, u32)> {
        (0..n)
            .map(|x| {
                let u = ((x as f64 + 0.5) * m as f64 / n as f64 - 0.5).clamp(0.0, (m - 1) as f64);
                let (a, t) = (u as usize, u - u.floor());
                let weight = if smooth {
                    (t * 256.0).round() as u32
                } else {
                    256 * u32::from(t >= 0.5)
                };
                (a, (a + 1).min(m - 1), weight)
            })
            .collect()
    };
    let (columns, rows) = (taps(w, fw), taps(h, fh));
    out.par_chunks_mut(4 * w)
        .zip(rows.par_iter())
        .for_each(|(row, &(y0, y1, wy))| {
            let (top, bottom) = (
                &rgba[4 * y0 * fw..4 * (y0 + 1) * fw],
                &rgba[4 * y1 * fw..4 * (y1 + 1) * fw],
            );
            for (px, &(x0, x1, wx)) in row.chunks_exact_mut(4).zip(&columns) {
                for c in 0..3 {
                    let mix = |line: &[u8]| {
                        u32::from(line[4 * x0 + c]) * (256 - wx) + u32::from(line[4 * x1 + c]) * wx
                    };
                    let v = mix(top) * (256 - wy) + mix(bottom) * wy;
                    px[c] = ((v + (1 << 15)) >> 16) as u8;
                }
            }
        });
}

#[cfg(test)]
mod tests;
