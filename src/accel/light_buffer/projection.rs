//! Where a shape is seen from a light: the cells of each face of the
//! cube of directions that its points can lie in, as rows of cells. A box
//! projects to a rectangle; a cone's pieces and a triangle project row by
//! row, far tighter for slanted, thin shapes (a cylinder of a ring, a
//! sliver of a fan-cut polygon). Every projection is conservative: padded
//! in space by the caller and in face coordinates by [`FACE_PAD`] or more.

use super::{FACE_PAD, SIDE, cell_index};
use crate::math::{Aabb, DVec3};

/// Joins the rows of one shape on one face, given in increasing order,
/// into rectangles `[i0, i1, j0, j1]`: adjacent rows alike are one.
pub(super) struct Runs<'p, F: FnMut([u8; 4])> {
    run: Option<[u8; 4]>,
    push: &'p mut F,
}

impl<'p, F: FnMut([u8; 4])> Runs<'p, F> {
    pub(super) fn new(push: &'p mut F) -> Self {
        Self { run: None, push }
    }

    /// Row `j`'s cells `i0..=i1`.
    pub(super) fn row(&mut self, j: u8, i0: u8, i1: u8) {
        match &mut self.run {
            Some(cells) if cells[0] == i0 && cells[1] == i1 && cells[3] + 1 == j => cells[3] = j,
            run => {
                if let Some(cells) = run.take() {
                    (self.push)(cells);
                }
                *run = Some([i0, i1, j, j]);
            }
        }
    }

    pub(super) fn finish(self) {
        if let Some(cells) = self.run {
            (self.push)(cells);
        }
    }
}

/// One shape's rectangles on a face, as rectangles that cover each cell
/// once: row by row, the span from the leftmost to the rightmost cell of
/// the pieces crossing the row.
pub(super) fn merge_rows(pieces: &[[u8; 4]], push: &mut impl FnMut([u8; 4])) {
    if let [cells] = pieces {
        push(*cells);
        return;
    }
    let Some(first) = pieces.iter().map(|c| c[2]).min() else {
        return;
    };
    let last = pieces.iter().map(|c| c[3]).max().unwrap_or(first);
    let mut runs = Runs::new(push);
    for j in first..=last {
        let (mut i0, mut i1) = (u8::MAX, 0);
        for c in pieces.iter().filter(|c| c[2] <= j && j <= c[3]) {
            (i0, i1) = (i0.min(c[0]), i1.max(c[1]));
        }
        if i0 <= i1 {
            runs.row(j, i0, i1);
        }
    }
    runs.finish();
}

/// The distance from the origin to the triangle `v` (the closest point
/// by the regions of its corners, edges and face: Ericson, Real-Time
/// Collision Detection, 5.1.5), or `None` for a sliver (an angle's sine
/// under 1e-3), whose closest point rounding could move far.
pub(super) fn nearest_distance(v: &[DVec3; 3]) -> Option<f64> {
    let [a, b, c] = *v;
    let (ab, ac, bc) = (b - a, c - a, c - b);
    let twice_area = ab.cross(ac).length_squared();
    let longest = ab
        .length_squared()
        .max(ac.length_squared())
        .max(bc.length_squared());
    // The smallest angle's sine is twice the area over the product of
    // the two longest sides, at least over the longest side squared.
    if !(twice_area >= 1e-6 * longest * longest) {
        return None;
    }
    Some(closest_point(a, b, c).length())
}

/// The triangle's point nearest the origin.
fn closest_point(a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let (ab, ac, ap) = (b - a, c - a, -a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = -b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + d1 / (d1 - d3) * ab;
    }
    let cp = -c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + d2 / (d2 - d6) * ac;
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && d4 - d3 >= 0.0 && d5 - d6 >= 0.0 {
        return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
    }
    let denominator = 1.0 / (va + vb + vc);
    a + vb * denominator * ab + vc * denominator * ac
}

/// The rows of `face` through which the triangle `v` (relative to the
/// light, each point padded by `pad` in space by the caller's box) can be
/// seen, within `bound` (the rectangle of its padded box), or `false` if
/// it does not lie wholly in front of the face's plane (a vertex behind
/// it, or nearer than twice the padding), for which the box is used.
///
/// In front of the plane, the triangle projects to the triangle of its
/// projected vertices; row by row, the columns it covers run from its
/// leftmost to its rightmost point in the row's band, which lie at
/// vertices or where edges cross the band's edges. A point `pad` off the
/// triangle, at least `m` in front of the plane, projects at most
/// `2 pad (1 + |u|) / m` from it: the band and the columns are widened
/// by that and by [`FACE_PAD`].
pub(super) fn triangle_rows<F: FnMut([u8; 4])>(
    v: &[DVec3; 3],
    face: usize,
    pad: f64,
    bound: [u8; 4],
    push: &mut F,
) -> bool {
    // A rectangle a row high or a column wide is as tight as rows get.
    if bound[0] == bound[1] || bound[2] == bound[3] {
        push(bound);
        return true;
    }
    let major = face / 2;
    let (across_u, across_v) = ((major + 1) % 3, (major + 2) % 3);
    let sign = if face.is_multiple_of(2) { 1.0 } else { -1.0 };
    let m = v.map(|p| sign * p[major]);
    let m_min = m[0].min(m[1]).min(m[2]);
    if !(m_min > 2.0 * pad) {
        return false;
    }
    let uv: [(f64, f64); 3] =
        std::array::from_fn(|k| (v[k][across_u] / m[k], v[k][across_v] / m[k]));
    let widest = uv
        .iter()
        .fold(0.0f64, |w, &(u, v)| w.max(u.abs()).max(v.abs()));
    let margin = FACE_PAD + 2.0 * pad * (1.0 + widest) / m_min;
    if !(margin < 1.0) {
        return false;
    }
    let cell = |u: f64| cell_index(u.clamp(-1.0, 1.0)) as u8;
    let (v_lo, v_hi) = uv
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &(_, v)| {
            (lo.min(v), hi.max(v))
        });
    let rows = cell(v_lo - margin).max(bound[2])..=cell(v_hi + margin).min(bound[3]);
    // Each edge not along a row: its corners, the change in u per unit
    // of v (infinite for an edge too flat to divide by: both its corners'
    // columns are then taken), and its range of v.
    let edges: [Option<_>; 3] = std::array::from_fn(|k| {
        let (p, q) = (uv[k], uv[(k + 1) % 3]);
        (p.1 != q.1).then(|| {
            (
                p,
                q,
                (q.0 - p.0) / (q.1 - p.1),
                (p.1.min(q.1), p.1.max(q.1)),
            )
        })
    });
    let mut runs = Runs::new(push);
    for j in rows {
        // The row's band, widened.
        let step = 2.0 / SIDE as f64;
        let (a, b) = (
            -1.0 + f64::from(j) * step - margin,
            -1.0 + f64::from(j + 1) * step + margin,
        );
        let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
        for (k, &(u, v)) in uv.iter().enumerate() {
            if a <= v && v <= b {
                (lo, hi) = (lo.min(u), hi.max(u));
            }
            if let Some((p, q, slope, (v0, v1))) = edges[k] {
                for level in [a, b] {
                    if v0 <= level && level <= v1 {
                        let (u0, u1) = if slope.is_finite() {
                            let u = p.0 + (level - p.1) * slope;
                            (u, u)
                        } else {
                            (p.0.min(q.0), p.0.max(q.0))
                        };
                        (lo, hi) = (lo.min(u0), hi.max(u1));
                    }
                }
            }
        }
        if lo > hi {
            continue;
        }
        let (i0, i1) = (
            cell(lo - margin).max(bound[0]),
            cell(hi + margin).min(bound[1]),
        );
        if i0 <= i1 {
            runs.row(j, i0, i1);
        }
    }
    runs.finish();
    true
}

/// The cells of `face` that box `b` (relative to the light) can be seen
/// through, as inclusive ranges `[i0, i1, j0, j1]`, or `None`.
pub(super) fn face_rect(b: &Aabb, face: usize) -> Option<[u8; 4]> {
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
