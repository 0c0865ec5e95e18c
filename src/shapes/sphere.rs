//! Spheres: the ray test in the numerically stable form of Haines et al.
//! (*Ray Tracing Gems*, ch. 7), hit points re-projected onto the surface,
//! and the exact sphere/box overlap the octree classifies with.

use super::hit::{Crossings, ShapeHit, Surface, unit_or_none};
use crate::math::{Aabb, DVec3, Ray};

#[derive(Clone, Debug, PartialEq)]
pub struct Sphere {
    pub center: DVec3,
    pub radius: f64,
}

impl Sphere {
    pub fn new(center: DVec3, radius: f64) -> Self {
        Self { center, radius }
    }

    /// Both parameters where the ray's line meets the sphere, smaller first,
    /// in the form of Haines et al., "Precision Improvements for Ray/Sphere
    /// Intersection" (Ray Tracing Gems ch. 7): the discriminant is
    /// `r^2 - |f - (f.d) d|^2`, which stays accurate for a small sphere far
    /// away, and the roots use the stable `c / q`, `q` pair.
    #[inline(always)]
    fn roots(&self, ray: &Ray) -> Option<(f64, f64)> {
        let f = ray.origin - self.center;
        let b = f.dot(ray.dir);
        let perp = f - b * ray.dir;
        let r2 = self.radius * self.radius;
        let disc = r2 - perp.length_squared();
        if !(disc >= 0.0) {
            return None;
        }
        let c = f.length_squared() - r2;
        let q = -(b + disc.sqrt().copysign(b));
        let (t0, t1) = if q == 0.0 { (0.0, 0.0) } else { (c / q, q) };
        Some(if t0 <= t1 { (t0, t1) } else { (t1, t0) })
    }

    /// The nearest hit with `0 < t < t_max`.
    #[inline(always)]
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<ShapeHit> {
        let (near, far) = self.roots(ray)?;
        if near > 0.0 && near < t_max {
            Some(ShapeHit::at(near))
        } else if far > 0.0 && far < t_max {
            Some(ShapeHit::at(far))
        } else {
            None
        }
    }

    /// Every crossing of the surface with `0 < t < t_max` (at most two).
    #[inline(always)]
    pub fn crossings(&self, ray: &Ray, t_max: f64) -> Crossings {
        let mut out = Crossings::default();
        if let Some((near, far)) = self.roots(ray) {
            for t in [near, far] {
                // A tangent ray's double root touches the surface once.
                if t > 0.0 && t < t_max && out.as_slice().last() != Some(&t) {
                    out.push(t);
                }
            }
        }
        out
    }

    pub fn surface(&self, ray: &Ray, hit: &ShapeHit) -> Surface {
        let p = ray.at(hit.t);
        let radial = p - self.center;
        // Re-project onto the sphere: the point's error then depends on the
        // sphere's own magnitude, not on how far the ray travelled.
        let normal = unit_or_none(radial).unwrap_or(-ray.dir);
        let point = self.center + normal * self.radius;
        Surface {
            point,
            geometric_normal: normal,
            shading_normal: normal,
        }
    }

    pub fn bounds(&self) -> Aabb {
        let r = DVec3::splat(self.radius);
        Aabb::new(self.center - r, self.center + r)
    }

    /// Whether the sphere's surface (not the ball inside it) touches the
    /// closed box: the box's nearest point lies within the radius and its
    /// farthest corner beyond it. A cell deep inside a large sphere holds
    /// none of its surface and never references it.
    pub fn overlaps_box(&self, b: &Aabb) -> bool {
        let r2 = self.radius * self.radius;
        let nearest = self.center.clamp(b.min, b.max);
        let farthest = (self.center - b.min).abs().max((b.max - self.center).abs());
        nearest.distance_squared(self.center) <= r2 && farthest.length_squared() >= r2
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn ray(o: [f64; 3], d: [f64; 3]) -> Ray {
        Ray::new(DVec3::from(o), DVec3::from(d).normalize())
    }

    #[test]
    fn hit_from_outside_returns_near_root() {
        let s = Sphere::new(DVec3::ZERO, 1.0);
        let h = s
            .intersect(&ray([0.0, 0.0, 5.0], [0.0, 0.0, -1.0]), f64::INFINITY)
            .unwrap();
        assert_eq!(h.t, 4.0);
        let surf = s.surface(&ray([0.0, 0.0, 5.0], [0.0, 0.0, -1.0]), &h);
        assert_eq!(surf.geometric_normal, DVec3::Z);
    }

    #[test]
    fn miss_behind_and_t_max() {
        let s = Sphere::new(DVec3::ZERO, 1.0);
        assert!(
            s.intersect(&ray([0.0, 2.0, 5.0], [0.0, 0.0, -1.0]), f64::INFINITY)
                .is_none()
        );
        assert!(
            s.intersect(&ray([0.0, 0.0, 5.0], [0.0, 0.0, 1.0]), f64::INFINITY)
                .is_none()
        );
        assert!(
            s.intersect(&ray([0.0, 0.0, 5.0], [0.0, 0.0, -1.0]), 3.9)
                .is_none()
        );
    }

    #[test]
    fn crossings_are_both_roots_in_range() {
        let s = Sphere::new(DVec3::ZERO, 1.0);
        let r = ray([0.0, 0.0, 5.0], [0.0, 0.0, -1.0]);
        assert_eq!(s.crossings(&r, f64::INFINITY).as_slice(), &[4.0, 6.0]);
        assert_eq!(s.crossings(&r, 5.0).as_slice(), &[4.0]);
        let inside = ray([0.0, 0.0, 0.5], [0.0, 0.0, -1.0]);
        assert_eq!(s.crossings(&inside, f64::INFINITY).as_slice(), &[1.5]);
        let away = ray([0.0, 0.0, 5.0], [0.0, 0.0, 1.0]);
        assert!(s.crossings(&away, f64::INFINITY).as_slice().is_empty());
    }

    #[test]
    fn origin_inside_returns_far_root() {
        let s = Sphere::new(DVec3::ZERO, 2.0);
        let h = s
            .intersect(&ray([0.5, 0.0, 0.0], [1.0, 0.0, 0.0]), f64::INFINITY)
            .unwrap();
        assert!((h.t - 1.5).abs() < 1e-15);
    }

    #[test]
    fn tangent_and_grazing() {
        let s = Sphere::new(DVec3::ZERO, 1.0);
        let tangent = s.intersect(&ray([1.0, 0.0, 5.0], [0.0, 0.0, -1.0]), f64::INFINITY);
        assert_eq!(tangent.map(|h| h.t), Some(5.0));
        let just_off = s.intersect(
            &ray([1.0 + 1e-12, 0.0, 5.0], [0.0, 0.0, -1.0]),
            f64::INFINITY,
        );
        assert!(just_off.is_none());
    }

    #[test]
    fn tiny_sphere_far_away_is_hit_accurately() {
        let s = Sphere::new(DVec3::new(0.0, 0.0, -1e6), 1e-3);
        let h = s
            .intersect(&ray([0.0, 5e-4, 0.0], [0.0, 0.0, -1.0]), f64::INFINITY)
            .unwrap();
        let expected = 1e6 - (1e-6f64 - 25e-8).sqrt();
        assert!((h.t - expected).abs() < 1e-9, "{} vs {}", h.t, expected);
    }

    #[test]
    fn box_overlap_is_exact() {
        let s = Sphere::new(DVec3::ZERO, 1.0);
        let near_corner = Aabb::new(DVec3::splat(0.5), DVec3::splat(1.0));
        let past_corner = Aabb::new(DVec3::splat(0.6), DVec3::splat(1.0));
        assert!(s.overlaps_box(&near_corner));
        assert!(
            !s.overlaps_box(&past_corner),
            "bounding boxes overlap, the sphere does not"
        );
        let deep_inside = Aabb::new(DVec3::splat(-0.5), DVec3::splat(0.5));
        assert!(!s.overlaps_box(&deep_inside), "no surface inside the box");
        let holds_the_sphere = Aabb::new(DVec3::splat(-2.0), DVec3::splat(2.0));
        assert!(s.overlaps_box(&holds_the_sphere));
        let touching_inside = Aabb::new(DVec3::ZERO, DVec3::new(1.0, 0.1, 0.1));
        assert!(s.overlaps_box(&touching_inside));
    }
}
