//! The light buffer (Haines and Greenberg 1986): for each point light, a
//! cube of directions around it whose cells list the bounded shapes that
//! a ray leaving the light in that direction can meet. A shadow ray whose
//! cell lists a few shapes is answered by testing those and the unbounded
//! ones: brute force over every shape that can meet it, so the answer is
//! brute force's, which every accelerator's is. Most shadow rays reach
//! their light through a cell that lists nothing. A cell that would list
//! more than [`MAX_LIST`] shapes (over a mesh, say) is left to the
//! accelerator.

use rayon::prelude::*;
use serde::Serialize;

use crate::math::{Aabb, DVec3};
use crate::shapes::{PreparedRay, Shape};

/// Cells along a side of each of the cube's six faces: 128 took tree 7 %
/// fewer instructions a ray than 64, mount 4 %, balls 3 %, teapot 2 %, and
/// no scene more; 192 gained tree and balls another 2 % for 2.25 times the
/// memory and cost mount its cube (docs/notes/experiments.md).
const SIDE: usize = 128;
const FACE_CELLS: usize = SIDE * SIDE;
const CUBE_CELLS: usize = 6 * FACE_CELLS;
/// Longest list a cell keeps; a longer one goes to the accelerator (a
/// shape test costs about a twentieth of a shadow ray's walk).
const MAX_LIST: usize = 12;
/// Padding of a box's projection, in face coordinates (`[-1, 1]`): far
/// more than the rounding of a ray's direction or of the projection.
const FACE_PAD: f64 = 1e-6;
/// Padding of a shape's box, relative to the magnitude of the scene's
/// coordinates: the rounding of a primitive test's hit points, as the
/// octree pads its cells.
const BOX_PAD: f64 = 1e-9;
/// A box this close to the light (relative to the scene's magnitude) is
/// listed in every cell: near the light a ray's rounding turns its
/// direction.
const NEAR_LIGHT: f64 = 1e-8;
/// At most this many shape-light pairs are projected (tens of
/// milliseconds); a larger scene keeps no light buffer.
const MAX_PAIRS: usize = 2_000_000;
/// Fewer shape-light pairs than this are projected on the calling thread:
/// waking a pool thread takes longer (100-200 µs) than projecting them.
const PARALLEL_PAIRS: usize = 20_000;
/// Lights after this many keep no cube. A cube takes 384 KiB of starts
/// and at most `MAX_LIST` shapes a cell, 4.7 MiB: sixteen keep the bound
/// sixty-four cubes of 64x64 cells had (an 80-light scene of 6,500 shapes
/// took 75 MB at its peak with 64 cubes of 128x128, 29 MB before).
const MAX_CUBES: usize = 16;
/// In a cube's `starts`: the cell's list was too long to keep.
const LONG: u32 = 1 << 31;

/// One light's cube of directions.
struct DirectionCube {
    /// Per cell, where its list starts in `shapes`, or [`LONG`] added for a
    /// cell whose list was too long (it is empty); one more entry ends the
    /// last list.
    starts: Vec<u32>,
    shapes: Vec<u32>,
}

/// What a light buffer holds, for `--stats` and the viewer.
#[derive(Clone, Copy, Debug, Default, PartialEq, Serialize)]
pub struct LightBufferStats {
    /// Lights with a cube (others' shadow rays go to the accelerator).
    pub cubes: usize,
    /// The scene's lights.
    pub lights: usize,
    /// Of the cubes' cells, those whose list was too long to keep.
    pub long_cells: usize,
    /// Entries over all the kept lists.
    pub listed: usize,
    pub memory_bytes: u64,
}

/// The light buffers of a scene's lights, in the scene's order.
pub struct LightBuffer {
    /// `None` for a light whose cells are mostly too long to list.
    cubes: Vec<Option<DirectionCube>>,
    /// Shapes without bounds (planes, unclipped quadrics): every shadow
    /// ray tests them.
    unbounded: Vec<u32>,
    /// What it was built for: a renderer of other lights or shapes
    /// ignores it.
    lights: Vec<DVec3>,
    shape_count: usize,
    stats: LightBufferStats,
}

/// What a light buffer says of one shadow ray.
pub enum Candidates<'a> {
    /// Every bounded shape the ray can meet (maybe none).
    Few(&'a [u32]),
    /// Too many to list: ask the accelerator.
    Many,
}

impl LightBuffer {
    /// The buffers of `lights` over `shapes`, built on the current rayon
    /// pool; `None` for a scene without lights or too large to project in
    /// tens of milliseconds.
    pub fn build(shapes: &[Shape], lights: &[DVec3]) -> Option<Self> {
        if lights.is_empty() || shapes.len().saturating_mul(lights.len()) > MAX_PAIRS {
            return None;
        }
        let (mut boxes, mut unbounded) = (Vec::new(), Vec::new());
        for (i, shape) in shapes.iter().enumerate() {
            match shape.bounds() {
                Some(b) => boxes.push((i as u32, b)),
                None => unbounded.push(i as u32),
            }
        }
        // The magnitude of every point a shadow ray's hit is computed from.
        let scale = boxes
            .iter()
            .fold(Aabb::from_points(lights), |all, (_, b)| all.union(*b))
            .max_abs()
            .max(f64::MIN_POSITIVE);
        let (pad, near) = (BOX_PAD * scale, NEAR_LIGHT * scale);
        let cube = |(i, &light): (usize, &DVec3)| {
            (i < MAX_CUBES)
                .then(|| DirectionCube::build(&boxes, light, pad, near))
                .flatten()
        };
        let cubes: Vec<Option<DirectionCube>> = if shapes.len() * lights.len() < PARALLEL_PAIRS {
            lights.iter().enumerate().map(cube).collect()
        } else {
            lights.par_iter().enumerate().map(cube).collect()
        };
        let kept = || cubes.iter().flatten();
        let stats = LightBufferStats {
            cubes: kept().count(),
            lights: lights.len(),
            long_cells: kept()
                .map(|c| c.starts.iter().filter(|&&s| s & LONG != 0).count())
                .sum(),
            listed: kept().map(|c| c.shapes.len()).sum(),
            memory_bytes: 4
                * (kept()
                    .map(|c| c.starts.len() + c.shapes.len())
                    .sum::<usize>()
                    + unbounded.len()) as u64,
        };
        Some(Self {
            cubes,
            unbounded,
            lights: lights.to_vec(),
            shape_count: shapes.len(),
            stats,
        })
    }

    /// Whether it was built for these lights over this many shapes (a
    /// buffer of moved lights would answer wrongly).
    pub fn fits(&self, shape_count: usize, lights: &[DVec3]) -> bool {
        self.shape_count == shape_count && self.lights == lights
    }

    pub fn stats(&self) -> LightBufferStats {
        self.stats
    }

    /// The shapes without bounds.
    #[inline(always)]
    pub fn unbounded(&self) -> &[u32] {
        &self.unbounded
    }

    /// The bounded shapes the shadow ray `ray` (from the surface to light
    /// `light`) can meet.
    #[inline(always)]
    pub fn candidates(&self, light: usize, ray: &PreparedRay) -> Candidates<'_> {
        let Some(Some(cube)) = self.cubes.get(light) else {
            return Candidates::Many;
        };
        let cell = cell_of_ray(ray);
        let start = cube.starts[cell];
        if start & LONG != 0 {
            return Candidates::Many;
        }
        let end = cube.starts[cell + 1] & !LONG;
        Candidates::Few(&cube.shapes[start as usize..end as usize])
    }
}

/// The cells of one face a box can be seen through, as inclusive ranges.
#[derive(Clone, Copy)]
struct Rect {
    shape: u32,
    face: u8,
    /// `[i0, i1, j0, j1]`: columns then rows.
    cells: [u8; 4],
}

impl DirectionCube {
    fn build(boxes: &[(u32, Aabb)], light: DVec3, pad: f64, near: f64) -> Option<Self> {
        let mut rects: Vec<Rect> = Vec::new();
        for &(shape, b) in boxes {
            let b = Aabb::new(b.min - pad - light, b.max + pad - light);
            let gap = (b.min.max(DVec3::ZERO) + (-b.max).max(DVec3::ZERO)).length();
            // A box beyond f64's range projects to no number: every cell.
            let everywhere = gap <= near || !(b.min.is_finite() && b.max.is_finite());
            for face in 0..6 {
                let cells = if everywhere {
                    Some([0, SIDE as u8 - 1, 0, SIDE as u8 - 1])
                } else {
                    face_rect(&b, face)
                };
                if let Some(cells) = cells {
                    rects.push(Rect {
                        shape,
                        face: face as u8,
                        cells,
                    });
                }
            }
        }
        let counts = cell_counts(&rects);
        // Mostly long lists would cost every shadow ray a look-up that
        // sends it to the accelerator anyway (a terrain, or gears, seen
        // from above): decided before any list is filled.
        let occupied = counts.iter().filter(|&&c| c > 0).count();
        let long_cells = counts.iter().filter(|&&c| c as usize > MAX_LIST).count();
        if 10 * long_cells > 9 * occupied {
            return None;
        }
        let mut starts = Vec::with_capacity(CUBE_CELLS + 1);
        let mut next = 0u32;
        for &c in &counts {
            if c as usize > MAX_LIST {
                starts.push(next | LONG);
            } else {
                starts.push(next);
                next += c;
            }
        }
        starts.push(next);
        let mut shapes = vec![0u32; next as usize];
        let mut filled = vec![0u8; CUBE_CELLS];
        for r in &rects {
            let [i0, i1, j0, j1] = r.cells.map(usize::from);
            let face = r.face as usize * FACE_CELLS;
            for j in j0..=j1 {
                for cell in face + j * SIDE + i0..=face + j * SIDE + i1 {
                    let start = starts[cell];
                    if start & LONG == 0 {
                        shapes[(start + filled[cell] as u32) as usize] = r.shape;
                        filled[cell] += 1;
                    }
                }
            }
        }
        Some(Self { starts, shapes })
    }
}

/// How many rectangles cover each cell, by a summed difference table:
/// constant work per rectangle however many cells it covers.
fn cell_counts(rects: &[Rect]) -> Vec<u32> {
    const ROW: usize = SIDE + 1;
    let mut diff = vec![0i32; 6 * ROW * ROW];
    for r in rects {
        let [i0, i1, j0, j1] = r.cells.map(usize::from);
        let f = r.face as usize * ROW * ROW;
        diff[f + j0 * ROW + i0] += 1;
        diff[f + j0 * ROW + i1 + 1] -= 1;
        diff[f + (j1 + 1) * ROW + i0] -= 1;
        diff[f + (j1 + 1) * ROW + i1 + 1] += 1;
    }
    let mut counts = vec![0u32; CUBE_CELLS];
    for face in 0..6 {
        let d = &mut diff[face * ROW * ROW..(face + 1) * ROW * ROW];
        for j in 0..SIDE {
            for i in 0..SIDE {
                let above = if j > 0 { d[(j - 1) * ROW + i] } else { 0 };
                let left = if i > 0 { d[j * ROW + i - 1] } else { 0 };
                let corner = if i > 0 && j > 0 {
                    d[(j - 1) * ROW + i - 1]
                } else {
                    0
                };
                d[j * ROW + i] += above + left - corner;
                counts[face * FACE_CELLS + j * SIDE + i] = d[j * ROW + i] as u32;
            }
        }
    }
    counts
}

/// The cell a direction from the light falls in: the definition
/// [`cell_of_ray`] computes from a prepared ray (a test holds them equal).
#[cfg(test)]
fn cell_of(d: DVec3) -> usize {
    let a = d.abs();
    let major = if a.x >= a.y && a.x >= a.z {
        0
    } else if a.y >= a.z {
        1
    } else {
        2
    };
    let face = 2 * major + (d[major] < 0.0) as usize;
    let m = a[major];
    let (u, v) = (d[(major + 1) % 3] / m, d[(major + 2) % 3] / m);
    face * FACE_CELLS + cell_index(v) * SIDE + cell_index(u)
}

/// [`cell_of`] of the direction back along `ray` (from the light), the
/// same cell from the ray's prepared shear instead of two divisions (the
/// divisions' latency was a tenth of a shadow ray's time on the default
/// scene).
#[inline(always)]
fn cell_of_ray(ray: &PreparedRay) -> usize {
    let (major, u, v) = ray.cube_face();
    // Back along the ray: every component negated. The face's sign is the
    // direction's own (a zero component, as `cell_of` has it, counts as
    // positive after negation).
    let face = 2 * major + (ray.ray.dir[major] > 0.0) as usize;
    face * FACE_CELLS + cell_index(-v) * SIDE + cell_index(-u)
}

/// The cell along one side that face coordinate `u` (in `[-1, 1]`) falls in.
#[inline(always)]
fn cell_index(u: f64) -> usize {
    // A NaN (a zero direction) lands in cell 0: `as` saturates.
    (((u + 1.0) * 0.5 * SIDE as f64) as usize).min(SIDE - 1)
}

/// The cells of `face` that box `b` (relative to the light) can be seen
/// through, as inclusive ranges `[i0, i1, j0, j1]`, or `None`.
fn face_rect(b: &Aabb, face: usize) -> Option<[u8; 4]> {
    let major = face / 2;
    let (across_u, across_v) = ((major + 1) % 3, (major + 2) % 3);
    // Distances along the face's axis (positive in front of the light).
    let (m0, m1) = if face.is_multiple_of(2) {
        (b.min[major], b.max[major])
    } else {
        (-b.max[major], -b.min[major])
    };
    if m1 <= 0.0 {
        return None;
    }
    // A direction in this face's region has |u|, |v| <= m: the box's
    // points nearer the light's plane than their distance off the axis
    // lie in other faces' regions.
    let off_axis = |axis: usize| b.min[axis].max(-b.max[axis]).max(0.0);
    let m0 = m0.max(off_axis(across_u)).max(off_axis(across_v));
    if m0 > m1 {
        return None;
    }
    let range = |axis: usize| -> (f64, f64) {
        if m0 <= 0.0 {
            // The box reaches the light's plane: directions up to the
            // face's edges.
            return (-1.0, 1.0);
        }
        // x / m over the box is monotone in each, so its extremes are at
        // the corners.
        let (lo, hi) = (b.min[axis], b.max[axis]);
        let corners = [lo / m0, lo / m1, hi / m0, hi / m1];
        let min = corners.iter().copied().fold(f64::INFINITY, f64::min);
        let max = corners.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        (min - FACE_PAD, max + FACE_PAD)
    };
    let (u0, u1) = range(across_u);
    let (v0, v1) = range(across_v);
    if u0 > 1.0 || u1 < -1.0 || v0 > 1.0 || v1 < -1.0 {
        return None;
    }
    let cell = |u: f64| cell_index(u.clamp(-1.0, 1.0)) as u8;
    Some([cell(u0), cell(u1), cell(v0), cell(v1)])
}

#[cfg(test)]
mod tests;
