//! Pixels no point shows: a blend of the neighbours of one surface. A
//! pixel with no point lies where a surface stretched between its points,
//! or in a gap a nearer surface opened as it moved; so where its
//! neighbours show two surfaces, it shows the one most of them show, the
//! farther one where they are as many (the surface behind the edge, not
//! the edge): edge-aware filling with depth as the guide, after Kopf et
//! al. 2007's joint bilateral upsampling. A filled pixel becomes a point at the depth it was
//! filled from, with the material and weights of a neighbour it was filled
//! from. Gaps wider than the few pixels that reaches (fresh rays go there
//! first, so only when rays are scarce) take a colour by push-pull (Gortler
//! et al. 1996: each coarser level averages the known pixels under it, and
//! an unknown pixel takes its nearest known ancestor) and no point.

use rayon::prelude::*;

use super::point::{Pixels, Point, reset};
use super::reproject::{CENTRE, Phase, offsets};
use crate::camera::Camera;
use crate::math::DVec3;

/// Neighbours of a gap within this share of the farthest one's depth show
/// one surface.
const FAR_SHARE: f32 = 0.9;

/// Passes of edge-aware filling: each reaches one pixel further into a gap.
const EDGE_PASSES: usize = 3;

/// The buffers of filling, kept between frames.
#[derive(Default)]
pub(super) struct Scratch {
    gaps: Vec<u32>,
    left: Vec<u32>,
    results: Vec<Option<(Point, f32)>>,
    /// Push-pull's levels, from half the image's size down.
    levels: Vec<Vec<[u32; 4]>>,
}

/// Fills the `gaps` of `out` (a frame of `camera`'s view; pixels that
/// showed no point after reprojection) that still show none: as points
/// (positions relative to `anchor`, made at frame `now`) where neighbours
/// reach, by colour alone elsewhere. `phase` says where in its pixel each
/// pixel's point landed. Returns how many gaps it filled.
pub(super) fn fill(
    out: &mut Pixels,
    gaps: &[u32],
    phase: &[Phase],
    camera: &Camera,
    anchor: DVec3,
    now: u16,
    scratch: &mut Scratch,
) -> u64 {
    let (w, h) = (camera.width() as usize, camera.height() as usize);
    let Scratch {
        gaps: open,
        left,
        results,
        levels,
    } = scratch;
    open.clear();
    open.extend(
        gaps.iter()
            .copied()
            .filter(|&p| out.points[p as usize].is(Point::NOTHING)),
    );
    let eye = camera.eye - anchor;
    let filled = open.len() as u64;
    for _ in 0..EDGE_PASSES {
        if open.is_empty() {
            break;
        }
        let (points, depths) = (&out.points, &out.depth);
        open.par_iter()
            .map(|&p| {
                let (x, y) = (p as usize % w, p as usize / w);
                // The neighbours that show a point (at most eight), and
                // the farthest of them.
                let mut around = [0usize; 8];
                let mut count = 0;
                let (mut near, mut far) = (f32::INFINITY, f32::NEG_INFINITY);
                for j in y.saturating_sub(1)..(y + 2).min(h) {
                    for i in x.saturating_sub(1)..(x + 2).min(w) {
                        let q = j * w + i;
                        if !points[q].is(Point::NOTHING) {
                            around[count] = q;
                            count += 1;
                            near = near.min(depths[q]);
                            far = far.max(depths[q]);
                        }
                    }
                }
                if count == 0 {
                    return None;
                }
                // Neighbours at two depths are two surfaces: the gap shows
                // the one most of them show (a surface stretched between
                // its points), the farther one where they are as many (a
                // gap opened at an edge shows what lies behind it).
                let split = if near >= far * FAR_SHARE {
                    f32::NEG_INFINITY
                } else if far.is_infinite() {
                    f32::MAX
                } else {
                    (near * far).sqrt()
                };
                let behind = around[..count]
                    .iter()
                    .filter(|&&q| depths[q] >= split)
                    .count();
                let far_side = 2 * behind >= count;
                let kept = |q: usize| (depths[q] >= split) == far_side;
                let far = around[..count]
                    .iter()
                    .filter(|&&q| kept(q))
                    .map(|&q| depths[q])
                    .fold(f32::NEG_INFINITY, f32::max);
                // The far neighbours' colours and depths, averaged: the
                // point lies on the surface they show, where in its pixel
                // the first of them lies in its own (so they keep one
                // spacing as they move on).
                let (mut sum, mut n, mut donor, mut at) = ([0u32; 3], 0u32, None, 0.0);
                let mut in_pixel = CENTRE;
                for &q in &around[..count] {
                    if kept(q) {
                        let point = &points[q];
                        for (s, c) in sum.iter_mut().zip(point.rgb) {
                            *s += u32::from(c);
                        }
                        n += 1;
                        at += depths[q];
                        if donor.is_none() {
                            donor = Some(*point);
                            in_pixel = phase[q];
                        }
                    }
                }
                let donor = donor?;
                // The depth at the gap: between two far neighbours on
                // opposite sides where there are such (the reciprocal of
                // depth is linear across a plane's image, so their mean
                // reciprocal is the plane's depth here), else the far
                // neighbours' mean reciprocal.
                let kept = |q: usize| !points[q].is(Point::NOTHING) && kept(q);
                let p = p as usize;
                let pair = [(1, 0), (0, 1), (1, 1), (1, -1)].iter().find_map(
                    |&(dx, dy): &(isize, isize)| {
                        let (a, b) = (
                            (x as isize + dx, y as isize + dy),
                            (x as isize - dx, y as isize - dy),
                        );
                        let inside = |(i, j): (isize, isize)| {
                            i >= 0 && j >= 0 && (i as usize) < w && (j as usize) < h
                        };
                        if !inside(a) || !inside(b) {
                            return None;
                        }
                        let (qa, qb) = (
                            a.1 as usize * w + a.0 as usize,
                            b.1 as usize * w + b.0 as usize,
                        );
                        (kept(qa) && kept(qb)).then_some((qa, qb))
                    },
                );
                let far = if far.is_infinite() {
                    far
                } else if let Some((qa, qb)) = pair {
                    2.0 / (1.0 / depths[qa] + 1.0 / depths[qb])
                } else {
                    n as f32
                        / around[..count]
                            .iter()
                            .filter(|&&q| kept(q))
                            .map(|&q| 1.0 / depths[q])
                            .sum::<f32>()
                };
                let _ = (at, p);
                let (dx, dy) = offsets(in_pixel);
                let dir = camera.ray(x as u32, y as u32, dx, dy).dir;
                let background = far.is_infinite();
                let position = if background {
                    dir
                } else {
                    // The depth is along the view; the ray's length to it:
                    eye + (f64::from(far) / dir.dot(-camera.w)) * dir
                };
                let point = Point {
                    position: [position.x as f32, position.y as f32, position.z as f32],
                    rgb: sum.map(|s| ((s + n / 2) / n) as u8),
                    flags: Point::FILLED
                        | (donor.flags & Point::STALE)
                        | if background { Point::BACKGROUND } else { 0 },
                    born: now,
                    ..donor
                };
                Some((point, far))
            })
            .collect_into_vec(results);
        left.clear();
        for (&p, result) in open.iter().zip(results.iter()) {
            match *result {
                Some((point, far)) => {
                    let p = p as usize;
                    out.points[p] = point;
                    out.depth[p] = far;
                    out.rgba[4 * p..4 * p + 3].copy_from_slice(&point.rgb);
                }
                None => left.push(p),
            }
        }
        std::mem::swap(open, left);
    }
    // Still open: coloured by push-pull.
    if !open.is_empty() {
        push_pull(out, open, (w, h), levels);
    }
    filled
}

/// Colours the `gaps` of `out` (pixels showing no point) with the average
/// of the pixels that show one in the smallest enclosing block that has
/// any (the block of 2 x 2 pixels, 4 x 4, and so on). `levels` is scratch
/// space kept between frames.
fn push_pull(
    out: &mut Pixels,
    gaps: &[u32],
    (w, h): (usize, usize),
    levels: &mut Vec<Vec<[u32; 4]>>,
) {
    // A cell of a level: the sum of its known pixels' channels and their
    // number. The first level, of 2 x 2 blocks, from the pixels.
    let size = |k: u32| (w.div_ceil(1 << k), h.div_ceil(1 << k));
    let mut count = 1;
    while size(count) != (1, 1) && size(count - 1) != (1, 1) {
        count += 1;
    }
    levels.resize_with(count as usize, Vec::new);
    let (lw, lh) = size(1);
    reset(&mut levels[0], lw * lh, [0; 4]);
    let (points, rgba) = (&out.points, &out.rgba);
    levels[0]
        .par_chunks_mut(lw)
        .enumerate()
        .for_each(|(by, row)| {
            for y in 2 * by..(2 * by + 2).min(h) {
                for x in 0..w {
                    let p = y * w + x;
                    if !points[p].is(Point::NOTHING) {
                        let cell = &mut row[x / 2];
                        for c in 0..3 {
                            cell[c] += u32::from(rgba[4 * p + c]);
                        }
                        cell[3] += 1;
                    }
                }
            }
        });
    for k in 1..count as usize {
        let (finer, coarser) = levels.split_at_mut(k);
        let (fw, fh) = size(k as u32);
        let (cw, ch) = size(k as u32 + 1);
        let (finer, coarser) = (&finer[k - 1], &mut coarser[0]);
        reset(coarser, cw * ch, [0; 4]);
        for y in 0..fh {
            for x in 0..fw {
                let f = finer[y * fw + x];
                let c = &mut coarser[(y / 2) * cw + x / 2];
                for j in 0..4 {
                    c[j] += f[j];
                }
            }
        }
    }
    for &p in gaps {
        let (x, y) = (p as usize % w, p as usize / w);
        for (k, cells) in levels.iter().enumerate() {
            let (cw, _) = size(k as u32 + 1);
            let c = cells[(y >> (k + 1)) * cw + (x >> (k + 1))];
            if let Some(n) = std::num::NonZeroU32::new(c[3]) {
                let p = p as usize;
                for (channel, sum) in out.rgba[4 * p..4 * p + 3].iter_mut().zip(c) {
                    *channel = ((sum + n.get() / 2) / n) as u8;
                }
                break;
            }
        }
    }
}
