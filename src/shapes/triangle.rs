//! Triangles: the watertight ray test of Woop, Benthin & Wald (2013), in
//! `f64`, so rays through shared edges and vertices never slip through a
//! mesh; interpolated vertex normals for smooth meshes; and the exact
//! triangle/box overlap (separating axes) the octree classifies with.

use super::hit::{PreparedRay, ShapeHit, Surface, along_axes, unit_or_none};
use crate::math::{Aabb, DVec3};

/// Marker for "no vertex normals": the triangle is flat shaded.
pub const NO_NORMALS: u32 = u32::MAX;

#[derive(Clone, Debug, PartialEq)]
pub struct Triangle {
    pub vertices: [DVec3; 3],
    /// Index into the scene's per-triangle vertex normals, or `NO_NORMALS` (`u32::MAX`).
    pub vertex_normals: u32,
}

impl Triangle {
    /// `None` for degenerate triangles (zero area, collinear or repeated
    /// vertices, non-finite coordinates): they can never be hit, so glint
    /// drops them at load instead of testing them for every ray.
    pub fn new(vertices: [DVec3; 3]) -> Option<Self> {
        let [a, b, c] = vertices;
        if !(a.is_finite() && b.is_finite() && c.is_finite()) {
            return None;
        }
        let (e1, e2) = (b - a, c - a);
        let len = e1.cross(e2).length();
        // Relative to the edges: the sine of the angle at vertex 0.
        if !(len > 1e-12 * e1.length() * e2.length()) {
            return None;
        }
        Some(Self {
            vertices,
            vertex_normals: NO_NORMALS,
        })
    }

    /// Unit geometric normal; the counter-clockwise winding faces it.
    /// Computed when needed (once per shaded hit) to keep the triangle small.
    pub fn normal(&self) -> DVec3 {
        let [a, b, c] = self.vertices;
        (b - a).cross(c - a).normalize()
    }

    /// Watertight ray/triangle intersection: Woop, Benthin & Wald,
    /// "Watertight Ray/Triangle Intersection", JCGT 2(1), 2013. Rays through
    /// a shared edge or vertex hit at least one of the triangles that share it.
    #[inline(always)]
    pub fn intersect(&self, r: &PreparedRay, t_max: f64) -> Option<ShapeHit> {
        // The axes are a run-time choice per ray: dispatching once to code
        // with constant axes avoids indexing vectors by a variable.
        along_axes!(r.permutation, |KX, KY, KZ| self
            .intersect_along::<KX, KY, KZ>(r, t_max))
    }

    /// [`Triangle::intersect`] for a ray whose permutation is `(KX, KY, KZ)`.
    #[inline(always)]
    fn intersect_along<const KX: usize, const KY: usize, const KZ: usize>(
        &self,
        r: &PreparedRay,
        t_max: f64,
    ) -> Option<ShapeHit> {
        let o = r.ray.origin;
        let s = r.shear;
        let a = (self.vertices[0] - o).to_array();
        let b = (self.vertices[1] - o).to_array();
        let c = (self.vertices[2] - o).to_array();
        let (ax, ay) = (a[KX] - s.x * a[KZ], a[KY] - s.y * a[KZ]);
        let (bx, by) = (b[KX] - s.x * b[KZ], b[KY] - s.y * b[KZ]);
        let (cx, cy) = (c[KX] - s.x * c[KZ], c[KY] - s.y * c[KZ]);
        let u = cx * by - cy * bx;
        let v = ax * cy - ay * cx;
        let w = bx * ay - by * ax;
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 {
            return None;
        }
        let t_scaled = s.z * (u * a[KZ] + v * b[KZ] + w * c[KZ]);
        let t = t_scaled / det;
        if !(t > 0.0 && t < t_max) {
            return None;
        }
        Some(ShapeHit {
            t,
            b1: v / det,
            b2: w / det,
        })
    }

    #[inline(always)]
    pub fn surface(&self, hit: &ShapeHit, vertex_normals: &[[DVec3; 3]]) -> Surface {
        let b0 = 1.0 - hit.b1 - hit.b2;
        let [v0, v1, v2] = self.vertices;
        // Interpolating the vertices gives a point whose error is bounded by
        // the vertices' magnitude (Wächter & Binder, RTG ch. 6).
        let point = b0 * v0 + hit.b1 * v1 + hit.b2 * v2;
        let normal = self.normal();
        let shading_normal = vertex_normals
            .get(self.vertex_normals as usize)
            .and_then(|[n0, n1, n2]| unit_or_none(b0 * *n0 + hit.b1 * *n1 + hit.b2 * *n2))
            .unwrap_or(normal);
        Surface {
            point,
            geometric_normal: normal,
            shading_normal,
        }
    }

    pub fn bounds(&self) -> Aabb {
        Aabb::from_points(&self.vertices)
    }

    /// The point at barycentric coordinates `(b1, b2)`.
    #[inline]
    pub fn point_at(&self, b1: f64, b2: f64) -> DVec3 {
        let [v0, v1, v2] = self.vertices;
        (1.0 - b1 - b2) * v0 + b1 * v1 + b2 * v2
    }

    /// The barycentric coordinates `(b1, b2)` of `point` (on the triangle's
    /// plane or projected onto it); `(0, 0)` where they are not numbers.
    #[inline]
    pub fn barycentric(&self, point: DVec3) -> (f64, f64) {
        let [v0, v1, v2] = self.vertices;
        let (e1, e2, d) = (v1 - v0, v2 - v0, point - v0);
        let (d11, d12, d22) = (e1.dot(e1), e1.dot(e2), e2.dot(e2));
        let (d1, d2) = (d.dot(e1), d.dot(e2));
        let det = d11 * d22 - d12 * d12;
        let b1 = (d22 * d1 - d12 * d2) / det;
        let b2 = (d11 * d2 - d12 * d1) / det;
        if b1.is_finite() && b2.is_finite() {
            (b1, b2)
        } else {
            (0.0, 0.0)
        }
    }

    /// Whether the triangle is shaded with vertex normals.
    pub fn has_vertex_normals(&self) -> bool {
        self.vertex_normals != NO_NORMALS
    }

    /// The point of the smooth surface that the vertex normals describe,
    /// above the hit `point` on the flat triangle, on the side `side`; the
    /// hit itself on a flat-shaded triangle. Shadow rays from there do not
    /// see the facet's own plane cut across a smooth terminator (Hanika,
    /// "Hacking the shadow terminator", Ray Tracing Gems II, 2021: each
    /// vertex's tangent plane lifts the point by how far it lies below it,
    /// and the lifts are blended by the barycentric coordinates).
    #[inline(always)]
    pub fn smooth_point(
        &self,
        hit: &ShapeHit,
        point: DVec3,
        side: DVec3,
        vertex_normals: &[[DVec3; 3]],
    ) -> DVec3 {
        let Some(normals) = vertex_normals.get(self.vertex_normals as usize) else {
            return point;
        };
        let weights = [1.0 - hit.b1 - hit.b2, hit.b1, hit.b2];
        let mut lift = DVec3::ZERO;
        for k in 0..3 {
            // The scene stores vertex normals as unit vectors.
            let n = normals[k];
            let n = if n.dot(side) < 0.0 { -n } else { n };
            let below = (self.vertices[k] - point).dot(n);
            if below > 0.0 {
                lift += weights[k] * below * n;
            }
        }
        let lifted = point + lift;
        if lifted.is_finite() { lifted } else { point }
    }
}

/// Exact triangle/box overlap by the separating axis theorem
/// (Akenine-Möller, "Fast 3D Triangle-Box Overlap Testing", JGT 2001):
/// the 3 box normals, the triangle normal and the 9 edge cross products.
/// Touching counts as overlapping.
///
/// The octree's build spends most of its time here, on triangles whose
/// bounding box already overlaps the box, so the cheap answers come first:
/// the box normals by comparing the vertices' extent with the box, then a
/// vertex inside the box (overlap, no axis to try), then the triangle's
/// normal, then the edge axes with their zero components left out (an
/// axis `X × e` has no x component, and the edge's own two vertices
/// project alike on it, so two projections decide).
pub fn triangle_overlaps_box(vertices: &[DVec3; 3], b: &Aabb) -> bool {
    let [p0, p1, p2] = *vertices;
    let (lo, hi) = (p0.min(p1).min(p2), p0.max(p1).max(p2));
    if lo.cmpgt(b.max).any() || hi.cmplt(b.min).any() {
        return false;
    }
    if vertices.iter().any(|&p| b.contains(p)) {
        return true;
    }
    let center = b.center();
    let half = 0.5 * b.extent();
    let v = [p0 - center, p1 - center, p2 - center];
    let edges = [v[1] - v[0], v[2] - v[1], v[0] - v[2]];
    let n = edges[0].cross(edges[1]);
    if n != DVec3::ZERO {
        let d = [v[0].dot(n), v[1].dot(n), v[2].dot(n)];
        let r = half.dot(n.abs());
        if d[0].min(d[1]).min(d[2]) > r || d[0].max(d[1]).max(d[2]) < -r {
            return false;
        }
    }
    // Edge k joins v[k] and v[k+1]; v[k+2] is the vertex off it.
    for (k, e) in edges.into_iter().enumerate() {
        let (on, off) = (v[k], v[(k + 2) % 3]);
        let a = e.abs();
        // X × e = (0, -e.z, e.y), Y × e = (e.z, 0, -e.x), Z × e = (-e.y, e.x, 0).
        let axes = [
            (
                on.z * e.y - on.y * e.z,
                off.z * e.y - off.y * e.z,
                half.y * a.z + half.z * a.y,
                a.y + a.z,
            ),
            (
                on.x * e.z - on.z * e.x,
                off.x * e.z - off.z * e.x,
                half.x * a.z + half.z * a.x,
                a.x + a.z,
            ),
            (
                on.y * e.x - on.x * e.y,
                off.y * e.x - off.x * e.y,
                half.x * a.y + half.y * a.x,
                a.x + a.y,
            ),
        ];
        for (p, q, r, length) in axes {
            // A zero axis (an edge along a box normal) separates nothing.
            if length > 0.0 && (p.min(q) > r || p.max(q) < -r) {
                return false;
            }
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Ray;

    fn tri() -> Triangle {
        Triangle::new([DVec3::ZERO, DVec3::X, DVec3::Y]).unwrap()
    }

    fn prepared(o: [f64; 3], d: [f64; 3]) -> PreparedRay {
        PreparedRay::new(Ray::new(DVec3::from(o), DVec3::from(d).normalize()))
    }

    #[test]
    fn hit_reports_barycentrics_and_point() {
        let t = tri();
        let h = t
            .intersect(&prepared([0.25, 0.5, 2.0], [0.0, 0.0, -1.0]), f64::INFINITY)
            .unwrap();
        assert!((h.t - 2.0).abs() < 1e-15);
        let s = t.surface(&h, &[]);
        assert!((s.point - DVec3::new(0.25, 0.5, 0.0)).length() < 1e-15);
        assert_eq!(s.geometric_normal, DVec3::Z);
    }

    #[test]
    fn both_sides_hit_and_misses_miss() {
        let t = tri();
        assert!(
            t.intersect(&prepared([0.2, 0.2, -1.0], [0.0, 0.0, 1.0]), f64::INFINITY)
                .is_some()
        );
        assert!(
            t.intersect(&prepared([0.6, 0.6, 1.0], [0.0, 0.0, -1.0]), f64::INFINITY)
                .is_none()
        );
        assert!(
            t.intersect(&prepared([0.2, 0.2, 1.0], [0.0, 0.0, 1.0]), f64::INFINITY)
                .is_none()
        );
        // In the triangle's plane: no hit, no NaN.
        assert!(
            t.intersect(&prepared([-1.0, 0.2, 0.0], [1.0, 0.0, 0.0]), f64::INFINITY)
                .is_none()
        );
    }

    #[test]
    fn shared_edge_is_watertight() {
        // Two triangles sharing the diagonal of the unit square.
        let a = Triangle::new([DVec3::ZERO, DVec3::X, DVec3::ONE.with_z(0.0)]).unwrap();
        let b = Triangle::new([DVec3::ZERO, DVec3::ONE.with_z(0.0), DVec3::Y]).unwrap();
        for k in 0..=100 {
            let s = k as f64 / 100.0;
            for d in [[0.0, 0.0, -1.0], [0.3, -0.2, -1.0], [-0.5, 0.7, -1.0]] {
                let dir = DVec3::from(d).normalize();
                let target = DVec3::new(s, s, 0.0);
                let o = target - 3.0 * dir;
                let r = PreparedRay::new(Ray::new(o, dir));
                let hits = a.intersect(&r, f64::INFINITY).is_some() as u32
                    + b.intersect(&r, f64::INFINITY).is_some() as u32;
                let on_border = k == 0 || k == 100;
                assert!(
                    hits >= 1 || on_border,
                    "ray through the shared edge at {s} leaked"
                );
            }
        }
    }

    #[test]
    fn degenerate_triangles_are_rejected() {
        assert!(Triangle::new([DVec3::ZERO, DVec3::X, 2.0 * DVec3::X]).is_none());
        assert!(Triangle::new([DVec3::ZERO, DVec3::ZERO, DVec3::Y]).is_none());
        assert!(Triangle::new([DVec3::ZERO, DVec3::X, DVec3::NAN]).is_none());
        assert!(Triangle::new([DVec3::ZERO, DVec3::X * 1e-4, DVec3::Y * 1e-4]).is_some());
        assert!(Triangle::new([DVec3::ZERO, DVec3::X * 1e4, DVec3::Y * 1e4]).is_some());
    }

    /// The separating axis test written plainly: every axis, every
    /// vertex projected, no shortcut.
    fn plain_overlap(vertices: &[DVec3; 3], b: &Aabb) -> bool {
        let (center, half) = (b.center(), 0.5 * b.extent());
        let v = vertices.map(|p| p - center);
        let edges = [v[1] - v[0], v[2] - v[1], v[0] - v[2]];
        let mut axes = vec![DVec3::X, DVec3::Y, DVec3::Z, edges[0].cross(edges[1])];
        for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
            axes.extend(edges.iter().map(|&e| axis.cross(e)));
        }
        !axes.into_iter().filter(|&a| a != DVec3::ZERO).any(|a| {
            let p = v.map(|q| q.dot(a));
            let r = half.dot(a.abs());
            p[0].min(p[1]).min(p[2]) > r || p[0].max(p[1]).max(p[2]) < -r
        })
    }

    /// On a grid of quarters every product and sum is exact, so the
    /// shortcuts (vertex inside, two projections per edge axis) must give
    /// the plain test's answer, touching cases included.
    #[test]
    fn box_overlap_agrees_with_the_plain_separating_axis_test() {
        let mut state = 0x2545_f491_4f6c_dd1d_u64;
        let mut quarter = move |range: u64| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % range) as f64 * 0.25
        };
        let (mut overlapping, mut separated) = (0, 0);
        for _ in 0..200_000 {
            let mut corner = || DVec3::new(quarter(24), quarter(24), quarter(24));
            let (a, c) = (corner(), corner());
            let b = Aabb::new(a.min(c), a.max(c) + DVec3::splat(0.25));
            let v = [corner(), corner(), corner()];
            let expected = plain_overlap(&v, &b);
            assert_eq!(
                triangle_overlaps_box(&v, &b),
                expected,
                "{v:?} against {b:?}"
            );
            if expected {
                overlapping += 1
            } else {
                separated += 1
            }
        }
        assert!(
            overlapping > 10_000 && separated > 10_000,
            "{overlapping} {separated}"
        );
    }

    #[test]
    fn box_overlap_is_exact() {
        let unit = Aabb::new(DVec3::ZERO, DVec3::ONE);
        // Crosses the box's corner region diagonally without touching it.
        let outside = [
            DVec3::new(2.5, 0.0, 0.5),
            DVec3::new(0.0, 2.5, 0.5),
            DVec3::new(3.0, 3.0, 0.5),
        ];
        assert!(Aabb::from_points(&outside).overlaps(&unit));
        assert!(!triangle_overlaps_box(&outside, &unit));
        let crossing = [
            DVec3::new(0.5, 0.5, -1.0),
            DVec3::new(0.5, 0.5, 2.0),
            DVec3::new(3.0, 3.0, 0.5),
        ];
        assert!(triangle_overlaps_box(&crossing, &unit));
        let touching_face = [
            DVec3::new(1.0, 0.2, 0.2),
            DVec3::new(2.0, 0.2, 0.2),
            DVec3::new(1.0, 0.8, 0.8),
        ];
        assert!(triangle_overlaps_box(&touching_face, &unit));
    }
}
