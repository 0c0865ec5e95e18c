//! The light buffer (Haines and Greenberg 1986): for each point light, a
//! cube of directions around it whose cells list the bounded shapes that
//! a ray leaving the light in that direction can meet. A shadow ray whose
//! cell lists a few shapes is answered by testing those and the unbounded
//! ones: brute force over every shape that can meet it, so the answer is
//! brute force's, which every accelerator's is. Most shadow rays reach
//! their light through a cell that lists nothing. A cell that would list
//! more than [`MAX_LIST`] shapes (over a mesh, say) is left to the
//! accelerator, but for shadow rays from points nearer the light than
//! all but its nearest few. Triangles and cones are listed where they
//! themselves are seen, not their boxes (`projection.rs`).

mod projection;

use rayon::prelude::*;
use serde::Serialize;

use self::projection::{face_rect, merge_rows, nearest_distance, triangle_rows};
use crate::math::{Aabb, DVec3};
use crate::shapes::{PreparedRay, Shape};

/// Cells along a side of each of the cube's six faces: finer cells list
/// fewer shapes a shadow ray need not meet, at four times the memory per
/// doubling; 128 is where the gain stopped paying for the memory
/// (docs/notes/experiments.md, "Figures behind constants").
const SIDE: usize = 128;
const FACE_CELLS: usize = SIDE * SIDE;
const CUBE_CELLS: usize = 6 * FACE_CELLS;
/// Longest list a cell keeps; a longer one goes to the accelerator,
/// except for the shadow rays that start nearer the light than its first
/// `MAX_LIST` shapes leave (see [`DirectionCube`]). A ray tests only the
/// shapes nearer the light than its origin, so a long list costs little
/// and spares a walk (docs/notes/experiments.md, "Figures behind
/// constants").
const MAX_LIST: usize = 32;
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
/// and at most `MAX_LIST + 1` entries of 8 bytes a cell, 26 MiB; real
/// scenes' cubes hold a few MiB (gears' five 5 MB in all; an 80-light
/// scene of 6,500 shapes took 75 MB at its peak with 64 cubes, 36 MB
/// with these 16).
const MAX_CUBES: usize = 16;
/// In a cube's `starts`: the cell's list was too long to keep whole.
const LONG: u32 = 1 << 31;

/// One light's cube of directions. Every list is sorted by how near its
/// shapes (their boxes, or a triangle itself) come to the light, and a shadow ray tests only those
/// nearer the light than its origin (no point of the ray is farther). A
/// long cell keeps its `MAX_LIST` nearest, then the nearness of the first
/// one left out: a shadow ray that starts nearer (a point lit through a
/// crowded cell, on the first surface the light sees) is answered from
/// them as from a short list.
struct DirectionCube {
    /// Per cell, where its list starts in `shapes`, or [`LONG`] added for a
    /// cell whose list was too long; one more entry ends the last list.
    starts: Vec<u32>,
    shapes: Vec<u32>,
    /// Per entry of `shapes`, how near its box comes to the light, less
    /// the padding, rounded down ([`reach_key`]).
    nears: Vec<f32>,
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
        // A shape's boxes, consecutive: one, or a cone's pieces.
        let (mut boxes, mut unbounded) = (Vec::new(), Vec::new());
        for (i, shape) in shapes.iter().enumerate() {
            match shape {
                Shape::Cone(cone) => boxes.extend(cone.cover().map(|b| (i as u32, b))),
                _ => match shape.bounds() {
                    Some(b) => boxes.push((i as u32, b)),
                    None => unbounded.push(i as u32),
                },
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
                .then(|| DirectionCube::build(shapes, &boxes, light, pad, near))
                .flatten()
        };
        let cubes: Vec<Option<DirectionCube>> = if shapes.len() * lights.len() < PARALLEL_PAIRS {
            lights.iter().enumerate().map(cube).collect()
        } else {
            lights.par_iter().enumerate().map(cube).collect()
        };
        let kept = || cubes.iter().flatten();
        let long_cells = kept()
            .map(|c| c.starts.iter().filter(|&&s| s & LONG != 0).count())
            .sum();
        let stats = LightBufferStats {
            cubes: kept().count(),
            lights: lights.len(),
            long_cells,
            listed: kept().map(|c| c.shapes.len()).sum::<usize>() - long_cells,
            memory_bytes: 4
                * (kept()
                    .map(|c| c.starts.len() + c.shapes.len() + c.nears.len())
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
        let (start, end) = (cube.starts[cell], cube.starts[cell + 1] & !LONG);
        let first = (start & !LONG) as usize;
        if first == end as usize {
            // Most shadow rays: nothing in the way.
            return Candidates::Few(&[]);
        }
        // The ray's points are no farther from the light than its origin:
        // the shapes whose boxes keep farther off cannot meet it (a NaN
        // keeps every one).
        let reach = (ray.ray.origin - self.lights[light]).length_squared();
        let beyond = |near: f32| f64::from(near) * f64::from(near) > reach;
        let nears = &cube.nears[first..end as usize];
        // Often the ray starts past them all (or, in a long cell, past
        // those kept): one comparison.
        let met = if nears.last().is_some_and(|&near| beyond(near)) {
            nears.iter().take_while(|&&near| !beyond(near)).count()
        } else if start & LONG != 0 {
            return Candidates::Many;
        } else {
            nears.len()
        };
        Candidates::Few(&cube.shapes[first..first + met])
    }
}

/// One shape as a light sees it (16 bytes: one per shape and cube being
/// built).
struct Seen {
    /// How near its boxes come (see [`Rect::near`]); 0 if `everywhere`.
    near: f32,
    /// Where its boxes start in the builder's list of boxes, and its whole
    /// box's rectangles in `whole_rects`.
    first_box: u32,
    first_rect: u32,
    /// So near the light (or so far out of range) that every direction
    /// may meet it.
    everywhere: bool,
}

/// The cells of one face a box can be seen through, as inclusive ranges.
#[derive(Clone, Copy)]
struct Rect {
    shape: u32,
    /// How near the box comes to the light, less the padding, rounded
    /// down: nothing of the shape a shadow ray can meet is nearer.
    near: f32,
    face: u8,
    /// `[i0, i1, j0, j1]`: columns then rows.
    cells: [u8; 4],
}

impl DirectionCube {
    fn build(
        scene: &[Shape],
        boxes: &[(u32, Aabb)],
        light: DVec3,
        pad: f64,
        near: f64,
    ) -> Option<Self> {
        // A box relative to the light, padded.
        let seen_box = |b: Aabb| Aabb::new(b.min - pad - light, b.max + pad - light);
        let mut groups: Vec<Seen> = Vec::new();
        // Whole boxes' rectangles first: cheap, and enough to tell a cube
        // of mostly long lists, which is not kept.
        let mut whole_rects: Vec<Rect> = Vec::new();
        let mut first_box = 0;
        for group in boxes.chunk_by(|a, b| a.0 == b.0) {
            let (mut key, mut everywhere, mut whole) = (f32::INFINITY, false, Aabb::EMPTY);
            for &(_, b) in group {
                let b = seen_box(b);
                let gap = (b.min.max(DVec3::ZERO) + (-b.max).max(DVec3::ZERO)).length();
                // A box beyond f64's range projects to no number: every cell.
                everywhere |= gap <= near || !(b.min.is_finite() && b.max.is_finite());
                key = key.min(reach_key(gap - pad));
                whole = whole.union(b);
            }
            // A triangle comes no nearer than its nearest point, often
            // farther than its box's corner (for one whose angles are all
            // far from 0 and 180 degrees: the closest point's rounding then
            // stays far below the padding).
            if let Shape::Triangle(triangle) = &scene[group[0].0 as usize]
                && let Some(distance) = nearest_distance(&triangle.vertices.map(|c| c - light))
            {
                key = key.max(reach_key(distance - 2.0 * pad));
            }
            let key = if everywhere { 0.0 } else { key };
            groups.push(Seen {
                near: key,
                first_box,
                first_rect: whole_rects.len() as u32,
                everywhere,
            });
            first_box += group.len() as u32;
            for face in 0..6 {
                let cells = if everywhere {
                    Some([0, SIDE as u8 - 1, 0, SIDE as u8 - 1])
                } else {
                    face_rect(&whole, face)
                };
                if let Some(cells) = cells {
                    whole_rects.push(Rect {
                        shape: group[0].0,
                        near: key,
                        face: face as u8,
                        cells,
                    });
                }
            }
        }
        // Mostly long lists would cost every shadow ray a look-up that
        // sends it to the accelerator anyway (a terrain, or gears, seen
        // from above): decided before any list is filled.
        let counts = cell_counts(&whole_rects);
        let occupied = counts.iter().filter(|&&c| c > 0).count();
        let long_cells = counts.iter().filter(|&&c| c as usize > MAX_LIST).count();
        if 10 * long_cells > 9 * occupied {
            return None;
        }
        // Nearest the light first, ties by shape (groups come in shape
        // order): each cell's list comes out sorted, and a long cell's
        // first shape left out gives the nearness it is whole within. A
        // key is never negative, so its bits sort as its value.
        let mut order: Vec<u64> = groups
            .iter()
            .enumerate()
            .map(|(g, seen)| u64::from(seen.near.to_bits()) << 32 | g as u64)
            .collect();
        order.sort_unstable();
        // Then each shape's own outline, within its whole box's
        // rectangles: a triangle's rows, a cone's pieces.
        let mut rects: Vec<Rect> = Vec::with_capacity(whole_rects.len());
        let (mut near_boxes, mut pieces) = (Vec::new(), Vec::new());
        for &o in &order {
            let g = o as u32 as usize;
            let (seen, next) = (&groups[g], groups.get(g + 1));
            let everywhere = seen.everywhere;
            let group =
                &boxes[seen.first_box as usize..next.map_or(boxes.len(), |n| n.first_box as usize)];
            let whole = &whole_rects[seen.first_rect as usize
                ..next.map_or(whole_rects.len(), |n| n.first_rect as usize)];
            let triangle = match &scene[group[0].0 as usize] {
                Shape::Triangle(t) => Some(t),
                _ => None,
            };
            // One box of another shape: its rectangles are its outline.
            if everywhere || (triangle.is_none() && group.len() == 1) {
                rects.extend_from_slice(whole);
                continue;
            }
            if triangle.is_none() {
                near_boxes.clear();
                near_boxes.extend(group.iter().map(|&(_, b)| seen_box(b)));
            }
            for &outline in whole {
                let (face, cells) = (outline.face, outline.cells);
                let mut push = |cells| rects.push(Rect { cells, ..outline });
                if let Some(triangle) = triangle {
                    let corners = triangle.vertices.map(|c| c - light);
                    if !triangle_rows(&corners, face as usize, pad, cells, &mut push) {
                        push(cells);
                    }
                } else {
                    pieces.clear();
                    pieces.extend(
                        near_boxes
                            .iter()
                            .filter_map(|b| face_rect(b, face as usize)),
                    );
                    merge_rows(&pieces, &mut push);
                }
            }
        }
        let counts = cell_counts(&rects);
        let mut starts = Vec::with_capacity(CUBE_CELLS + 1);
        let mut next = 0u32;
        for &c in &counts {
            if c as usize > MAX_LIST {
                starts.push(next | LONG);
                next += MAX_LIST as u32 + 1;
            } else {
                starts.push(next);
                next += c;
            }
        }
        starts.push(next);
        // `rects` come in the order of `order`: every list sorted.
        let mut shapes = vec![0u32; next as usize];
        let mut nears = vec![0f32; next as usize];
        let mut filled = vec![0u8; CUBE_CELLS];
        for r in &rects {
            let [i0, i1, j0, j1] = r.cells.map(usize::from);
            let face = r.face as usize * FACE_CELLS;
            for j in j0..=j1 {
                for cell in face + j * SIDE + i0..=face + j * SIDE + i1 {
                    let (start, n) = (starts[cell], filled[cell] as usize);
                    if start & LONG != 0 && n > MAX_LIST {
                        continue;
                    }
                    let at = (start & !LONG) as usize + n;
                    // A long cell's last entry only marks the nearness.
                    shapes[at] = r.shape;
                    nears[at] = r.near;
                    filled[cell] += 1;
                }
            }
        }
        Some(Self {
            starts,
            shapes,
            nears,
        })
    }
}

/// `distance` rounded down to an `f32` no less than zero, so that a shape
/// is never ruled out for a ray it could meet.
fn reach_key(distance: f64) -> f32 {
    if !(distance > 0.0) {
        return 0.0;
    }
    let key = distance as f32;
    if f64::from(key) > distance {
        key.next_down()
    } else {
        key
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
    // Clamped as a float first (`max` takes a NaN, from a zero direction,
    // to 0), so the conversion needs no saturating checks of its own.
    ((u + 1.0) * 0.5 * SIDE as f64)
        .max(0.0)
        .min((SIDE - 1) as f64) as u32 as usize
}

#[cfg(test)]
mod tests;
