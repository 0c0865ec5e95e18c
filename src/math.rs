//! Small geometric vocabulary shared by every module: rays, boxes and the
//! robust helpers that keep secondary rays from re-hitting their own surface.

pub use glam::DVec3;

/// Linear RGB, one `f64` per channel.
pub type Color = DVec3;

/// A ray `origin + t * dir`, `dir` of unit length. Valid hits have `t > 0`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Ray {
    pub origin: DVec3,
    pub dir: DVec3,
}

impl Ray {
    pub fn new(origin: DVec3, dir: DVec3) -> Self {
        Self { origin, dir }
    }

    pub fn at(&self, t: f64) -> DVec3 {
        self.origin + t * self.dir
    }
}

/// Axis-aligned bounding box; `min > max` on some axis means empty.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Aabb {
    pub min: DVec3,
    pub max: DVec3,
}

impl Aabb {
    pub const EMPTY: Aabb = Aabb {
        min: DVec3::splat(f64::INFINITY),
        max: DVec3::splat(f64::NEG_INFINITY),
    };

    pub fn new(min: DVec3, max: DVec3) -> Self {
        Self { min, max }
    }

    pub fn from_points(points: &[DVec3]) -> Self {
        points.iter().fold(Self::EMPTY, |b, &p| b.grow(p))
    }

    pub fn is_empty(&self) -> bool {
        !(self.min.x <= self.max.x && self.min.y <= self.max.y && self.min.z <= self.max.z)
    }

    pub fn grow(self, p: DVec3) -> Self {
        Self::new(self.min.min(p), self.max.max(p))
    }

    pub fn union(self, other: Aabb) -> Self {
        Self::new(self.min.min(other.min), self.max.max(other.max))
    }

    pub fn intersection(self, other: Aabb) -> Self {
        Self::new(self.min.max(other.min), self.max.min(other.max))
    }

    pub fn overlaps(&self, other: &Aabb) -> bool {
        !self.intersection(*other).is_empty()
    }

    pub fn contains(&self, p: DVec3) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }

    pub fn center(&self) -> DVec3 {
        0.5 * (self.min + self.max)
    }

    pub fn extent(&self) -> DVec3 {
        self.max - self.min
    }

    pub fn surface_area(&self) -> f64 {
        if self.is_empty() {
            return 0.0;
        }
        let e = self.extent();
        2.0 * (e.x * e.y + e.y * e.z + e.z * e.x)
    }

    /// Largest absolute coordinate of the box: the magnitude that bounds the
    /// rounding error of anything computed from points inside it.
    pub fn max_abs(&self) -> f64 {
        self.min.abs().max(self.max.abs()).max_element()
    }

    /// The box grown by `rel` times its largest absolute coordinate on every
    /// side, so that closed-box tests made in floating point stay conservative.
    pub fn padded(&self, rel: f64) -> Self {
        let pad = DVec3::splat(rel * self.max_abs().max(f64::MIN_POSITIVE));
        Self::new(self.min - pad, self.max + pad)
    }

    /// Parametric range `[t_enter, t_exit]` of the ray inside the box, clipped
    /// to `[t_min, t_max]`. Direction components that are `0.0` or `-0.0` are
    /// handled explicitly: the ray is then inside the slab everywhere or nowhere.
    pub fn ray_range(&self, ray: &Ray, t_min: f64, t_max: f64) -> Option<(f64, f64)> {
        let mut t0 = t_min;
        let mut t1 = t_max;
        for axis in 0..3 {
            let o = ray.origin[axis];
            let d = ray.dir[axis];
            if d == 0.0 {
                if o < self.min[axis] || o > self.max[axis] {
                    return None;
                }
                continue;
            }
            let inv = 1.0 / d;
            let (mut near, mut far) = ((self.min[axis] - o) * inv, (self.max[axis] - o) * inv);
            if near > far {
                std::mem::swap(&mut near, &mut far);
            }
            t0 = t0.max(near);
            t1 = t1.min(far);
            if t0 > t1 {
                return None;
            }
        }
        Some((t0, t1))
    }
}

/// Relative size of the offset that moves a secondary ray's origin off its
/// surface: about 2^12 ulps of the magnitude involved, comfortably above the
/// error of the hit points glint computes (re-projected onto the surface or
/// interpolated from vertices), and far below any feature of a scene.
const OFFSET_RELATIVE: f64 = 1.0 / (1u64 << 40) as f64;

/// Moves `point` off a surface along the geometric normal `normal` (pointing
/// to the side the new ray leaves into), by an amount that scales with the
/// magnitude of each coordinate and never drops below `floor_scale`
/// (the magnitude of the scene, so points near the origin still move).
///
/// This is the scheme of Wächter & Binder, "A Fast and Robust Method for
/// Avoiding Self-Intersection" (Ray Tracing Gems, ch. 6, 2019): the offset is
/// proportional to the floating-point spacing at the point rather than a
/// fixed epsilon. glint works in `f64`, so the proportion is expressed
/// directly instead of through integer bit manipulation.
pub fn offset_ray_origin(point: DVec3, normal: DVec3, floor_scale: f64) -> DVec3 {
    let magnitude = point.abs().max(DVec3::splat(floor_scale));
    point + normal * magnitude * OFFSET_RELATIVE
}

/// How far short of `point` a ray aimed at it stops: the largest move
/// [`offset_ray_origin`] would make there, so a segment's end is kept off
/// a surface through it as its start is.
pub fn offset_distance(point: DVec3, floor_scale: f64) -> f64 {
    point.abs().max_element().max(floor_scale) * OFFSET_RELATIVE
}

/// Mirror direction of `dir` about the unit normal `n`.
pub fn reflect(dir: DVec3, n: DVec3) -> DVec3 {
    dir - 2.0 * dir.dot(n) * n
}

/// Snell refraction of the unit `dir` through a surface with unit normal `n`
/// facing the incoming ray (`dir . n <= 0`), `eta = n_incident / n_transmitted`.
/// `None` on total internal reflection.
pub fn refract(dir: DVec3, n: DVec3, eta: f64) -> Option<DVec3> {
    let cos_i = (-dir.dot(n)).clamp(0.0, 1.0);
    let sin2_t = eta * eta * (1.0 - cos_i * cos_i).max(0.0);
    if sin2_t > 1.0 {
        return None;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let t = eta * dir + (eta * cos_i - cos_t) * n;
    Some(t.normalize())
}

/// Roots of `a t^2 + 2 h t + c = 0` (half-b form), smaller first, computed as
/// `q = -(h + sign(h) sqrt(h^2 - a c))`, `t = q / a`, `t = c / q` to avoid
/// cancellation (Press et al., Numerical Recipes, 5.6). `a == 0` is the
/// linear case.
pub fn solve_quadratic_half(a: f64, h: f64, c: f64) -> Option<(f64, f64)> {
    if a == 0.0 {
        if h == 0.0 {
            return None;
        }
        let t = -c / (2.0 * h);
        return Some((t, t));
    }
    let disc = h * h - a * c;
    if disc < 0.0 || !disc.is_finite() {
        return None;
    }
    let q = -(h + disc.sqrt().copysign(h));
    if q == 0.0 {
        // h == 0 and a c == 0: a double root at zero.
        return Some((0.0, 0.0));
    }
    let (t0, t1) = (q / a, c / q);
    Some(if t0 <= t1 { (t0, t1) } else { (t1, t0) })
}

/// Orthonormal basis completing the unit vector `n` (Duff et al. 2017,
/// "Building an Orthonormal Basis, Revisited").
pub fn orthonormal_basis(n: DVec3) -> (DVec3, DVec3) {
    let sign = 1.0f64.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        DVec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        DVec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

/// A deterministic stream of numbers in `[0, 1)` for tests (Marsaglia's
/// xorshift, as [`crate::render::random_lines`] draws its lines).
#[cfg(test)]
pub(crate) struct XorShift(pub u64);

#[cfg(test)]
impl XorShift {
    pub(crate) fn unit(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quadratic_roots_are_accurate_when_b_dominates() {
        // x^2 - 1e8 x + 1 = 0: the small root 1e-8 is lost by the textbook formula.
        let (t0, t1) = solve_quadratic_half(1.0, -0.5e8, 1.0).unwrap();
        assert!((t0 - 1e-8).abs() < 1e-20, "t0 = {t0}");
        assert!((t1 - 1e8).abs() < 1e-6, "t1 = {t1}");
    }

    #[test]
    fn quadratic_linear_case_and_no_roots() {
        assert_eq!(solve_quadratic_half(0.0, 1.0, -4.0), Some((2.0, 2.0)));
        assert_eq!(solve_quadratic_half(0.0, 0.0, 1.0), None);
        assert_eq!(solve_quadratic_half(1.0, 0.0, 1.0), None);
    }

    #[test]
    fn snell_law_and_round_trip() {
        let n = DVec3::Z;
        let dir = DVec3::new(0.6, 0.0, -0.8);
        let eta = 1.0 / 1.5;
        let t = refract(dir, n, eta).unwrap();
        assert!((t.length() - 1.0).abs() < 1e-12);
        let sin_i = dir.cross(-n).length();
        let sin_t = t.cross(-n).length();
        assert!((sin_i - 1.5 * sin_t).abs() < 1e-12, "n1 sin i = n2 sin t");
        // Leaving the glass along the reversed ray returns the original direction.
        let back = refract(-t, -n, 1.5).unwrap();
        assert!((back + dir).length() < 1e-12);
    }

    #[test]
    fn total_internal_reflection_beyond_critical_angle() {
        let n = DVec3::Z;
        let critical = (1.0f64 / 1.5).asin();
        let below = DVec3::new((critical - 1e-3).sin(), 0.0, -(critical - 1e-3).cos());
        let above = DVec3::new((critical + 1e-3).sin(), 0.0, -(critical + 1e-3).cos());
        assert!(refract(below, n, 1.5).is_some());
        assert!(refract(above, n, 1.5).is_none());
    }

    #[test]
    fn ior_one_bends_nothing() {
        let dir = DVec3::new(0.3, -0.4, -0.5).normalize();
        let t = refract(dir, DVec3::Z, 1.0).unwrap();
        assert!((t - dir).length() < 1e-15);
    }

    #[test]
    fn reflection_keeps_angle() {
        let r = reflect(DVec3::new(1.0, -1.0, 0.0).normalize(), DVec3::Y);
        assert!((r - DVec3::new(1.0, 1.0, 0.0).normalize()).length() < 1e-15);
    }

    #[test]
    fn ray_range_handles_zero_and_negative_zero_directions() {
        let b = Aabb::new(DVec3::ZERO, DVec3::ONE);
        for dz in [0.0, -0.0] {
            let inside = Ray::new(DVec3::new(-1.0, 0.5, 0.5), DVec3::new(1.0, 0.0, dz));
            assert_eq!(b.ray_range(&inside, 0.0, f64::INFINITY), Some((1.0, 2.0)));
            let on_face = Ray::new(DVec3::new(-1.0, 0.5, 1.0), DVec3::new(1.0, 0.0, dz));
            assert_eq!(b.ray_range(&on_face, 0.0, f64::INFINITY), Some((1.0, 2.0)));
            let outside = Ray::new(DVec3::new(-1.0, 0.5, 1.5), DVec3::new(1.0, 0.0, dz));
            assert_eq!(b.ray_range(&outside, 0.0, f64::INFINITY), None);
        }
    }

    #[test]
    fn offset_moves_points_at_every_scale() {
        for scale in [1e-6, 1.0, 1e6] {
            let p = DVec3::new(scale, 0.0, -scale);
            let q = offset_ray_origin(p, DVec3::Y, scale);
            assert!(q.y > 0.0 && q.y < scale * 1e-9, "scale {scale}: {q}");
            assert_eq!(q.x, p.x);
        }
    }

    #[test]
    fn basis_is_orthonormal() {
        for n in [DVec3::Z, -DVec3::Z, DVec3::new(1.0, 2.0, 3.0).normalize()] {
            let (a, b) = orthonormal_basis(n);
            assert!(a.dot(b).abs() < 1e-12 && a.dot(n).abs() < 1e-12 && b.dot(n).abs() < 1e-12);
            assert!((a.length() - 1.0).abs() < 1e-12 && (b.length() - 1.0).abs() < 1e-12);
        }
    }
}
