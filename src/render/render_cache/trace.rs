//! The render cache's rays: the eye rays that seed it from a finished
//! image, and each preview's fresh rays, spent in priority order (Walter,
//! Drettakis and Parker 1999: rays go where the picture needs them most)
//! until the frame's time is up. Fresh pixels are traced as the passes
//! trace them (`sample_lanes`: packets of neighbouring pixels, the same
//! integrator), with a recorder that keeps where each eye ray hit and which
//! materials its ray tree met.

use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

use rayon::prelude::*;

use super::point::{NO_MATERIAL, Point, display_rgb, material_of, reset, view_weight};
use super::reproject::{CENTRE, Phase, offsets};
use crate::math::{DVec3, Ray};
use crate::render::packets::PacketScratch;
use crate::render::ray_tree::{RayKind, RayRecorder};
use crate::render::renderer::{Query, Renderer, Scratch as QueryScratch};
use crate::render::tile_job::{keep_scratch, spare_scratch};
use crate::simd::LaneWork;
use crate::stats::{NoCounts, RayCounts, RenderCounts};

/// Where an eye ray hit and what its ray tree met.
#[derive(Clone, Copy, Debug)]
pub(in crate::render) struct SampleRecord {
    point: DVec3,
    /// The eye ray's material (`u32::MAX`: it left the scene).
    material: u32,
    /// Every material the tree met, bit `m % 32`.
    touched: u32,
    /// A secondary ray's record: only its materials count.
    nested: bool,
}

impl Default for SampleRecord {
    fn default() -> Self {
        Self {
            point: DVec3::ZERO,
            material: u32::MAX,
            touched: 0,
            nested: false,
        }
    }
}

impl RayRecorder for SampleRecord {
    #[inline(always)]
    fn child(&self, _: RayKind, _: &Ray, _: u32, _: f64) -> Self {
        Self {
            nested: true,
            ..Self::default()
        }
    }

    #[inline(always)]
    fn material(&mut self, index: u32) {
        self.touched |= 1 << (index % 32);
        if !self.nested {
            self.material = index;
        }
    }

    #[inline(always)]
    fn surface(&mut self, point: DVec3) {
        if !self.nested {
            self.point = point;
        }
    }

    #[inline(always)]
    fn attach(&mut self, child: Self, _color: crate::math::Color) {
        self.touched |= child.touched;
    }
}

/// The kept point of an eye ray `ray` traced to `value` with `rec`, and
/// its depth along `renderer`'s view.
fn point_of(
    renderer: &Renderer,
    anchor: DVec3,
    ray: &Ray,
    value: DVec3,
    rec: &SampleRecord,
    now: u16,
) -> (Point, f32) {
    let rgb = display_rgb(renderer, value);
    if rec.material == u32::MAX {
        let d = ray.dir;
        let point = Point {
            position: [d.x as f32, d.y as f32, d.z as f32],
            rgb,
            flags: Point::BACKGROUND,
            born: now,
            view_weight: 0,
            material: NO_MATERIAL,
            touched: 0,
        };
        return (point, f32::INFINITY);
    }
    let p = rec.point - anchor;
    let point = Point {
        position: [p.x as f32, p.y as f32, p.z as f32],
        rgb,
        flags: 0,
        born: now,
        view_weight: view_weight(&renderer.materials[rec.material as usize]),
        material: material_of(rec.material),
        touched: rec.touched,
    };
    (point, renderer.camera().view_depth(rec.point) as f32)
}

/// The buffers of a preview's order of rays, kept between frames.
#[derive(Default)]
pub(super) struct Scratch {
    order: Vec<u32>,
    /// The pixels of one turn's lattice, by class.
    classes: [Vec<u32>; 4],
    /// How many rays the last preview traced: the order is made for a few
    /// times as many.
    last_traced: usize,
    /// The turn the next preview starts with.
    turn: usize,
}

/// The sixteen places of a pixel in its 4 x 4 block, in the order the
/// turns take them: each turn's lattice as far from the last few as the
/// block allows (a 4 x 4 Bayer matrix's order).
const LATTICE: [(usize, usize); 16] = [
    (0, 0),
    (2, 2),
    (2, 0),
    (0, 2),
    (1, 1),
    (3, 3),
    (3, 1),
    (1, 3),
    (1, 0),
    (3, 2),
    (3, 0),
    (1, 2),
    (0, 1),
    (2, 3),
    (2, 1),
    (0, 3),
];

/// The rows of an image `height` high in a golden-ratio order (each far
/// from the last few), as a stride coprime with the height.
fn row_stride(height: usize) -> usize {
    let mut step = ((height as f64 * 0.618_034) as usize).max(1);
    while gcd(step, height.max(1)) != 1 {
        step += 1;
    }
    step
}

/// Which pixels a preview traces, in order (Bishop et al. 1994's frameless
/// rendering updates pixels in a spread order rather than whole frames):
/// the `gaps` (pixels no point reached, rows in a spread order), then turn
/// by turn an interleaved sixteenth of the image (one place in every 4 x 4
/// block, the next place the next turn), within a turn the points an edit
/// made stale, then those whose colour depends on the eye, then filled
/// ones, then the rest. About `wanted` of them.
pub(super) fn turn_order<'s>(
    points: &[Point],
    gaps: &[u32],
    (width, height): (usize, usize),
    wanted: usize,
    scratch: &'s mut Scratch,
) -> &'s [u32] {
    let Scratch {
        order,
        classes,
        turn,
        ..
    } = scratch;
    order.clear();
    // The gaps, a row at a time in the spread order.
    let step = row_stride(height);
    let mut row_start = vec![0usize; height + 1];
    for &g in gaps {
        row_start[g as usize / width + 1] += 1;
    }
    for y in 0..height {
        row_start[y + 1] += row_start[y];
    }
    for k in 0..height {
        let y = k * step % height;
        order.extend_from_slice(&gaps[row_start[y]..row_start[y + 1]]);
    }
    let mut turns = 0;
    while order.len() < wanted && turns < LATTICE.len() {
        let (ox, oy) = LATTICE[(*turn + turns) % LATTICE.len()];
        for class in classes.iter_mut() {
            class.clear();
        }
        for y in (oy..height).step_by(4) {
            for x in (ox..width).step_by(4) {
                let p = y * width + x;
                let point = &points[p];
                let class = if point.is(Point::NOTHING) {
                    // A gap: already in the order.
                    continue;
                } else if point.is(Point::STALE) {
                    0
                } else if point.is(Point::BACKGROUND) && !point.is(Point::FILLED) {
                    // The background's colour is the same from every eye.
                    continue;
                } else if point.view_weight > 0 {
                    1
                } else if point.is(Point::FILLED) {
                    2
                } else {
                    3
                };
                classes[class].push(p as u32);
            }
        }
        for class in classes.iter() {
            order.extend_from_slice(class);
        }
        turns += 1;
    }
    *turn = (*turn + 1) % LATTICE.len();
    order
}

fn gcd(a: usize, b: usize) -> usize {
    if b == 0 { a } else { gcd(b, a % b) }
}

/// The fresh pixels of a preview: each with its point and depth.
pub(super) struct Traced {
    pub points: Vec<(u32, Point, f32)>,
    pub rays: RayCounts,
}

/// Pixels traced between two looks at the clock: tens of microseconds of
/// work for diffuse pixels, a few hundred for glass, so a frame overruns
/// its time by at most that much per thread.
const CHUNK: usize = 64;

/// Traces the pixels of `order`, from its start, until `until`: each
/// thread takes the next chunk while there is time.
/// The fresh rays of a preview at frame `now` of `renderer`'s view, whose
/// reprojected `points` (positions relative to `anchor`) leave `gaps`:
/// traced in [`turn_order`] until `until`, each where in its pixel
/// `phase` says.
#[allow(clippy::too_many_arguments)]
pub(super) fn trace_in_turn(
    renderer: &Renderer,
    anchor: DVec3,
    points: &[Point],
    gaps: &[u32],
    phase: &[Phase],
    now: u16,
    until: Instant,
    scratch: &mut Scratch,
) -> Traced {
    let s = renderer.settings();
    let wanted = (4 * scratch.last_traced).max(8192);
    let order = turn_order(
        points,
        gaps,
        (s.width as usize, s.height as usize),
        wanted,
        scratch,
    );
    let traced = trace_in_order(renderer, anchor, order, phase, now, until);
    scratch.last_traced = traced.points.len();
    traced
}

/// Traces the pixels of `order`, from its start, until `until`: each
/// thread takes the next chunk while there is time.
fn trace_in_order(
    renderer: &Renderer,
    anchor: DVec3,
    order: &[u32],
    phase: &[Phase],
    now: u16,
    until: Instant,
) -> Traced {
    let width = renderer.settings().width;
    let height = renderer.settings().height;
    let chunks: Vec<&[u32]> = order.chunks(CHUNK).collect();
    let next = AtomicUsize::new(0);
    let threads = rayon::current_num_threads().max(1);
    type Part = (Vec<(u32, Point, f32)>, RenderCounts);
    let parts: Vec<Part> = (0..threads)
        .into_par_iter()
        .map(|_| {
            let mut slots = Vec::new();
            let mut counts = RenderCounts::default();
            while Instant::now() < until {
                let k = next.fetch_add(1, Ordering::Relaxed);
                let Some(chunk) = chunks.get(k) else {
                    break;
                };
                let runs = runs_of(chunk, width);
                let phases: Vec<Phase> = chunk
                    .iter()
                    .map(|&p| ray_phase(phase, p as usize, (width, height)))
                    .collect();
                let work = TraceRuns {
                    renderer,
                    anchor,
                    runs: &runs,
                    phases: &phases,
                    now,
                };
                let (mut traced, c) = if renderer.uses_packets() {
                    crate::simd::dispatch(renderer.simd, work)
                        .unwrap_or_else(|| trace_single(renderer, anchor, &runs, &phases, now))
                } else {
                    trace_single(renderer, anchor, &runs, &phases, now)
                };
                slots.append(&mut traced);
                counts += c;
            }
            (slots, counts)
        })
        .collect();
    let mut out = Traced {
        points: Vec::new(),
        rays: RayCounts::default(),
    };
    for (mut points, counts) in parts {
        out.points.append(&mut points);
        out.rays += counts.rays;
    }
    out
}

/// Where in pixel `p` its fresh ray passes: where the point it had landed
/// (a point re-traced stays where it was), else where a neighbour's did
/// (the first of the eight that has one), else its centre.
fn ray_phase(phase: &[Phase], p: usize, (width, height): (u32, u32)) -> Phase {
    if phase[p] != CENTRE {
        return phase[p];
    }
    let (w, h) = (width as usize, height as usize);
    let (x, y) = (p % w, p / w);
    for j in y.saturating_sub(1)..(y + 2).min(h) {
        for i in x.saturating_sub(1)..(x + 2).min(w) {
            if phase[j * w + i] != CENTRE {
                return phase[j * w + i];
            }
        }
    }
    CENTRE
}

/// A chunk's pixels as runs of neighbours in one row: (row, first column,
/// length).
fn runs_of(chunk: &[u32], width: u32) -> Vec<(u32, u32, u32)> {
    let mut runs: Vec<(u32, u32, u32)> = Vec::new();
    for &p in chunk {
        let (x, y) = (p % width, p / width);
        match runs.last_mut() {
            Some((ry, rx, len)) if *ry == y && *rx + *len == x => *len += 1,
            _ => runs.push((y, x, 1)),
        }
    }
    runs
}

/// Runs of pixels traced in packets of `N` neighbours.
struct TraceRuns<'r, 'a> {
    renderer: &'r Renderer<'a>,
    anchor: DVec3,
    runs: &'r [(u32, u32, u32)],
    /// Where in its pixel each ray passes, in the runs' order.
    phases: &'r [Phase],
    /// The frame the points are made in.
    now: u16,
}

impl LaneWork for TraceRuns<'_, '_> {
    type Output = (Vec<(u32, Point, f32)>, RenderCounts);

    #[inline(always)]
    fn run<S: pulp::Simd, const N: usize>(self, simd: S) -> Self::Output {
        let r = self.renderer;
        let width = r.settings().width;
        let mut out = Vec::new();
        let mut counts = RenderCounts::default();
        let mut scratch = spare_scratch::<QueryScratch>();
        let mut stack = spare_scratch::<PacketScratch<N>>();
        let mut query = Query {
            counter: &mut NoCounts,
            scratch: &mut scratch,
        };
        let mut at = 0;
        for &(y, x0, len) in self.runs {
            let mut x = x0;
            while x < x0 + len {
                let n = N.min((x0 + len - x) as usize);
                let mut rays = [Ray::new(DVec3::ZERO, DVec3::X); N];
                for (k, ray) in rays.iter_mut().enumerate().take(n) {
                    let (dx, dy) = offsets(self.phases[at + k]);
                    *ray = r.camera.ray(x + k as u32, y, dx, dy);
                }
                at += n;
                let mut recs = [SampleRecord::default(); N];
                let values = r.sample_lanes(
                    simd,
                    &rays[..n],
                    &mut query,
                    &mut stack,
                    &mut counts,
                    &mut recs,
                );
                for k in 0..n {
                    let (point, depth) =
                        point_of(r, self.anchor, &rays[k], values[k], &recs[k], self.now);
                    out.push((y * width + x + k as u32, point, depth));
                }
                x += n as u32;
            }
        }
        keep_scratch(stack);
        keep_scratch(scratch);
        (out, counts)
    }
}

/// [`TraceRuns`] one ray at a time (no SIMD level with lanes).
fn trace_single(
    r: &Renderer,
    anchor: DVec3,
    runs: &[(u32, u32, u32)],
    phases: &[Phase],
    now: u16,
) -> (Vec<(u32, Point, f32)>, RenderCounts) {
    let width = r.settings().width;
    let mut out = Vec::new();
    let mut counts = RenderCounts::default();
    let mut scratch = spare_scratch::<QueryScratch>();
    let mut query = Query {
        counter: &mut NoCounts,
        scratch: &mut scratch,
    };
    let mut phases = phases.iter();
    for &(y, x0, len) in runs {
        for x in x0..x0 + len {
            let (dx, dy) = offsets(phases.next().copied().unwrap_or(CENTRE));
            let ray = r.camera.ray(x, y, dx, dy);
            let mut rec = SampleRecord::default();
            let value = r.sample_recorded(&ray, &mut query, &mut counts, &mut rec);
            let (point, depth) = point_of(r, anchor, &ray, value, &rec, now);
            out.push((y * width + x, point, depth));
        }
    }
    keep_scratch(scratch);
    (out, counts)
}

/// The points of a finished image of `renderer`'s view, into `points`: an
/// eye ray through each pixel's centre finds the point, `rgba` (the image
/// as shown) gives its colour. Which materials a point's ray tree met is
/// known only where its material spawns no secondary rays (its own,
/// then); elsewhere every material is assumed.
pub(super) fn seed_points(
    renderer: &Renderer,
    anchor: DVec3,
    rgba: &[u8],
    now: u16,
    points: &mut Vec<Point>,
) {
    let s = renderer.settings();
    let (width, height) = (s.width, s.height);
    let scene = renderer.scene;
    let blank = Point {
        position: [0.0; 3],
        rgb: [0; 3],
        flags: Point::BACKGROUND,
        born: now,
        view_weight: 0,
        material: NO_MATERIAL,
        touched: 0,
    };
    reset(points, (width * height) as usize, blank);
    points
        .par_chunks_mut(width as usize)
        .enumerate()
        .for_each(|(y, row)| {
            let y = y as u32;
            let hits = row_hits(renderer, y);
            for (x, point) in row.iter_mut().enumerate() {
                let pixel = y as usize * width as usize + x;
                let rgb = [rgba[4 * pixel], rgba[4 * pixel + 1], rgba[4 * pixel + 2]];
                let ray = renderer.camera.ray(x as u32, y, 0.5, 0.5);
                *point = match hits[x] {
                    None => Point {
                        position: [ray.dir.x as f32, ray.dir.y as f32, ray.dir.z as f32],
                        rgb,
                        ..blank
                    },
                    Some((t, shape)) => {
                        let m = scene.shape_materials[shape as usize];
                        let material = &renderer.materials[m as usize];
                        let spawns = material.reflectivity > 0.0 || material.transparency > 0.0;
                        let p = ray.origin + t * ray.dir - anchor;
                        Point {
                            position: [p.x as f32, p.y as f32, p.z as f32],
                            rgb,
                            flags: 0,
                            born: now,
                            view_weight: view_weight(material),
                            material: material_of(m),
                            touched: if spawns { u32::MAX } else { 1 << (m % 32) },
                        }
                    }
                };
            }
        });
}

/// The closest hit (distance, shape) of each pixel centre's eye ray in
/// row `y`.
fn row_hits(renderer: &Renderer, y: u32) -> Vec<Option<(f64, u32)>> {
    struct RowHits<'r, 'a> {
        renderer: &'r Renderer<'a>,
        y: u32,
    }
    impl LaneWork for RowHits<'_, '_> {
        type Output = Vec<Option<(f64, u32)>>;
        #[inline(always)]
        fn run<S: pulp::Simd, const N: usize>(self, simd: S) -> Self::Output {
            let r = self.renderer;
            let width = r.settings().width;
            let mut out = Vec::with_capacity(width as usize);
            let mut scratch = spare_scratch::<QueryScratch>();
            let mut stack = spare_scratch::<PacketScratch<N>>();
            let mut query = Query {
                counter: &mut NoCounts,
                scratch: &mut scratch,
            };
            let mut x = 0;
            while x < width {
                let n = N.min((width - x) as usize);
                let mut rays = [Ray::new(DVec3::ZERO, DVec3::X); N];
                for (k, ray) in rays.iter_mut().enumerate() {
                    *ray = r.camera.ray(x + k as u32, self.y, 0.5, 0.5);
                }
                let hits =
                    r.closest_lanes::<S, NoCounts, N>(simd, &rays[..n], &mut query, &mut stack);
                out.extend(hits[..n].iter().map(|h| h.map(|h| (h.hit.t, h.shape))));
                x += n as u32;
            }
            keep_scratch(stack);
            keep_scratch(scratch);
            out
        }
    }
    let work = RowHits { renderer, y };
    let packets = renderer
        .uses_packets()
        .then(|| crate::simd::dispatch(renderer.simd, work));
    if let Some(Some(hits)) = packets {
        return hits;
    }
    let width = renderer.settings().width;
    let mut scratch = spare_scratch::<QueryScratch>();
    let mut query = Query {
        counter: &mut NoCounts,
        scratch: &mut scratch,
    };
    let hits = (0..width)
        .map(|x| {
            let ray = renderer.camera.ray(x, y, 0.5, 0.5);
            renderer
                .closest(&crate::shapes::PreparedRay::new(ray), &mut query)
                .map(|h| (h.hit.t, h.shape))
        })
        .collect();
    keep_scratch(scratch);
    hits
}
