//! Triangulation of simple polygons by ear clipping.
//!
//! NFF `p`/`pp` entities and OBJ faces with more than three vertices may be
//! concave (the gear faces of the SPD's `gears` are 144-vertex outlines with
//! 36 teeth), so a fan from the first vertex is wrong for them. This module
//! projects a polygon onto its own plane (the Newell normal), removes repeated
//! and collinear vertices, refuses polygons whose edges cross, and clips ears:
//! by the two-ears theorem (Meisters, "Polygons have ears", Amer. Math.
//! Monthly 82, 1975) every simple polygon with more than three vertices has a
//! vertex whose triangle with its neighbours lies inside it. A vertex is an
//! ear when it is convex and no reflex vertex lies in that triangle
//! (Eberly, "Triangulation by Ear Clipping", Geometric Tools, 2002).
//!
//! The triangles run in the polygon's own winding, so their normals face
//! the same side as the polygon's, whichever way it was given.

use crate::math::{DVec3, orthonormal_basis};

/// Why a polygon could not be triangulated. Such polygons are dropped at
/// load and counted, never filled some other way.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PolygonDefect {
    /// Fewer than three distinct vertices, all vertices on one line, or a
    /// non-finite coordinate: nothing to fill.
    ZeroArea,
    /// Two edges cross, or the outline touches itself so that no ear
    /// clipping exists: not a simple polygon.
    NotSimple,
}

/// Counts of polygons dropped at load, by reason.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct DroppedPolygons {
    pub zero_area: usize,
    pub not_simple: usize,
}

impl DroppedPolygons {
    pub fn record(&mut self, defect: PolygonDefect) {
        match defect {
            PolygonDefect::ZeroArea => self.zero_area += 1,
            PolygonDefect::NotSimple => self.not_simple += 1,
        }
    }

    pub fn total(&self) -> usize {
        self.zero_area + self.not_simple
    }
}

/// Sine of the angle below which three consecutive vertices count as
/// collinear: far below any feature a scene file can describe (NFF files
/// carry about six significant digits), far above rounding error.
const COLLINEAR_SINE: f64 = 1e-10;

/// Up to this many edges, crossings are found by testing every pair; above
/// it, through a grid over the polygon.
const BRUTE_FORCE_EDGES: usize = 64;

/// Triangles (as indices into `vertices`, in the polygon's winding) that
/// exactly cover the simple polygon with these vertices, in order.
pub fn triangulate(vertices: &[DVec3]) -> Result<Vec<[u32; 3]>, PolygonDefect> {
    if vertices.len() < 3 || !vertices.iter().all(|v| v.is_finite()) {
        return Err(PolygonDefect::ZeroArea);
    }
    if vertices.len() > u32::MAX as usize {
        return Err(PolygonDefect::NotSimple);
    }
    // Work relative to the centroid: the numbers then carry the polygon's
    // size, not its distance from the origin.
    let centroid = vertices.iter().copied().sum::<DVec3>() / vertices.len() as f64;
    let local: Vec<DVec3> = vertices.iter().map(|&v| v - centroid).collect();
    // Scaled by a power of two to about unit size. That is exact, so every
    // test below decides as it would unscaled, while its products of up to
    // four coordinates neither overflow (a polygon 1e150 across) nor
    // underflow (1e-150 across).
    let largest = local
        .iter()
        .fold(0.0f64, |m, v| m.max(v.abs().max_element()));
    if !(largest > 0.0 && largest.is_finite()) {
        return Err(PolygonDefect::ZeroArea);
    }
    let exponent = largest.log2().floor() as i32;
    let (half, rest) = (
        2f64.powi(-exponent / 2),
        2f64.powi(-(exponent - exponent / 2)),
    );
    let local: Vec<DVec3> = local.iter().map(|&v| v * half * rest).collect();
    // Newell's normal: twice the vector area, pointing to the side from
    // which the vertices run counter-clockwise.
    let mut area_vector = DVec3::ZERO;
    for (i, &a) in local.iter().enumerate() {
        let b = local[(i + 1) % local.len()];
        area_vector += a.cross(b);
    }
    let extent = local.iter().fold(0.0f64, |m, v| m.max(v.length()));
    let twice_area = area_vector.length();
    if !(twice_area > 1e-12 * extent * extent) {
        // No net area: all on one line, or lobes of opposite turn that
        // cancel (a bow tie), which is a crossing outline.
        return Err(if spans_a_plane(&local, extent) {
            PolygonDefect::NotSimple
        } else {
            PolygonDefect::ZeroArea
        });
    }
    let normal = area_vector / twice_area;
    let (u, v) = orthonormal_basis(normal);
    // Orient the plane's axes so that the polygon runs counter-clockwise.
    let flip = if u.cross(v).dot(normal) < 0.0 {
        -1.0
    } else {
        1.0
    };
    let points: Vec<[f64; 2]> = local.iter().map(|p| [p.dot(u), flip * p.dot(v)]).collect();

    let mut ring = Ring::new(&points);
    ring.remove_degenerate_vertices();
    if ring.len < 3 {
        return Err(PolygonDefect::ZeroArea);
    }
    let outline = ring.indices();
    let area = signed_area(&points, &outline);
    if !(area > 0.0) {
        // The projection is positive by construction; a non-positive area
        // after cleaning means the outline folds back over itself.
        return Err(PolygonDefect::NotSimple);
    }
    if has_crossing(&points, &outline) {
        return Err(PolygonDefect::NotSimple);
    }
    let triangles = ring.clip_ears().ok_or(PolygonDefect::NotSimple)?;
    // A partition of a simple polygon has exactly its area; anything else
    // means the outline was not simple in a way the tests above let pass.
    let covered: f64 = triangles
        .iter()
        .map(|t| {
            orient(
                points[t[0] as usize],
                points[t[1] as usize],
                points[t[2] as usize],
            )
        })
        .sum::<f64>()
        * 0.5;
    if !((covered - area).abs() <= 1e-9 * area) {
        return Err(PolygonDefect::NotSimple);
    }
    Ok(triangles)
}

/// Whether the points (relative to their centroid, within `extent` of it)
/// do not all lie on one line.
fn spans_a_plane(points: &[DVec3], extent: f64) -> bool {
    let Some(&far) = points
        .iter()
        .max_by(|a, b| a.length_squared().total_cmp(&b.length_squared()))
    else {
        return false;
    };
    points
        .iter()
        .any(|p| far.cross(*p).length() > 1e-12 * extent * extent)
}

/// Twice the signed area of triangle `abc`: positive when counter-clockwise.
#[inline]
fn orient(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    (b[0] - a[0]) * (c[1] - a[1]) - (b[1] - a[1]) * (c[0] - a[0])
}

fn sub(a: [f64; 2], b: [f64; 2]) -> [f64; 2] {
    [a[0] - b[0], a[1] - b[1]]
}

fn norm(a: [f64; 2]) -> f64 {
    a[0].hypot(a[1])
}

/// Signed area of the closed outline through `indices`.
fn signed_area(points: &[[f64; 2]], indices: &[u32]) -> f64 {
    let mut sum = 0.0;
    for (k, &i) in indices.iter().enumerate() {
        let a = points[i as usize];
        let b = points[indices[(k + 1) % indices.len()] as usize];
        sum += a[0] * b[1] - a[1] * b[0];
    }
    0.5 * sum
}

/// Whether `b` turns neither left nor right on the way from `a` to `c`
/// (relative to the edge lengths), or repeats `a` or `c`.
fn is_degenerate_corner(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> bool {
    let (e1, e2) = (sub(b, a), sub(c, b));
    let (l1, l2) = (norm(e1), norm(e2));
    l1 == 0.0 || l2 == 0.0 || orient(a, b, c).abs() <= COLLINEAR_SINE * l1 * l2
}

/// The remaining outline as a doubly linked ring of vertex indices.
struct Ring<'a> {
    points: &'a [[f64; 2]],
    next: Vec<u32>,
    prev: Vec<u32>,
    removed: Vec<bool>,
    start: u32,
    len: usize,
}

impl<'a> Ring<'a> {
    fn new(points: &'a [[f64; 2]]) -> Self {
        let n = points.len();
        Self {
            points,
            next: (0..n).map(|i| ((i + 1) % n) as u32).collect(),
            prev: (0..n).map(|i| ((i + n - 1) % n) as u32).collect(),
            removed: vec![false; n],
            start: 0,
            len: n,
        }
    }

    fn p(&self, i: u32) -> [f64; 2] {
        self.points[i as usize]
    }

    fn unlink(&mut self, i: u32) {
        let (p, n) = (self.prev[i as usize], self.next[i as usize]);
        self.next[p as usize] = n;
        self.prev[n as usize] = p;
        self.removed[i as usize] = true;
        self.len -= 1;
        if self.start == i {
            self.start = n;
        }
    }

    fn indices(&self) -> Vec<u32> {
        let mut out = Vec::with_capacity(self.len);
        let mut i = self.start;
        for _ in 0..self.len {
            out.push(i);
            i = self.next[i as usize];
        }
        out
    }

    /// Removes repeated vertices, vertices on the straight line between
    /// their neighbours and the tips of zero-width spikes, until none is left:
    /// none of them changes the region the outline bounds.
    fn remove_degenerate_vertices(&mut self) {
        let mut i = self.start;
        let mut unchanged = 0;
        while self.len >= 3 && unchanged < self.len {
            let (p, n) = (self.prev[i as usize], self.next[i as usize]);
            if is_degenerate_corner(self.p(p), self.p(i), self.p(n)) {
                self.unlink(i);
                // The neighbours may have become degenerate: look at them again.
                i = p;
                unchanged = 0;
            } else {
                i = n;
                unchanged += 1;
            }
        }
    }

    fn is_degenerate(&self, i: u32) -> bool {
        let (p, n) = (self.prev[i as usize], self.next[i as usize]);
        is_degenerate_corner(self.p(p), self.p(i), self.p(n))
    }

    fn is_convex(&self, i: u32) -> bool {
        let (p, n) = (self.prev[i as usize], self.next[i as usize]);
        orient(self.p(p), self.p(i), self.p(n)) > 0.0
    }

    /// Whether vertex `i` and its neighbours form an ear: a convex corner
    /// whose triangle holds no reflex vertex, not even on its border.
    fn is_ear(&self, i: u32, reflex: &ReflexIndex) -> bool {
        if !self.is_convex(i) {
            return false;
        }
        let (p, n) = (self.prev[i as usize], self.next[i as usize]);
        let (a, b, c) = (self.p(p), self.p(i), self.p(n));
        !reflex.any_in_box(a, b, c, |k| {
            if self.removed[k as usize] || k == p || k == i || k == n || self.is_convex(k) {
                return false;
            }
            let q = self.p(k);
            // A vertex at the same place as a corner (a keyhole's bridge)
            // does not block the ear.
            if q == a || q == b || q == c {
                return false;
            }
            orient(a, b, q) >= 0.0 && orient(b, c, q) >= 0.0 && orient(c, a, q) >= 0.0
        })
    }

    /// Clips ears until one triangle is left; `None` if no ear can be found.
    fn clip_ears(&mut self) -> Option<Vec<[u32; 3]>> {
        let reflex = ReflexIndex::new(self);
        let mut triangles = Vec::with_capacity(self.len.saturating_sub(2));
        let mut i = self.start;
        let mut tried = 0;
        while self.len > 3 {
            if self.is_ear(i, &reflex) {
                let (p, n) = (self.prev[i as usize], self.next[i as usize]);
                triangles.push([p, i, n]);
                self.unlink(i);
                tried = 0;
                // Clipping can leave a neighbour straight or repeated:
                // such a corner bounds nothing and is dropped.
                for k in [n, p] {
                    if self.len > 3 && !self.removed[k as usize] && self.is_degenerate(k) {
                        self.unlink(k);
                    }
                }
                i = if self.removed[p as usize] {
                    self.start
                } else {
                    p
                };
            } else {
                tried += 1;
                if tried > self.len {
                    return None;
                }
                i = self.next[i as usize];
            }
        }
        let (p, n) = (self.prev[i as usize], self.next[i as usize]);
        if orient(self.p(p), self.p(i), self.p(n)) > 0.0 {
            triangles.push([p, i, n]);
        } else if orient(self.p(p), self.p(i), self.p(n)) < 0.0 {
            return None;
        }
        Some(triangles)
    }
}

/// The vertices that are reflex at the start (clipping only ever makes
/// corners more convex), bucketed in a grid for large polygons so an ear
/// test looks only at those near the candidate triangle.
struct ReflexIndex {
    min: [f64; 2],
    cell: [f64; 2],
    side: usize,
    cells: Vec<Vec<u32>>,
}

impl ReflexIndex {
    fn new(ring: &Ring) -> Self {
        let reflex: Vec<u32> = ring
            .indices()
            .into_iter()
            .filter(|&i| !ring.is_convex(i))
            .collect();
        let side = if reflex.len() <= BRUTE_FORCE_EDGES {
            1
        } else {
            ((reflex.len() as f64).sqrt().ceil() as usize).max(1)
        };
        let (min, max) = bounds(ring.points, &reflex);
        let cell = [
            ((max[0] - min[0]) / side as f64).max(f64::MIN_POSITIVE),
            ((max[1] - min[1]) / side as f64).max(f64::MIN_POSITIVE),
        ];
        let mut index = Self {
            min,
            cell,
            side,
            cells: vec![Vec::new(); side * side],
        };
        for k in reflex {
            let (x, y) = index.cell_of(ring.points[k as usize]);
            index.cells[y * side + x].push(k);
        }
        index
    }

    fn cell_of(&self, p: [f64; 2]) -> (usize, usize) {
        let f = |a: usize| {
            let c = ((p[a] - self.min[a]) / self.cell[a]).floor();
            if c.is_finite() && c > 0.0 {
                (c as usize).min(self.side - 1)
            } else {
                0
            }
        };
        (f(0), f(1))
    }

    /// Whether `hit` holds for any indexed vertex in the bounding box of `abc`.
    fn any_in_box(
        &self,
        a: [f64; 2],
        b: [f64; 2],
        c: [f64; 2],
        mut hit: impl FnMut(u32) -> bool,
    ) -> bool {
        let lo = [a[0].min(b[0]).min(c[0]), a[1].min(b[1]).min(c[1])];
        let hi = [a[0].max(b[0]).max(c[0]), a[1].max(b[1]).max(c[1])];
        let (x0, y0) = self.cell_of(lo);
        let (x1, y1) = self.cell_of(hi);
        for y in y0..=y1 {
            for x in x0..=x1 {
                if self.cells[y * self.side + x].iter().any(|&k| hit(k)) {
                    return true;
                }
            }
        }
        false
    }
}

fn bounds(points: &[[f64; 2]], indices: &[u32]) -> ([f64; 2], [f64; 2]) {
    let mut min = [f64::INFINITY; 2];
    let mut max = [f64::NEG_INFINITY; 2];
    for &i in indices {
        let p = points[i as usize];
        for a in 0..2 {
            min[a] = min[a].min(p[a]);
            max[a] = max[a].max(p[a]);
        }
    }
    if min[0] > max[0] {
        ([0.0; 2], [0.0; 2])
    } else {
        (min, max)
    }
}

/// Whether two edges of the outline that do not share a vertex properly
/// cross (each passes strictly from one side of the other to the other).
/// Touching is left to the ear clipping, which succeeds on outlines that
/// only touch themselves (keyholes) and fails on those that overlap.
fn has_crossing(points: &[[f64; 2]], outline: &[u32]) -> bool {
    let n = outline.len();
    let edge = |k: usize| {
        (
            points[outline[k] as usize],
            points[outline[(k + 1) % n] as usize],
        )
    };
    let crosses = |k: usize, m: usize| {
        // Adjacent edges share a vertex and cannot properly cross.
        if k == m || (k + 1) % n == m || (m + 1) % n == k {
            return false;
        }
        let (a, b) = edge(k);
        let (c, d) = edge(m);
        let (o1, o2) = (orient(a, b, c), orient(a, b, d));
        let (o3, o4) = (orient(c, d, a), orient(c, d, b));
        ((o1 > 0.0 && o2 < 0.0) || (o1 < 0.0 && o2 > 0.0))
            && ((o3 > 0.0 && o4 < 0.0) || (o3 < 0.0 && o4 > 0.0))
    };
    if n <= BRUTE_FORCE_EDGES {
        return (0..n).any(|k| (k + 1..n).any(|m| crosses(k, m)));
    }
    // Bucket the edges in a grid; only edges sharing a cell can cross.
    let (min, max) = bounds(points, outline);
    let side = ((n as f64).sqrt().ceil() as usize).max(1);
    let cell = [
        ((max[0] - min[0]) / side as f64).max(f64::MIN_POSITIVE),
        ((max[1] - min[1]) / side as f64).max(f64::MIN_POSITIVE),
    ];
    let cell_of = |p: [f64; 2], a: usize| {
        let c = ((p[a] - min[a]) / cell[a]).floor();
        if c.is_finite() && c > 0.0 {
            (c as usize).min(side - 1)
        } else {
            0
        }
    };
    let mut cells: Vec<Vec<u32>> = vec![Vec::new(); side * side];
    for k in 0..n {
        let (a, b) = edge(k);
        let (x0, x1) = (
            cell_of([a[0].min(b[0]), 0.0], 0),
            cell_of([a[0].max(b[0]), 0.0], 0),
        );
        let (y0, y1) = (
            cell_of([0.0, a[1].min(b[1])], 1),
            cell_of([0.0, a[1].max(b[1])], 1),
        );
        for y in y0..=y1 {
            for x in x0..=x1 {
                cells[y * side + x].push(k as u32);
            }
        }
    }
    cells.iter().any(|list| {
        list.iter().enumerate().any(|(s, &k)| {
            list[s + 1..]
                .iter()
                .any(|&m| crosses(k as usize, m as usize))
        })
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn flat(points: &[(f64, f64)]) -> Vec<DVec3> {
        points.iter().map(|&(x, y)| DVec3::new(x, y, 0.0)).collect()
    }

    fn area_of(vertices: &[DVec3], triangles: &[[u32; 3]]) -> DVec3 {
        triangles
            .iter()
            .map(|t| {
                let [a, b, c] = t.map(|i| vertices[i as usize]);
                0.5 * (b - a).cross(c - a)
            })
            .sum()
    }

    /// Even-odd point-in-polygon test in the xy plane, written
    /// independently of the triangulation.
    fn inside(polygon: &[(f64, f64)], x: f64, y: f64) -> bool {
        let mut inside = false;
        for k in 0..polygon.len() {
            let (x0, y0) = polygon[k];
            let (x1, y1) = polygon[(k + 1) % polygon.len()];
            if (y0 > y) != (y1 > y) && x < x0 + (y - y0) / (y1 - y0) * (x1 - x0) {
                inside = !inside;
            }
        }
        inside
    }

    fn shoelace(polygon: &[(f64, f64)]) -> f64 {
        let n = polygon.len();
        0.5 * (0..n)
            .map(|k| {
                let (a, b) = (polygon[k], polygon[(k + 1) % n]);
                a.0 * b.1 - a.1 * b.0
            })
            .sum::<f64>()
    }

    fn star(points: usize, outer: f64, inner: f64) -> Vec<(f64, f64)> {
        (0..2 * points)
            .map(|k| {
                let a = std::f64::consts::PI * k as f64 / points as f64;
                let r = if k % 2 == 0 { outer } else { inner };
                (r * a.cos(), r * a.sin())
            })
            .collect()
    }

    #[test]
    fn star_is_covered_exactly_in_both_windings() {
        let s = star(5, 1.0, 0.4);
        for polygon in [s.clone(), s.iter().rev().copied().collect()] {
            let vertices = flat(&polygon);
            let triangles = triangulate(&vertices).unwrap();
            assert_eq!(triangles.len(), 8);
            let area = area_of(&vertices, &triangles);
            // The triangles keep the polygon's orientation.
            let expected = shoelace(&polygon);
            assert!((area.z - expected).abs() < 1e-12, "{area} vs {expected}");
            for t in &triangles {
                let [a, b, c] = t.map(|i| vertices[i as usize]);
                assert!(
                    (b - a).cross(c - a).z * expected > 0.0,
                    "a triangle turned over"
                );
                let g = (a + b + c) / 3.0;
                assert!(inside(&polygon, g.x, g.y), "triangle outside the star");
            }
        }
    }

    #[test]
    fn fan_would_be_wrong_but_ears_are_right() {
        // An arrow head whose first vertex sees only part of the outline.
        let polygon = [(0.0, 0.0), (2.0, 1.0), (4.0, 0.0), (2.0, 3.0)];
        let rotated: Vec<_> = polygon.iter().cycle().skip(1).take(4).copied().collect();
        let triangles = triangulate(&flat(&rotated)).unwrap();
        let area = area_of(&flat(&rotated), &triangles).z;
        assert!((area - shoelace(&rotated)).abs() < 1e-12);
    }

    #[test]
    fn repeated_and_collinear_vertices_are_handled() {
        let polygon = [
            (0.0, 0.0),
            (0.0, 0.0),
            (1.0, 0.0),
            (2.0, 0.0),
            (2.0, 2.0),
            (1.0, 2.0),
            (0.0, 2.0),
            (0.0, 1.0),
            (0.0, 0.0),
        ];
        let vertices = flat(&polygon);
        let triangles = triangulate(&vertices).unwrap();
        assert!((area_of(&vertices, &triangles).z - 4.0).abs() < 1e-12);
        for t in &triangles {
            let [a, b, c] = t.map(|i| vertices[i as usize]);
            assert!((b - a).cross(c - a).z > 0.0, "zero-area triangle emitted");
        }
    }

    #[test]
    fn defects_are_named() {
        let line = [(0.0, 0.0), (1.0, 1.0), (2.0, 2.0), (3.0, 3.0)];
        assert_eq!(triangulate(&flat(&line)), Err(PolygonDefect::ZeroArea));
        let point = [(1.0, 1.0); 4];
        assert_eq!(triangulate(&flat(&point)), Err(PolygonDefect::ZeroArea));
        let bow_tie = [(0.0, 0.0), (1.0, 1.0), (1.0, 0.0), (0.0, 1.0)];
        assert_eq!(triangulate(&flat(&bow_tie)), Err(PolygonDefect::NotSimple));
        // A pentagram drawn with five vertices crosses itself.
        let pentagram: Vec<_> = (0..5)
            .map(|k| {
                let a = 4.0 * std::f64::consts::PI * k as f64 / 5.0;
                (a.cos(), a.sin())
            })
            .collect();
        assert_eq!(
            triangulate(&flat(&pentagram)),
            Err(PolygonDefect::NotSimple)
        );
        let mut nan = flat(&[(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)]);
        nan[1].x = f64::NAN;
        assert_eq!(triangulate(&nan), Err(PolygonDefect::ZeroArea));
    }

    #[test]
    fn any_plane_and_far_from_the_origin() {
        let s = star(7, 2.0, 0.5);
        let (u, v) = orthonormal_basis(DVec3::new(0.3, -0.5, 0.8).normalize());
        let origin = DVec3::new(1e6, -3e5, 7e5);
        let vertices: Vec<DVec3> = s.iter().map(|&(x, y)| origin + x * u + y * v).collect();
        let triangles = triangulate(&vertices).unwrap();
        let area = area_of(&vertices, &triangles).length();
        assert!((area - shoelace(&s)).abs() < 1e-6 * shoelace(&s), "{area}");
    }

    #[test]
    fn keyhole_that_touches_itself_is_filled() {
        // A square with a square hole, joined by a bridge of two coincident edges.
        let polygon = [
            (0.0, 0.0),
            (4.0, 0.0),
            (4.0, 4.0),
            (0.0, 4.0),
            (0.0, 2.0),
            (1.0, 2.0),
            (1.0, 3.0),
            (3.0, 3.0),
            (3.0, 1.0),
            (1.0, 1.0),
            (1.0, 2.0),
            (0.0, 2.0),
        ];
        let vertices = flat(&polygon);
        let triangles = triangulate(&vertices).unwrap();
        assert!((area_of(&vertices, &triangles).z - 12.0).abs() < 1e-12);
    }

    #[test]
    fn large_polygons_use_the_grid() {
        // 4,000 teeth: every other vertex reflex.
        let s = star(2000, 1.0, 0.9);
        let vertices = flat(&s);
        let triangles = triangulate(&vertices).unwrap();
        assert_eq!(triangles.len(), s.len() - 2);
        assert!((area_of(&vertices, &triangles).z - shoelace(&s)).abs() < 1e-9);
        let mut crossing = s.clone();
        crossing.swap(10, 2000);
        assert_eq!(triangulate(&flat(&crossing)), Err(PolygonDefect::NotSimple));
    }

    /// A random simple polygon: a star-shaped one (vertices at random radii
    /// in order of angle around a point inside, so no gap between angles
    /// reaches half a turn), then sheared, which keeps it simple.
    fn random_polygon() -> impl Strategy<Value = Vec<(f64, f64)>> {
        (3usize..60)
            .prop_flat_map(|n| {
                (
                    proptest::collection::vec((0.0f64..1.0, 0.05f64..1.0), n),
                    -2.0f64..2.0,
                )
            })
            .prop_filter("an angular gap of half a turn or more", |(spokes, _)| {
                let mut turns: Vec<f64> = spokes.iter().map(|s| s.0).collect();
                turns.sort_by(f64::total_cmp);
                let wrap = turns[0] + 1.0 - turns[turns.len() - 1];
                turns.windows(2).all(|w| w[1] - w[0] < 0.45) && wrap < 0.45
            })
            .prop_map(|(mut spokes, shear)| {
                spokes.sort_by(|a, b| a.0.total_cmp(&b.0));
                spokes.dedup_by(|a, b| (a.0 - b.0).abs() < 1e-6);
                spokes
                    .iter()
                    .map(|&(t, r)| {
                        let a = t * std::f64::consts::TAU;
                        let (x, y) = (r * a.cos(), r * a.sin());
                        (x + shear * y, y)
                    })
                    .collect()
            })
    }

    proptest! {
        #[test]
        fn random_simple_polygons_are_partitioned(polygon in random_polygon()) {
            let vertices = flat(&polygon);
            let expected = shoelace(&polygon);
            match triangulate(&vertices) {
                Ok(triangles) => {
                    let area = area_of(&vertices, &triangles).z;
                    prop_assert!((area - expected).abs() <= 1e-9 * expected.abs().max(1e-12),
                        "area {} vs {}", area, expected);
                    for t in &triangles {
                        let [a, b, c] = t.map(|i| vertices[i as usize]);
                        prop_assert!((b - a).cross(c - a).z * expected > 0.0);
                        let g = (a + b + c) / 3.0;
                        prop_assert!(inside(&polygon, g.x, g.y), "triangle outside the polygon");
                    }
                }
                // Only outlines that really are degenerate may be refused.
                Err(defect) => prop_assert!(
                    expected.abs() < 1e-9 || polygon.len() < 3,
                    "{:?} for a polygon of area {}", defect, expected
                ),
            }
        }
    }

    /// A polygon 1e150 or 1e-150 across is cut as at unit size: the
    /// tests' products of four coordinates would overflow or underflow
    /// unscaled (found by taking a test hall to those scales).
    #[test]
    fn huge_and_tiny_polygons_are_cut_as_at_unit_size() {
        let square = [(0.0, 0.0), (2.0, 0.0), (2.0, 1.0), (1.0, 0.5), (0.0, 1.0)];
        let at = |scale: f64| {
            let points: Vec<(f64, f64)> = square
                .iter()
                .map(|&(x, y)| (x * scale, y * scale))
                .collect();
            triangulate(&flat(&points))
        };
        let unit = at(1.0).unwrap();
        for scale in [1e150, 1e-150, 1e300, 1e-300, 3e7] {
            assert_eq!(at(scale).unwrap(), unit, "scale {scale}");
        }
    }
}
