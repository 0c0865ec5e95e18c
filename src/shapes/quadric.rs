//! General quadric surfaces, optionally clipped to a box: ellipsoids,
//! cylinders, cones, hyperboloids and paraboloids from one implicit
//! equation, evaluated in local coordinates and refined by a Newton step.

use super::hit::{Crossings, ShapeHit, Surface, unit_or_none};
use crate::math::{Aabb, DVec3, Ray, solve_quadratic_half};

/// General quadric surface
/// `F(x,y,z) = A x^2 + B xy + C xz + D x + E y^2 + F yz + G y + H z^2 + I z + J = 0`,
/// optionally clipped to an axis-aligned box.
///
/// The coefficients carry no implicit factors of 2: the cross terms `B xy`,
/// `C xz`, `F yz` and the linear terms `D x`, `G y`, `I z` appear exactly as
/// written. Substituting the ray `o + t d` gives `Aq t^2 + Bq t + Cq = 0`
/// with `Aq = Q(d)`, `Bq = grad F(o) . d` and `Cq = F(o)`, where `Q` is the
/// quadratic part; the normal is `grad F`.
///
/// Precision far from the origin: evaluating `F` at a point 1e6 from the
/// origin sums terms of 1e12 whose rounding (about 1e-4) swamps the value
/// near the surface, so a shadow ray could not tell which side it starts
/// on. glint therefore re-centres each quadric at load on a local origin
/// (its clip box's centre, or the centre of a central quadric) and
/// evaluates `F` in local coordinates, where the terms are of the size of
/// the object. The re-centred constant carries the rounding of the world
/// coefficients once, as a shift of the surface far below a pixel.
#[derive(Clone, Debug, PartialEq)]
pub struct Quadric {
    /// `[A, B, C, D, E, F, G, H, I, J]` in world coordinates, as given.
    pub coefficients: [f64; 10],
    pub clip: Option<Aabb>,
    /// The local origin and the coefficients about it: `F(p) = G(p - origin)`.
    origin: DVec3,
    local: [f64; 10],
}

impl Quadric {
    pub fn new(coefficients: [f64; 10], clip: Option<Aabb>) -> Self {
        let origin = clip
            .map(|c| c.center())
            .or_else(|| central_point(&coefficients))
            .unwrap_or(DVec3::ZERO);
        let [a, b, c, _, e, f, _, h, _, _] = coefficients;
        let world = Self {
            coefficients,
            clip,
            origin: DVec3::ZERO,
            local: coefficients,
        };
        // The quadratic part is unchanged; the linear part is grad F(origin),
        // the constant F(origin).
        let g = world.gradient(origin);
        let local = [a, b, c, g.x, e, f, g.y, h, g.z, world.value(origin)];
        if local.iter().all(|x| x.is_finite()) {
            Self {
                coefficients,
                clip,
                origin,
                local,
            }
        } else {
            world
        }
    }

    /// `F(p)`.
    pub fn value(&self, p: DVec3) -> f64 {
        let [a, b, c, d, e, f, g, h, i, j] = self.local;
        let q = p - self.origin;
        let (x, y, z) = (q.x, q.y, q.z);
        x * (a * x + b * y + c * z + d) + y * (e * y + f * z + g) + z * (h * z + i) + j
    }

    /// `grad F(p)`.
    pub fn gradient(&self, p: DVec3) -> DVec3 {
        let [a, b, c, d, e, f, g, h, i, _] = self.local;
        let q = p - self.origin;
        let (x, y, z) = (q.x, q.y, q.z);
        DVec3::new(
            2.0 * a * x + b * y + c * z + d,
            b * x + 2.0 * e * y + f * z + g,
            c * x + f * y + 2.0 * h * z + i,
        )
    }

    /// The quadratic part `Q(d)`.
    fn quadratic_form(&self, d: DVec3) -> f64 {
        let [a, b, c, _, e, f, _, h, _, _] = self.local;
        d.x * (a * d.x + b * d.y + c * d.z) + d.y * (e * d.y + f * d.z) + h * d.z * d.z
    }

    /// The parameters where the ray's line meets the surface, smaller first,
    /// and the parameter range inside the clip box (`None` if the ray misses
    /// the box before `t_max`).
    #[inline(always)]
    fn roots(&self, ray: &Ray, t_max: f64) -> Option<((f64, f64), (f64, f64))> {
        let mut range = (0.0, t_max);
        if let Some(clip) = &self.clip {
            range = clip.ray_range(ray, 0.0, t_max)?;
        }
        let aq = self.quadratic_form(ray.dir);
        let half_bq = 0.5 * self.gradient(ray.origin).dot(ray.dir);
        let cq = self.value(ray.origin);
        // `Aq == 0` (a line parallel to a paraboloid's axis, a plane) is the
        // linear case, handled inside the solver; tiny `Aq` is handled by the
        // stable `c / q` root.
        Some((solve_quadratic_half(aq, half_bq, cq)?, range))
    }

    fn accepts(&self, ray: &Ray, t: f64, t_max: f64, (t_lo, t_hi): (f64, f64)) -> bool {
        t > 0.0 && t < t_max && t >= t_lo && t <= t_hi && self.inside_clip(ray.at(t))
    }

    #[inline(always)]
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<ShapeHit> {
        let ((t0, t1), range) = self.roots(ray, t_max)?;
        [t0, t1]
            .into_iter()
            .find(|&t| self.accepts(ray, t, t_max, range))
            .map(ShapeHit::at)
    }

    /// Every crossing of the surface with `0 < t < t_max` (at most two).
    #[inline(always)]
    pub fn crossings(&self, ray: &Ray, t_max: f64) -> Crossings {
        let mut out = Crossings::default();
        if let Some(((t0, t1), range)) = self.roots(ray, t_max) {
            for t in [t0, t1] {
                // A double root (tangent ray, the linear case) counts once.
                if self.accepts(ray, t, t_max, range) && out.as_slice().last() != Some(&t) {
                    out.push(t);
                }
            }
        }
        out
    }

    fn inside_clip(&self, p: DVec3) -> bool {
        self.clip.is_none_or(|c| c.contains(p))
    }

    pub fn surface(&self, ray: &Ray, hit: &ShapeHit) -> Surface {
        let mut point = ray.at(hit.t);
        // One Newton step along the ray moves the point onto the surface to
        // within rounding, so secondary rays start from an accurate point.
        let slope = self.gradient(point).dot(ray.dir);
        if slope != 0.0 {
            let refined = point - (self.value(point) / slope) * ray.dir;
            if refined.is_finite() && self.value(refined).abs() <= self.value(point).abs() {
                point = refined;
            }
        }
        // The gradient vanishes at a cone's apex: any normal is as good as
        // another there, so face the ray.
        let normal = unit_or_none(self.gradient(point)).unwrap_or(-ray.dir);
        Surface {
            point,
            geometric_normal: normal,
            shading_normal: normal,
        }
    }
}

/// The centre of a central quadric (where its gradient vanishes, solving
/// `2 Q x = -l`), if `Q` is well conditioned; `None` for paraboloids,
/// cylinders and other quadrics without a unique centre.
fn central_point(k: &[f64; 10]) -> Option<DVec3> {
    let [a, b, c, d, e, f, g, h, i, _] = *k;
    let q = glam::DMat3::from_cols(
        DVec3::new(2.0 * a, b, c),
        DVec3::new(b, 2.0 * e, f),
        DVec3::new(c, f, 2.0 * h),
    );
    let det = q.determinant();
    let scale = q.to_cols_array().iter().fold(0.0f64, |m, x| m.max(x.abs()));
    if !(det.abs() > 1e-9 * scale * scale * scale) {
        return None;
    }
    let centre = q.inverse() * -DVec3::new(d, g, i);
    centre.is_finite().then_some(centre)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::shapes::Sphere;

    fn sphere_quadric(c: DVec3, r: f64) -> Quadric {
        // (x-cx)^2 + (y-cy)^2 + (z-cz)^2 - r^2
        Quadric::new(
            [
                1.0,
                0.0,
                0.0,
                -2.0 * c.x,
                1.0,
                0.0,
                -2.0 * c.y,
                1.0,
                -2.0 * c.z,
                c.length_squared() - r * r,
            ],
            None,
        )
    }

    #[test]
    fn sphere_form_matches_analytic_sphere() {
        let c = DVec3::new(0.3, -0.2, 0.1);
        let q = sphere_quadric(c, 0.7);
        let s = Sphere::new(c, 0.7);
        for k in 0..200 {
            let a = k as f64 * 0.1;
            let dir = DVec3::new(a.cos() * 0.3, a.sin() * 0.3, -1.0).normalize();
            let ray = Ray::new(DVec3::new(0.0, 0.0, 3.0), dir);
            let (hq, hs) = (
                q.intersect(&ray, f64::INFINITY),
                s.intersect(&ray, f64::INFINITY),
            );
            assert_eq!(hq.is_some(), hs.is_some(), "ray {k}");
            if let (Some(hq), Some(hs)) = (hq, hs) {
                assert!((hq.t - hs.t).abs() < 1e-12, "ray {k}: {} vs {}", hq.t, hs.t);
                let nq = q.surface(&ray, &hq).geometric_normal;
                let ns = s.surface(&ray, &hs).geometric_normal;
                assert!((nq - ns).length() < 1e-12);
            }
        }
    }

    #[test]
    fn scaling_coefficients_changes_nothing_but_normal_length() {
        let q = sphere_quadric(DVec3::ZERO, 1.0);
        let ray = Ray::new(DVec3::new(0.2, 0.1, 4.0), -DVec3::Z);
        let base = q.intersect(&ray, f64::INFINITY).unwrap();
        for scale in [1e-8, -3.0, 1e8] {
            let scaled = Quadric::new(q.coefficients.map(|c| c * scale), None);
            let h = scaled.intersect(&ray, f64::INFINITY).unwrap();
            assert!((h.t - base.t).abs() < 1e-14, "scale {scale}");
            // Negating F flips the gradient: the outside is where F > 0.
            let n = scaled.surface(&ray, &h).geometric_normal;
            assert!((n.z.abs() - q.surface(&ray, &base).geometric_normal.z).abs() < 1e-12);
        }
    }

    #[test]
    fn far_from_the_origin_the_side_of_a_point_is_still_known() {
        // A unit sphere 1e6 from the origin: 1e-7 off its surface, F must
        // have the right sign (world-space evaluation would be noise).
        let c = DVec3::new(1e6, -1e6, 1e6);
        let q = sphere_quadric(c, 1.0);
        let outside = c + DVec3::X * (1.0 + 1e-7);
        let inside = c + DVec3::X * (1.0 - 1e-7);
        assert!(q.value(outside) > 0.0 && q.value(inside) < 0.0);
        assert_eq!(
            central_point(&q.coefficients).map(|p| (p - c).length() < 1e-6),
            Some(true)
        );
    }

    #[test]
    fn linear_case_paraboloid_along_axis() {
        // z = x^2 + y^2, i.e. x^2 + y^2 - z = 0; a ray along -z has Aq = 0.
        let q = Quadric::new([1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, -1.0, 0.0], None);
        let ray = Ray::new(DVec3::new(0.5, 0.5, 10.0), -DVec3::Z);
        let h = q.intersect(&ray, f64::INFINITY).unwrap();
        assert!((h.t - 9.5).abs() < 1e-12);
    }

    #[test]
    fn clipped_cylinder_and_miss_outside_clip() {
        // x^2 + y^2 - 1 = 0, clipped to |z| <= 1.
        let clip = Aabb::new(DVec3::new(-1.0, -1.0, -1.0), DVec3::new(1.0, 1.0, 1.0));
        let q = Quadric::new(
            [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 0.0, -1.0],
            Some(clip),
        );
        let hit = Ray::new(DVec3::new(-5.0, 0.0, 0.5), DVec3::X);
        assert_eq!(q.intersect(&hit, f64::INFINITY).map(|h| h.t), Some(4.0));
        let above = Ray::new(DVec3::new(-5.0, 0.0, 1.5), DVec3::X);
        assert!(q.intersect(&above, f64::INFINITY).is_none());
        // Seen from inside the open tube, the far wall is hit.
        let inside = Ray::new(DVec3::new(0.0, 0.0, 0.5), DVec3::X);
        assert_eq!(q.intersect(&inside, f64::INFINITY).map(|h| h.t), Some(1.0));
    }

    #[test]
    fn cone_apex_gives_finite_normal() {
        // x^2 + y^2 - z^2 = 0: the apex is at the origin.
        let q = Quadric::new([1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, -1.0, 0.0, 0.0], None);
        let ray = Ray::new(DVec3::new(0.0, -2.0, 0.0), DVec3::Y);
        let h = q.intersect(&ray, f64::INFINITY).unwrap();
        assert!((h.t - 2.0).abs() < 1e-6, "{}", h.t);
        let s = q.surface(&ray, &h);
        assert!(s.geometric_normal.is_finite());
        assert!((s.geometric_normal.length() - 1.0).abs() < 1e-12);
    }
}
