//! Infinite planes: the one unbounded shape besides unclipped quadrics,
//! tested for every ray outside the octree.

use super::hit::{ShapeHit, Surface};
use crate::math::{DVec3, Ray};

/// Infinite plane through `point` with unit `normal`.
#[derive(Clone, Debug, PartialEq)]
pub struct Plane {
    pub point: DVec3,
    pub normal: DVec3,
}

impl Plane {
    /// `normal` need not be unit length; it must be non-zero.
    pub fn new(point: DVec3, normal: DVec3) -> Self {
        Self {
            point,
            normal: normal.normalize(),
        }
    }

    #[inline(always)]
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<ShapeHit> {
        let denom = ray.dir.dot(self.normal);
        if denom == 0.0 {
            return None;
        }
        let t = (self.point - ray.origin).dot(self.normal) / denom;
        (t > 0.0 && t < t_max).then_some(ShapeHit::at(t))
    }

    pub fn surface(&self, ray: &Ray, hit: &ShapeHit) -> Surface {
        let p = ray.at(hit.t);
        // Project onto the plane to remove the error of travelling along the ray.
        let point = p - (p - self.point).dot(self.normal) * self.normal;
        Surface {
            point,
            geometric_normal: self.normal,
            shading_normal: self.normal,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hit_miss_parallel_and_behind() {
        let p = Plane::new(DVec3::ZERO, DVec3::new(0.0, 2.0, 0.0));
        let down = Ray::new(DVec3::new(1.0, 3.0, 0.0), -DVec3::Y);
        assert_eq!(p.intersect(&down, f64::INFINITY).map(|h| h.t), Some(3.0));
        let up = Ray::new(DVec3::new(1.0, 3.0, 0.0), DVec3::Y);
        assert!(p.intersect(&up, f64::INFINITY).is_none());
        let parallel = Ray::new(DVec3::new(1.0, 3.0, 0.0), DVec3::X);
        assert!(p.intersect(&parallel, f64::INFINITY).is_none());
        let in_plane = Ray::new(DVec3::ZERO, DVec3::X);
        assert!(p.intersect(&in_plane, f64::INFINITY).is_none());
        let s = p.surface(&down, &ShapeHit::at(3.0));
        assert_eq!(s.point, DVec3::new(1.0, 0.0, 0.0));
    }

    #[test]
    fn grazing_ray_hits_far_away_without_nan() {
        let p = Plane::new(DVec3::ZERO, DVec3::Y);
        let dir = DVec3::new(1.0, -1e-9, 0.0).normalize();
        let h = p
            .intersect(&Ray::new(DVec3::Y, dir), f64::INFINITY)
            .unwrap();
        assert!((h.t - 1e9).abs() < 1.0, "{}", h.t);
    }
}
