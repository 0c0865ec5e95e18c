//! NFF cones and cylinders (`c`): open truncated cones without caps, with
//! the enclosing capsule the octree classifies them by.

use super::hit::{Crossings, ShapeHit, Surface, unit_or_none};
use crate::math::{Aabb, DVec3, Ray, solve_quadratic_half};

/// Relative margin of the early miss test in `Cone::roots_near_segment`.
const MISS_MARGIN: f64 = 1e-9;
/// Relative margin of the line-to-line miss test: ten times
/// `MISS_MARGIN`, enough that whatever it rules out the segment test
/// (whose margin grows with the re-based origin, at most `sqrt 3` times
/// the gap plus the height) would have ruled out too.
const LINE_MARGIN: f64 = 1e-8;

/// Open truncated cone (or cylinder) between two disks, without end caps:
/// NFF's `c` primitive. The radius varies linearly from `base_radius` at
/// `base` to `apex_radius` at `apex`.
#[derive(Clone, Debug, PartialEq)]
pub struct Cone {
    pub base: DVec3,
    pub base_radius: f64,
    pub apex: DVec3,
    pub apex_radius: f64,
    /// Unit axis from base to apex, its length and the radius slope.
    axis: DVec3,
    height: f64,
    slope: f64,
    /// What `line_passes_wide` needs whatever the ray: the widest radius
    /// and height with their margins.
    line_reach: f64,
}

impl Cone {
    /// `None` if base and apex coincide or a value is not finite.
    pub fn new(base: DVec3, base_radius: f64, apex: DVec3, apex_radius: f64) -> Option<Self> {
        let span = apex - base;
        let height = span.length();
        if !(height > 0.0
            && height.is_finite()
            && base_radius.is_finite()
            && apex_radius.is_finite())
        {
            return None;
        }
        let (base_radius, apex_radius) = (base_radius.abs(), apex_radius.abs());
        Some(Self {
            base,
            base_radius,
            apex,
            apex_radius,
            axis: span / height,
            height,
            slope: (apex_radius - base_radius) / height,
            line_reach: base_radius.max(apex_radius) * (1.0 + LINE_MARGIN) + LINE_MARGIN * height,
        })
    }

    /// Points `q` (relative to `base`) satisfy `|q_perp|^2 = (r0 + s z)^2`
    /// with `z = q . axis`; the perpendicular parts are formed explicitly.
    /// The parameters where the ray's line meets the infinite cone, smaller
    /// first, and a test of whether a parameter lies on the finite part.
    ///
    /// The line is first re-based at its point nearest the axis segment
    /// (as Haines et al., Ray Tracing Gems ch. 7, re-base sphere tests):
    /// from an origin far away, `o_perp` and `d_perp` are nearly parallel
    /// and rounding makes the discriminant `h^2 - a c` positive for lines
    /// that pass far from a thin cone, hits the octree (which only looks
    /// near the cone) would never see. The nearest point, not the
    /// segment's middle: a cone can be far longer than the ray is long.
    #[inline(always)]
    fn roots(&self, ray: &Ray) -> Option<((f64, f64), impl Fn(f64) -> bool)> {
        if self.line_passes_wide(ray) {
            return None;
        }
        self.roots_near_segment(ray)
    }

    /// `roots` without the line-to-line miss test, which must never rule
    /// out what this finds.
    #[inline(always)]
    fn roots_near_segment(&self, ray: &Ray) -> Option<((f64, f64), impl Fn(f64) -> bool)> {
        let (shift, along) = self.nearest_to_axis(ray);
        let o = (ray.origin + shift * ray.dir) - self.base;
        // A line that passes the axis segment farther off than the widest
        // radius misses the finite part: most lines the octree sends here
        // do, and this costs a few products instead of the quadratic. The
        // margin is far above what rounding of the re-based values (the
        // ones the quadratic would use) can move a hit.
        // Squared lengths and the 1-norm of `o` (at least its length):
        // no square roots for a test most calls end at.
        let gap = o - along * self.axis;
        let widest = self.base_radius.max(self.apex_radius);
        let reach = widest + MISS_MARGIN * (widest + o.abs().element_sum() + self.height);
        if gap.length_squared() > reach * reach {
            return None;
        }
        let (oz, dz) = (o.dot(self.axis), ray.dir.dot(self.axis));
        let o_perp = o - oz * self.axis;
        let d_perp = ray.dir - dz * self.axis;
        let r_o = self.base_radius + self.slope * oz;
        let a = d_perp.length_squared() - self.slope * self.slope * dz * dz;
        let h = o_perp.dot(d_perp) - self.slope * dz * r_o;
        let c = o_perp.length_squared() - r_o * r_o;
        let (t0, t1) = solve_quadratic_half(a, h, c)?;
        let (height, base_radius, slope) = (self.height, self.base_radius, self.slope);
        // Whether a parameter lies on the finite part, judged from the
        // re-based origin (`t - shift` is off by one rounding of `t`).
        let on_part = move |t: f64| {
            let z = oz + (t - shift) * dz;
            z >= 0.0 && z <= height && base_radius + slope * z >= 0.0
        };
        Some(((t0 + shift, t1 + shift), on_part))
    }

    /// Whether the ray's line passes the axis's whole line farther off than
    /// the widest radius, by a margin that keeps `roots`' own miss test
    /// (on the nearer segment) bound to agree: the distance between the
    /// two lines, `|w . n| / |n|` with `n = dir x axis`, costs no division
    /// where the segment's needs two. Lines within a milliradian of
    /// parallel are left to that test, as `n` loses its relative accuracy.
    #[inline(always)]
    fn line_passes_wide(&self, ray: &Ray) -> bool {
        let w = ray.origin - self.base;
        let n = ray.dir.cross(self.axis);
        let (across, n2) = (w.dot(n), n.length_squared());
        let far = self.line_reach + LINE_MARGIN * w.abs().element_sum();
        across * across > far * far * n2 && n2 > 1e-6 * ray.dir.length_squared()
    }

    /// The parameter of the ray's point nearest the axis segment (closest
    /// points of a line and a segment: the segment's parameter clamped to
    /// it, then the line's nearest to that point; 0 if not finite), and
    /// that segment parameter (NaN where the line's is not finite, so
    /// that no gap computed from it rules a hit out).
    #[inline(always)]
    fn nearest_to_axis(&self, ray: &Ray) -> (f64, f64) {
        let w = ray.origin - self.base;
        let (dd, da) = (ray.dir.length_squared(), ray.dir.dot(self.axis));
        let (dw, aw) = (ray.dir.dot(w), self.axis.dot(w));
        let denominator = dd - da * da;
        // Parallel (or nearly): any point of the axis is as near.
        let s = if denominator > 1e-12 * dd {
            (dd * aw - da * dw) / denominator
        } else {
            aw
        };
        let s = s.clamp(0.0, self.height);
        let t = (da * s - dw) / dd;
        if t.is_finite() {
            (t, s)
        } else {
            (0.0, f64::NAN)
        }
    }

    #[inline(always)]
    pub fn intersect(&self, ray: &Ray, t_max: f64) -> Option<ShapeHit> {
        let ((t0, t1), on_part) = self.roots(ray)?;
        [t0, t1]
            .into_iter()
            .find(|&t| t > 0.0 && t < t_max && on_part(t))
            .map(ShapeHit::at)
    }

    /// Every crossing of the surface with `0 < t < t_max` (at most two).
    #[inline(always)]
    pub fn crossings(&self, ray: &Ray, t_max: f64) -> Crossings {
        let mut out = Crossings::default();
        if let Some(((t0, t1), on_part)) = self.roots(ray) {
            for t in [t0, t1] {
                // A double root (tangent ray) touches the surface once.
                if t > 0.0 && t < t_max && on_part(t) && out.as_slice().last() != Some(&t) {
                    out.push(t);
                }
            }
        }
        out
    }

    /// A vector along the outward normal at a point on the surface (the
    /// gradient of `|q_perp|^2 - r(z)^2`, up to a factor of 2).
    pub fn outward(&self, p: DVec3) -> DVec3 {
        let q = p - self.base;
        let z = q.dot(self.axis);
        let q_perp = q - z * self.axis;
        q_perp - self.slope * (self.base_radius + self.slope * z) * self.axis
    }

    pub fn surface(&self, ray: &Ray, hit: &ShapeHit) -> Surface {
        let p = ray.at(hit.t);
        let q = p - self.base;
        let z = q.dot(self.axis);
        let q_perp = q - z * self.axis;
        let r = self.base_radius + self.slope * z;
        let radial = unit_or_none(q_perp);
        // Re-project onto the surface radially, then take the gradient
        // `q_perp - r s axis` (up to a factor), which vanishes only at an apex.
        let point = radial.map_or(p, |u| self.base + z * self.axis + r.max(0.0) * u);
        let normal = radial
            .and_then(|u| unit_or_none(u - self.slope * self.axis))
            .unwrap_or(-ray.dir);
        Surface {
            point,
            geometric_normal: normal,
            shading_normal: normal,
        }
    }

    /// Whether the surface may touch the closed box `b`: the box must come
    /// within the larger radius of the axis segment (the cone lies inside
    /// that capsule). Conservative, and far tighter than the bounding box
    /// for thin slanted cylinders such as the SPD's rings and tree.
    pub fn overlaps_box(&self, b: &Aabb) -> bool {
        if !self.bounds().overlaps(b) {
            return false;
        }
        let r = self.base_radius.max(self.apex_radius);
        // A relative margin keeps the test conservative under rounding.
        let reach2 = r * r * (1.0 + 1e-9) + 1e-18 * self.height * self.height;
        // The distance from the box to a point of the axis is convex along
        // the segment: a ternary search finds its minimum. It stops early
        // once a point is near enough, or once even the nearest point the
        // interval left could hold is too far: the distance changes at
        // most `height` per unit of the parameter.
        let distance2 = |s: f64| {
            let p = self.base + s * (self.apex - self.base);
            p.distance_squared(p.clamp(b.min, b.max))
        };
        if distance2(0.0) <= reach2 || distance2(1.0) <= reach2 {
            return true;
        }
        let reach = reach2.sqrt();
        let (mut lo, mut hi) = (0.0f64, 1.0f64);
        for _ in 0..64 {
            let (m1, m2) = (lo + (hi - lo) / 3.0, hi - (hi - lo) / 3.0);
            let (d1, d2) = (distance2(m1), distance2(m2));
            if d1.min(d2) <= reach2 {
                return true;
            }
            if d1 <= d2 {
                hi = m2;
            } else {
                lo = m1;
            }
            // Every point of [lo, hi] lies within (hi - lo) height of m1 or m2.
            if d1.min(d2).sqrt() - (hi - lo) * self.height > reach {
                return false;
            }
        }
        distance2(0.5 * (lo + hi)) <= reach2
    }

    pub fn bounds(&self) -> Aabb {
        self.pieces(1).next().unwrap_or(Aabb::EMPTY)
    }

    /// Boxes that together hold the surface: pieces about as long as the
    /// cone is wide (at most eight), for the light buffer, which lists a
    /// shape in every direction one of its boxes is seen in.
    pub fn cover(&self) -> impl Iterator<Item = Aabb> + '_ {
        let width = 2.0 * self.base_radius.max(self.apex_radius);
        let count = (self.height / width).ceil();
        // NaN (a zero radius) and infinity saturate: at most eight.
        self.pieces((count as usize).clamp(1, 8))
    }

    /// Boxes of the surface cut into `count` equal lengths along the
    /// axis (at least one): each piece lies in the convex hull of its two
    /// end circles, so in the union of their boxes. A slanted cylinder's
    /// pieces cover far less than its one box.
    pub fn pieces(&self, count: usize) -> impl Iterator<Item = Aabb> + '_ {
        // A disk of radius r with unit normal a extends r sqrt(1 - a_k^2) along axis k.
        let spread = (DVec3::ONE - self.axis * self.axis).max(DVec3::ZERO);
        let extent = DVec3::new(spread.x.sqrt(), spread.y.sqrt(), spread.z.sqrt());
        let count = count.max(1);
        let circle = move |k: usize| {
            if k == count {
                return (self.apex, self.apex_radius);
            }
            let f = k as f64 / count as f64;
            let r = self.base_radius + f * (self.apex_radius - self.base_radius);
            (self.base + f * (self.apex - self.base), r)
        };
        (0..count).map(move |k| {
            let ((c0, r0), (c1, r1)) = (circle(k), circle(k + 1));
            let (e0, e1) = (extent * r0, extent * r1);
            Aabb::new(c0 - e0, c0 + e0).union(Aabb::new(c1 - e1, c1 + e1))
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cylinder_hit_from_outside_and_inside() {
        let c = Cone::new(DVec3::ZERO, 1.0, DVec3::new(0.0, 0.0, 2.0), 1.0).unwrap();
        let outside = Ray::new(DVec3::new(-5.0, 0.0, 1.0), DVec3::X);
        let h = c.intersect(&outside, f64::INFINITY).unwrap();
        assert!((h.t - 4.0).abs() < 1e-12);
        let s = c.surface(&outside, &h);
        assert!((s.geometric_normal - -DVec3::X).length() < 1e-12);
        let inside = Ray::new(DVec3::new(0.0, 0.0, 1.0), DVec3::Y);
        assert!((c.intersect(&inside, f64::INFINITY).unwrap().t - 1.0).abs() < 1e-12);
        let past_end = Ray::new(DVec3::new(-5.0, 0.0, 2.5), DVec3::X);
        assert!(c.intersect(&past_end, f64::INFINITY).is_none());
    }

    #[test]
    fn cone_radius_varies_and_bounds_contain_rims() {
        let c = Cone::new(DVec3::ZERO, 1.0, DVec3::new(0.0, 0.0, 1.0), 0.0).unwrap();
        // At z = 0.5 the radius is 0.5.
        let r = Ray::new(DVec3::new(-5.0, 0.0, 0.5), DVec3::X);
        assert!((c.intersect(&r, f64::INFINITY).unwrap().t - 4.5).abs() < 1e-12);
        let tilted = Cone::new(DVec3::ZERO, 0.5, DVec3::new(1.0, 2.0, 3.0), 0.2).unwrap();
        let b = tilted.bounds().padded(1e-12);
        for k in 0..64 {
            let a = k as f64 / 64.0 * std::f64::consts::TAU;
            let (e1, e2) = crate::math::orthonormal_basis(tilted.axis);
            let rim = a.cos() * e1 + a.sin() * e2;
            assert!(b.contains(tilted.base + 0.5 * rim) && b.contains(tilted.apex + 0.2 * rim));
        }
        assert!(Cone::new(DVec3::ONE, 1.0, DVec3::ONE, 1.0).is_none());
    }

    /// The line-to-line test only rules out lines the segment's own test
    /// would: for random cones (slanted, pointed, far from the origin, tiny
    /// and huge) and lines passing them at every distance, from near and
    /// far, a line it rules out never has roots near the segment. And it
    /// does rule most far lines out, or it would save nothing.
    #[test]
    fn the_line_test_rules_out_only_what_the_segment_test_does() {
        let mut random = crate::math::XorShift(0x2545_f491_4f6c_dd1d);
        let mut unit = move || random.unit();
        let (mut ruled_out, mut far_lines) = (0, 0);
        for case in 0..20_000 {
            let scale = [1e-4, 1.0, 1e4][case % 3];
            let offset = [0.0, 1e6, -3e3][case % 5 % 3] * scale;
            let mut point = || DVec3::new(unit() - 0.5, unit() - 0.5, unit() - 0.5) * 8.0 * scale;
            let base = point() + DVec3::splat(offset);
            let apex = base + point();
            let dir = match case % 11 {
                // Within a few milliradians of the axis, down to 1e-9.
                0..=3 => {
                    (apex - base).normalize() + 10f64.powi(-(case as i32 % 8) - 2) * point() / scale
                }
                _ => point() + 1e-3 * scale * (apex - base),
            }
            .normalize();
            let r0 = if case % 4 == 0 { 0.0 } else { unit() * scale };
            let r1 = (unit() * scale).max(1e-3 * scale);
            let along = unit() * 1.4 - 0.2;
            let Some(cone) = Cone::new(base, r0, apex, r1) else {
                continue;
            };
            // A line through a point at a chosen distance from the axis
            // segment's line, origin near or far back along it.
            let widest = cone.base_radius.max(cone.apex_radius);
            let (e1, _) = crate::math::orthonormal_basis(cone.axis);
            let gap = widest * [0.5, 0.999, 1.001, 1.1, 3.0, 100.0][case % 6];
            let through = base + along * (apex - base) + gap * e1;
            let back = [1.0, 10.0, 1e6][case % 7 % 3] * scale;
            let ray = Ray::new(through - back * dir, dir);
            if gap > 1.01 * widest {
                far_lines += 1;
            }
            if cone.line_passes_wide(&ray) {
                ruled_out += 1;
                assert!(
                    cone.roots_near_segment(&ray).is_none(),
                    "case {case}: {cone:?} {ray:?}"
                );
            }
        }
        assert!(
            ruled_out > far_lines / 3,
            "{ruled_out} of {far_lines} ruled out"
        );
    }

    #[test]
    fn cones_seen_from_far_away_are_hit_where_they_are() {
        // Found by fuzzing (nff_scene): a shadow ray from 3e8 away hit a
        // needle it passes metres from and missed a cone it goes through,
        // and the octree, which only tests cones near them, disagreed with
        // brute force.
        let needle = Cone::new(
            DVec3::new(0.0, 3.0, 0.0),
            1e-9,
            DVec3::new(5.0, 6.0, 0.0),
            0.0,
        )
        .unwrap();
        let wide = Cone::new(
            DVec3::new(0.7, 7.0, -1.0),
            0.0,
            DVec3::new(3.0, 7.0, 5.0),
            2.0,
        )
        .unwrap();
        let light = DVec3::new(3.0, 3.0, 3.0);
        let far = DVec3::new(-32431558.005971525, 293176397.1541214, 1224367.2118846006);
        let ray = Ray::new(far, (light - far).normalize());
        let t_max = light.distance(far);
        assert!(needle.intersect(&ray, t_max).is_none());
        assert!(needle.crossings(&ray, t_max).as_slice().is_empty());
        assert_eq!(wide.crossings(&ray, t_max).as_slice().len(), 2);
        // A cone far longer than the ray (fuzzing again: re-basing at the
        // segment's middle, 2e9 away, made this ray hit it 17 from its axis).
        let long = Cone::new(
            DVec3::new(0.750948, 0.478724, 2.37111),
            0.002734,
            DVec3::new(4294967295.0, 0.488116, 2.38066),
            0.00183195,
        )
        .unwrap();
        let ground = Ray::new(
            DVec3::new(
                -13.27730228565912,
                -3.7053492863348225,
                0.0039062499990905053,
            ),
            DVec3::new(0.7353007712423545, -0.44675790606553667, 0.509647082968534),
        );
        assert!(long.intersect(&ground, 58.85659852163403).is_none());
        let across = Ray::new(DVec3::new(1e3, 0.48, 10.0), -DVec3::Z);
        let hit = long
            .intersect(&across, f64::INFINITY)
            .expect("crosses the axis");
        assert!((across.at(hit.t).z - 2.37111).abs() < 0.003);
        // Aimed at a point of the surface from ever farther away, a ray
        // hits within rounding of it (the point's error grows with the
        // distance travelled, about 1e-16 of it).
        let (e1, e2) = crate::math::orthonormal_basis(wide.axis);
        let z = 0.6 * wide.height;
        let target = wide.base + z * wide.axis + (wide.slope * z) * e1;
        // Coming from outside the surface there, so `target` is hit first.
        let back = (e1 + 0.3 * e2 - 0.2 * wide.axis).normalize();
        for exponent in 0..=12 {
            let distance = 10f64.powi(exponent);
            let from = target + distance * back;
            let ray = Ray::new(from, (target - from).normalize());
            let hit = wide.intersect(&ray, f64::INFINITY).unwrap_or_else(|| {
                panic!("missed from {distance:e}");
            });
            let error = ray.at(hit.t).distance(target);
            assert!(
                error <= 1e-9 * distance.max(1.0),
                "{error:e} from the aimed-at point at {distance:e}"
            );
        }
    }

    #[test]
    fn box_overlap_follows_the_axis_not_the_bounding_box() {
        // A thin diagonal cylinder: its bounding box is the whole unit cube.
        let c = Cone::new(DVec3::ZERO, 0.05, DVec3::ONE, 0.05).unwrap();
        let corner = Aabb::new(DVec3::new(0.8, 0.0, 0.0), DVec3::new(1.0, 0.2, 0.2));
        assert!(c.bounds().overlaps(&corner));
        assert!(!c.overlaps_box(&corner), "far from the axis");
        let on_axis = Aabb::new(DVec3::splat(0.45), DVec3::splat(0.55));
        assert!(c.overlaps_box(&on_axis));
        let touching = Aabb::new(
            DVec3::new(0.5 + 0.05 / 2f64.sqrt(), 0.5 - 0.05 / 2f64.sqrt(), 0.0),
            DVec3::new(0.9, 0.9, 1.0),
        );
        assert!(c.overlaps_box(&touching), "a box reaching the surface");
    }

    #[test]
    fn the_early_exits_give_the_dense_answer() {
        // The axis sampled densely is the reference: the search may answer
        // "overlaps" only within its margin of the reach, and must never
        // miss a box within it.
        let mut seed = 0x9e37_79b9_7f4a_7c15u64;
        let mut next = || {
            seed ^= seed << 13;
            seed ^= seed >> 7;
            seed ^= seed << 17;
            (seed >> 11) as f64 / (1u64 << 53) as f64 * 4.0 - 2.0
        };
        for _ in 0..2000 {
            let base = DVec3::new(next(), next(), next());
            let apex = DVec3::new(next(), next(), next());
            let (rb, ra) = (next().abs() * 0.2, next().abs() * 0.2);
            let Some(c) = Cone::new(base, rb, apex, ra) else {
                continue;
            };
            let (p, q) = (
                DVec3::new(next(), next(), next()),
                DVec3::new(next(), next(), next()),
            );
            let b = Aabb::new(p.min(q), p.min(q) + (p - q).abs() * 0.25);
            let nearest = (0..=20_000)
                .map(|i| {
                    let x = base + (i as f64 / 20_000.0) * (apex - base);
                    x.distance(x.clamp(b.min, b.max))
                })
                .fold(f64::INFINITY, f64::min);
            let r = rb.max(ra);
            // Sampling finds the minimum to within a step's length.
            let step = (apex - base).length() / 20_000.0;
            if !c.bounds().overlaps(&b) {
                // The exact bounds answer first; the search is for the rest.
                assert!(!c.overlaps_box(&b));
            } else if nearest <= r {
                assert!(
                    c.overlaps_box(&b),
                    "missed a box {nearest} from the axis, r {r}"
                );
            } else if nearest - step > r * (1.0 + 1e-6) {
                assert!(
                    !c.overlaps_box(&b),
                    "took a box {nearest} from the axis, r {r}"
                );
            }
        }
    }
}
