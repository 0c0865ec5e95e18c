//! Kept points moved into a new view: each lands in the pixel its position
//! projects into and the nearest of those that land in one pixel shows (a
//! depth test: each thread keeps the nearest it saw per pixel, then the
//! threads' nearest are merged). One with nearer points of one surface on
//! two opposite sides is taken as seen through a gap that surface opened as
//! it moved, and dropped (after Walter, Drettakis and Parker 1999's depth
//! culling, which compares with the neighbourhood's depths alone and so
//! also drops what shows in the corner where two nearer surfaces meet).
//!
//! Three passes, each in parallel: the points into per-thread depth
//! buffers; the buffers merged into each pixel's nearest point and its
//! depth; then, per pixel, the depth culling, the point it shows and the
//! picture, and the pixels left without a point. (A pass over a frame
//! costs about a millisecond on a 2-core machine: the steps are fused
//! rather than one pass each.)

use rayon::prelude::*;

use super::point::{Pixels, Point, reset};

/// No point landed in this pixel.
const NONE: u32 = u32::MAX;
use crate::camera::Camera;
use crate::math::DVec3;

/// No point in this pixel, as a depth-test key.
const EMPTY: u64 = u64::MAX;

/// Where in its pixel a point lands: the sub-pixel offsets along x and y
/// in sixteenths, `x` in the high four bits. Fresh rays and filled points
/// take the phase of the points around them: a surface's points then keep
/// one spacing as it moves, where points at other offsets would crowd into
/// some pixels and leave others empty at every seam between them.
pub(super) type Phase = u8;

/// The phase of a pixel's centre.
pub(super) const CENTRE: Phase = 0x88;

/// The sub-pixel offsets of `phase`, in `[0, 1)`.
pub(super) fn offsets(phase: Phase) -> (f64, f64) {
    (f64::from(phase >> 4) / 16.0, f64::from(phase & 15) / 16.0)
}

/// The phase of continuous image coordinates `(x, y)` in the pixel they
/// fall in.
#[inline(always)]
fn phase_of(x: f32, y: f32) -> Phase {
    // Both are at least 0 here: truncation is the floor.
    let fx = ((x - x as u32 as f32) * 16.0) as u8 & 15;
    let fy = ((y - y as u32 as f32) * 16.0) as u8 & 15;
    (fx << 4) | fy
}

/// Bits of a depth-test key below its depth: the phase, then the index.
const INDEX_BITS: u32 = 24;

/// A point is taken as hidden when nearer points on both sides of it, along
/// one of the four directions, are nearer by more than this share of its
/// depth: a surface seen at a grazing angle changes depth steadily across
/// a pixel or two, never towards the pixel from both sides.
const HIDDEN_MARGIN: f32 = 0.1;

/// Two nearer points on opposite sides are one surface (whose gap the point
/// is seen through) when they share a material and their depths differ by
/// at most this share.
const SAME_SURFACE: f32 = 0.1;

/// How far along each direction the depth culling looks for nearer points:
/// a gap two pixels wide in a nearer surface (as a surface turning towards
/// the eye opens them) is still found.
const HIDDEN_REACH: usize = 2;

/// Rows a parallel task takes.
const BAND: usize = 8;

/// The depth test's buffers, kept between frames.
#[derive(Default)]
pub(super) struct Scratch {
    /// Each thread's two nearest keys per pixel.
    buffers: Vec<Vec<[u64; 2]>>,
    /// The nearest point per pixel ([`NONE`]: none).
    landed: Vec<u32>,
    /// The second nearest point's key per pixel ([`EMPTY`]: none).
    second: Vec<u64>,
    /// Where in its pixel the nearest point lands.
    phase: Vec<Phase>,
    /// The pixels that show no point.
    gaps: Vec<u32>,
}

/// A reprojected frame.
pub(super) struct Frame<'s> {
    /// Where in each pixel its nearest point landed ([`CENTRE`] where none
    /// did).
    pub phase: &'s [Phase],
    /// The pixels that show no point.
    pub gaps: &'s [u32],
    /// Points dropped as seen through a gap.
    pub occluded: u64,
}

/// A view's projection of directions to pixels, in `f32`: positions are
/// kept relative to an anchor near the eye, so `f32` holds them to far
/// below a pixel.
#[derive(Clone, Copy)]
struct Projection {
    /// The anchor relative to the eye.
    offset: [f32; 3],
    /// `u` and `v` over a pixel's size, and the view direction `-w`.
    across: [f32; 3],
    down: [f32; 3],
    ahead: [f32; 3],
    /// The top-left corner of the image in pixels.
    left: f32,
    top: f32,
    width: u32,
    height: u32,
}

fn f32s(v: DVec3) -> [f32; 3] {
    [v.x as f32, v.y as f32, v.z as f32]
}

fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

impl Projection {
    fn new(camera: &Camera, anchor: DVec3, (width, height): (u32, u32)) -> Self {
        let (left, top, size) = camera.image_plane();
        Self {
            offset: f32s(anchor - camera.eye),
            across: f32s(camera.u / size),
            down: f32s(camera.v / size),
            ahead: f32s(-camera.w),
            left: (left / size) as f32,
            top: (top / size) as f32,
            width,
            height,
        }
    }

    /// The depth-test key of point `index`: its depth (infinite for the
    /// background) and index, in the pixel it lands in; `None` outside the
    /// image or behind the eye.
    #[inline(always)]
    fn key(&self, p: &Point, index: u32) -> Option<(usize, u64)> {
        let background = p.is(Point::BACKGROUND);
        let d = if background {
            p.position
        } else {
            [
                self.offset[0] + p.position[0],
                self.offset[1] + p.position[1],
                self.offset[2] + p.position[2],
            ]
        };
        let z = dot(d, self.ahead);
        if !(z > 0.0) {
            return None;
        }
        let inverse = 1.0 / z;
        let x = dot(d, self.across) * inverse - self.left;
        let y = self.top - dot(d, self.down) * inverse;
        if !(x >= 0.0 && y >= 0.0 && x < self.width as f32 && y < self.height as f32) {
            return None;
        }
        let depth = if background { f32::INFINITY } else { z };
        // Positive floats order as their bits: the key orders by depth,
        // then by phase and index (the same winner however the work is
        // split).
        let key = (u64::from(depth.to_bits()) << 32)
            | (u64::from(phase_of(x, y)) << INDEX_BITS)
            | u64::from(index);
        Some((y as usize * self.width as usize + x as usize, key))
    }
}

/// Moves `points` (one per pixel of the last preview, positions relative
/// to `anchor`) into `camera`'s view: into `out`, the point each pixel
/// shows (one with [`Point::NOTHING`] where none does), its depth along the
/// view (infinite for the background) and the picture.
pub(super) fn reproject<'s>(
    points: &[Point],
    anchor: DVec3,
    camera: &Camera,
    out: &mut Pixels,
    scratch: &'s mut Scratch,
) -> Frame<'s> {
    let (w, h) = (camera.width() as usize, camera.height() as usize);
    let pixels = w * h;
    let projection = Projection::new(camera, anchor, (camera.width(), camera.height()));
    // Each thread's nearest points, over a contiguous share of the points.
    let parts = rayon::current_num_threads().max(1);
    scratch.buffers.resize_with(parts, Vec::new);
    let share = points.len().div_ceil(parts).max(1);
    scratch
        .buffers
        .par_iter_mut()
        .enumerate()
        .for_each(|(part, buffer)| {
            reset(buffer, pixels, [EMPTY; 2]);
            let first = (part * share).min(points.len());
            let last = (first + share).min(points.len());
            for (k, p) in points[first..last].iter().enumerate() {
                if let Some((pixel, key)) = projection.key(p, (first + k) as u32) {
                    let slot = &mut buffer[pixel];
                    if key < slot[0] {
                        slot[1] = slot[0];
                        slot[0] = key;
                    } else if key < slot[1] {
                        slot[1] = key;
                    }
                }
            }
        });
    // The nearest of the threads' per pixel: its point, depth and phase.
    let Scratch {
        buffers,
        landed,
        second,
        phase,
        gaps,
    } = scratch;
    reset(landed, pixels, NONE);
    reset(second, pixels, EMPTY);
    reset(phase, pixels, CENTRE);
    reset(&mut out.depth, pixels, f32::INFINITY);
    landed
        .par_chunks_mut(w * BAND)
        .zip(second.par_chunks_mut(w * BAND))
        .zip(out.depth.par_chunks_mut(w * BAND))
        .zip(phase.par_chunks_mut(w * BAND))
        .enumerate()
        .for_each(|(band, (((landed, seconds), depths), phases))| {
            let first = band * w * BAND;
            for k in 0..landed.len() {
                // The two nearest of the threads' two nearest.
                let (mut best, mut next) = (EMPTY, EMPTY);
                for b in buffers.iter() {
                    for key in b[first + k] {
                        if key < best {
                            next = best;
                            best = key;
                        } else if key < next {
                            next = key;
                        }
                    }
                }
                if best != EMPTY {
                    landed[k] = (best & ((1 << INDEX_BITS) - 1)) as u32;
                    phases[k] = (best >> INDEX_BITS) as u8;
                    depths[k] = f32::from_bits((best >> 32) as u32);
                    seconds[k] = next;
                }
            }
        });
    // Per pixel: culled or shown, its point and picture.
    let (landed, depth) = (&*landed, &out.depth);
    let same_surface = |a: usize, b: usize| {
        let (da, db) = (depth[a], depth[b]);
        points[landed[a] as usize].material == points[landed[b] as usize].material
            && (da - db).abs() <= SAME_SURFACE * da.max(db)
    };
    let hidden = |p: usize| {
        let limit = depth[p] * (1.0 - HIDDEN_MARGIN);
        let (x, y) = (p % w, p / w);
        if x >= HIDDEN_REACH && y >= HIDDEN_REACH && x + HIDDEN_REACH < w && y + HIDDEN_REACH < h {
            // Away from the edges: the neighbours one and two steps away
            // along each direction, on both sides.
            for step in [1, w, w + 1, w - 1] {
                let ahead = if depth[p + step] < limit {
                    p + step
                } else if depth[p + 2 * step] < limit {
                    p + 2 * step
                } else {
                    continue;
                };
                let behind = if depth[p - step] < limit {
                    p - step
                } else if depth[p - 2 * step] < limit {
                    p - 2 * step
                } else {
                    continue;
                };
                if same_surface(ahead, behind) {
                    return true;
                }
            }
            return false;
        }
        // At the edges: the neighbours that exist.
        let (x, y) = (x as isize, y as isize);
        let nearer = |dx: isize, dy: isize| {
            (1..=HIDDEN_REACH as isize).find_map(|r| {
                let (i, j) = (x + r * dx, y + r * dy);
                if i < 0 || j < 0 || i >= w as isize || j >= h as isize {
                    return None;
                }
                let q = j as usize * w + i as usize;
                (depth[q] < limit).then_some(q)
            })
        };
        [(1, 0), (0, 1), (1, 1), (-1, 1)].iter().any(|&(dx, dy)| {
            match (nearer(dx, dy), nearer(-dx, -dy)) {
                (Some(a), Some(b)) => same_surface(a, b),
                _ => false,
            }
        })
    };
    // A pixel two points landed in passes the second to the neighbour
    // nearest to where it landed, if that neighbour has none: a surface
    // whose points crowd into one pixel leaves a gap beside it, which its
    // own point fills (exact, where filling would blend).
    let second = &*second;
    let toward = |key: u64| -> (isize, isize) {
        let phase = (key >> INDEX_BITS) as u8;
        let (fx, fy) = (
            f32::from(phase >> 4) / 16.0 + 1.0 / 32.0,
            f32::from(phase & 15) / 16.0 + 1.0 / 32.0,
        );
        let (dx, dy) = (fx.min(1.0 - fx), fy.min(1.0 - fy));
        if dx < dy {
            (if fx < 0.5 { -1 } else { 1 }, 0)
        } else {
            (0, if fy < 0.5 { -1 } else { 1 })
        }
    };
    let heal = |p: usize| -> Option<u64> {
        let (x, y) = ((p % w) as isize, (p / w) as isize);
        [(-1, 0), (1, 0), (0, -1), (0, 1)]
            .iter()
            .find_map(|&(dx, dy)| {
                let (i, j) = (x + dx, y + dy);
                if i < 0 || j < 0 || i >= w as isize || j >= h as isize {
                    return None;
                }
                let q = j as usize * w + i as usize;
                let key = second[q];
                (key != EMPTY && toward(key) == (-dx, -dy)).then_some(key)
            })
    };
    reset(&mut out.points, pixels, Point::NONE);
    reset(&mut out.rgba, 4 * pixels, 255);
    // Per band: its open pixels, its occluded count and the depths healed.
    type Band = (Vec<u32>, u64, Vec<(u32, f32)>);
    let bands: Vec<Band> = out
        .points
        .par_chunks_mut(w * BAND)
        .zip(out.rgba.par_chunks_mut(4 * w * BAND))
        .enumerate()
        .map(|(band, (shown, rgba))| {
            let first = band * w * BAND;
            let (mut open, mut occluded, mut depths_healed) = (Vec::new(), 0, Vec::new());
            for k in 0..shown.len() {
                let p = first + k;
                let index = landed[p];
                if index != NONE && !hidden(p) {
                    let point = &points[index as usize];
                    shown[k] = *point;
                    rgba[4 * k..4 * k + 3].copy_from_slice(&point.rgb);
                } else if let Some(key) = (index == NONE).then(|| heal(p)).flatten() {
                    let point = &points[(key & ((1 << INDEX_BITS) - 1)) as usize];
                    shown[k] = *point;
                    rgba[4 * k..4 * k + 3].copy_from_slice(&point.rgb);
                    depths_healed.push((p as u32, f32::from_bits((key >> 32) as u32)));
                } else {
                    occluded += u64::from(index != NONE);
                    open.push(p as u32);
                }
            }
            (open, occluded, depths_healed)
        })
        .collect();
    gaps.clear();
    let mut occluded = 0;
    for (open, n, healed) in bands {
        gaps.extend_from_slice(&open);
        occluded += n;
        for (p, d) in healed {
            out.depth[p as usize] = d;
        }
    }
    Frame {
        phase,
        gaps,
        occluded,
    }
}
