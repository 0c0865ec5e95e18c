//! Packets: up to `N` coherent rays (the eye rays of neighbouring pixels,
//! a pixel's samples, the shadow rays of neighbouring hits towards one
//! light) tested together, one lane each. Lanes run the single-ray tests'
//! arithmetic operation for operation, so a lane's answer is bit for bit
//! the single ray's (Wald et al. 2001 introduced packets for coherent rays;
//! here they must also stay exact).

// Lane loops index several arrays by the same lane number.
#![allow(clippy::needless_range_loop)]

use super::hit::{PreparedRay, along_axes, probe_past, wins};
use super::sphere::Sphere;
use super::triangle::Triangle;
use crate::math::{DVec3, Ray};
use crate::simd::{F64s, lanes, map2, mask, per_axis, splat};

/// Up to `N` rays that share their direction's signs and the watertight
/// test's axis permutation, and none of which is parallel to an axis plane
/// (the octree walk and the triangle test then treat every lane alike).
/// Each lane holds what [`PreparedRay::new`] computes for its ray, computed
/// in lanes with the same operations.
#[derive(Clone, Copy, Debug)]
pub struct RayPacket<const N: usize> {
    /// Lanes holding a ray (the others repeat lane 0 and are never live).
    pub live: u32,
    pub origin: [F64s<N>; 3],
    pub dir: [F64s<N>; 3],
    pub inv_dir: [F64s<N>; 3],
    pub shear: [F64s<N>; 3],
    /// Bit `k`: every lane's direction is negative on axis `k`.
    pub negative: u32,
    pub(super) permutation: u8,
}

impl<const N: usize> RayPacket<N> {
    /// A packet of `rays` (1 to `N`), or `None` if they disagree in signs
    /// or permutation or one is parallel to an axis plane: such rays are
    /// traced one by one.
    #[inline(always)]
    pub fn from_rays(rays: &[Ray]) -> Option<Self> {
        let first = rays.first()?;
        if rays.len() > N {
            return None;
        }
        let ray = |i: usize| rays.get(i).unwrap_or(first);
        let origin: [F64s<N>; 3] = per_axis!(|k| lanes!(N, |i| ray(i).origin[k]));
        let dir: [F64s<N>; 3] = per_axis!(|k| lanes!(N, |i| ray(i).dir[k]));
        let inv_dir: [F64s<N>; 3] = per_axis!(|k| lanes!(N, |i| 1.0 / dir[k][i]));
        let all = crate::simd::all_lanes::<N>();
        let zero = splat::<N>(0.0);
        let infinity = splat::<N>(f64::INFINITY);
        let mut negative = 0;
        for k in 0..3 {
            // `PreparedRay::new` treats a component whose reciprocal is not
            // finite as parallel: packets take none.
            let magnitude: F64s<N> = lanes!(N, |i| inv_dir[k][i].abs());
            if mask(magnitude, infinity, |m, inf| m < inf) != all {
                return None;
            }
            match mask(dir[k], zero, |d, z| d < z) {
                0 => {}
                m if m == all => negative |= 1 << k,
                _ => return None,
            }
        }
        let permutation = PreparedRay::permutation_of(first.dir);
        if (1..rays.len()).any(|i| PreparedRay::permutation_of(rays[i].dir) != permutation) {
            return None;
        }
        let shear = along_axes!(permutation, |KX, KY, KZ| shear_along::<KX, KY, KZ, N>(
            &dir, &inv_dir
        ));
        Some(Self {
            live: all >> (N - rays.len()),
            origin,
            dir,
            inv_dir,
            shear,
            negative,
            permutation,
        })
    }

    /// Lane `i` as a single prepared ray (bit for bit what
    /// [`PreparedRay::new`] gives for it), for the tests that run lane by
    /// lane.
    #[inline(always)]
    pub fn lane(&self, i: usize) -> PreparedRay {
        let column = |v: &[F64s<N>; 3]| [v[0][i], v[1][i], v[2][i]];
        PreparedRay {
            ray: Ray {
                origin: DVec3::from(column(&self.origin)),
                dir: DVec3::from(column(&self.dir)),
            },
            inv_dir: column(&self.inv_dir),
            negative: self.negative,
            parallel: 0,
            permutation: self.permutation,
            shear: DVec3::from(column(&self.shear)),
        }
    }
}

/// The watertight test's shear constants in lanes for the permutation
/// `(KX, KY, KZ)`: `d[KX] / d[KZ]`, `d[KY] / d[KZ]` and `1 / d[KZ]`, as in
/// [`PreparedRay::new`].
#[inline(always)]
fn shear_along<const KX: usize, const KY: usize, const KZ: usize, const N: usize>(
    dir: &[F64s<N>; 3],
    inv_dir: &[F64s<N>; 3],
) -> [F64s<N>; 3] {
    [
        map2(dir[KX], dir[KZ], |a, b| a / b),
        map2(dir[KY], dir[KZ], |a, b| a / b),
        inv_dir[KZ],
    ]
}

/// Per lane, the closest hit so far: its parameter (the limit beyond which
/// nothing matters, `t_max` before any hit), the shape (`NONE` before any
/// hit) and the barycentric coordinates of a triangle's hit.
#[derive(Clone, Copy, Debug)]
pub struct PacketHits<const N: usize> {
    pub t: F64s<N>,
    pub shape: [u32; N],
    pub b1: F64s<N>,
    pub b2: F64s<N>,
    /// The exclusive limit a test must beat in each lane: `t_max` before
    /// any hit, then just past the best `t`, since an equal `t` with a
    /// lower shape index also wins (as in the single-ray test).
    pub probe: F64s<N>,
}

impl<const N: usize> PacketHits<N> {
    /// No hit yet: shape index of a lane without one.
    pub const NONE: u32 = u32::MAX;

    pub fn new(t_max: F64s<N>) -> Self {
        Self {
            t: t_max,
            shape: [Self::NONE; N],
            b1: splat(0.0),
            b2: splat(0.0),
            probe: t_max,
        }
    }

    /// Keeps `index`'s hits in the `hit` lanes, each of which beat the
    /// lane's probe, where they are closer than the best or as close with
    /// a lower index (hits are rare: lane by lane).
    #[inline(always)]
    pub fn merge(&mut self, index: u32, hit: u32, t: F64s<N>, b1: F64s<N>, b2: F64s<N>) {
        let mut left = hit;
        while left != 0 {
            let i = left.trailing_zeros() as usize;
            left &= left - 1;
            if wins(t[i], index, self.t[i], self.shape[i]) {
                self.t[i] = t[i];
                self.b1[i] = b1[i];
                self.b2[i] = b2[i];
                self.shape[i] = index;
                self.probe[i] = probe_past(t[i]);
            }
        }
    }
}

/// What a triangle test found in each lane.
pub struct LaneHits<const N: usize> {
    /// Lanes hit within their limit.
    pub hit: u32,
    pub t: F64s<N>,
    pub b1: F64s<N>,
    pub b2: F64s<N>,
}

impl Triangle {
    /// [`Triangle::intersect`] for every lane of `p` at once, each against
    /// its own exclusive limit `t_max`.
    #[inline(always)]
    pub fn intersect_lanes<const N: usize>(
        &self,
        p: &RayPacket<N>,
        t_max: &F64s<N>,
    ) -> LaneHits<N> {
        along_axes!(p.permutation, |KX, KY, KZ| self
            .lanes_along::<KX, KY, KZ, N>(p, t_max))
    }

    /// The watertight test (Woop, Benthin & Wald 2013) in lanes, with the
    /// single-ray test's operations in the same order.
    #[inline(always)]
    fn lanes_along<const KX: usize, const KY: usize, const KZ: usize, const N: usize>(
        &self,
        p: &RayPacket<N>,
        t_max: &F64s<N>,
    ) -> LaneHits<N> {
        let o = &p.origin;
        let relative = |v: glam::DVec3| -> [F64s<N>; 3] {
            let v = v.to_array();
            per_axis!(|k| map2(splat(v[k]), o[k], |a, b| a - b))
        };
        let a = relative(self.vertices[0]);
        let b = relative(self.vertices[1]);
        let c = relative(self.vertices[2]);
        let (sx, sy, sz) = (p.shear[0], p.shear[1], p.shear[2]);
        let project = |v: &[F64s<N>; 3]| -> (F64s<N>, F64s<N>) {
            (
                lanes!(N, |i| v[KX][i] - sx[i] * v[KZ][i]),
                lanes!(N, |i| v[KY][i] - sy[i] * v[KZ][i]),
            )
        };
        let (ax, ay) = project(&a);
        let (bx, by) = project(&b);
        let (cx, cy) = project(&c);
        let u: F64s<N> = lanes!(N, |i| cx[i] * by[i] - cy[i] * bx[i]);
        let v: F64s<N> = lanes!(N, |i| ax[i] * cy[i] - ay[i] * cx[i]);
        let w: F64s<N> = lanes!(N, |i| bx[i] * ay[i] - by[i] * ax[i]);
        let zero = splat::<N>(0.0);
        // "Some edge function is negative" (and "positive") as one
        // comparison each: NaN-ignoring min and max skip a NaN as the
        // single-ray comparisons do.
        let lowest: F64s<N> = lanes!(N, |i| u[i].min(v[i]).min(w[i]));
        let highest: F64s<N> = lanes!(N, |i| u[i].max(v[i]).max(w[i]));
        let negative = mask(lowest, zero, |x, z| x < z);
        let positive = mask(highest, zero, |x, z| x > z);
        let det: F64s<N> = lanes!(N, |i| u[i] + v[i] + w[i]);
        let mut hit = !(negative & positive) & !mask(det, zero, |d, z| d == z) & p.live;
        if hit == 0 {
            return LaneHits {
                hit,
                t: zero,
                b1: zero,
                b2: zero,
            };
        }
        let t: F64s<N> = lanes!(N, |i| {
            let t_scaled = sz[i] * (u[i] * a[KZ][i] + v[i] * b[KZ][i] + w[i] * c[KZ][i]);
            t_scaled / det[i]
        });
        // 0 < t < t_max as one comparison: lanes with t <= 0 (or NaN)
        // compare +inf instead, which is never below a limit.
        let ahead: F64s<N> = lanes!(N, |i| if t[i] > 0.0 { t[i] } else { f64::INFINITY });
        hit &= mask(ahead, *t_max, |t, m| t < m);
        LaneHits {
            hit,
            t,
            b1: map2(v, det, |v, d| v / d),
            b2: map2(w, det, |w, d| w / d),
        }
    }
}

impl Sphere {
    /// [`Sphere::intersect`] for every lane of `p` at once, each against
    /// its own exclusive limit `t_max`, with the single-ray test's
    /// operations in the same order.
    #[inline(always)]
    pub fn intersect_lanes<const N: usize>(
        &self,
        p: &RayPacket<N>,
        t_max: &F64s<N>,
    ) -> LaneHits<N> {
        let c = self.center.to_array();
        let (o, d) = (&p.origin, &p.dir);
        let f: [F64s<N>; 3] = per_axis!(|k| map2(o[k], splat(c[k]), |a, b| a - b));
        let dot = |a: &[F64s<N>; 3], b: &[F64s<N>; 3]| -> F64s<N> {
            lanes!(N, |i| a[0][i] * b[0][i]
                + a[1][i] * b[1][i]
                + a[2][i] * b[2][i])
        };
        let b = dot(&f, d);
        let perp: [F64s<N>; 3] = per_axis!(|k| lanes!(N, |i| f[k][i] - b[i] * d[k][i]));
        let r2 = self.radius * self.radius;
        let perp2 = dot(&perp, &perp);
        let disc: F64s<N> = lanes!(N, |i| r2 - perp2[i]);
        let zero = splat::<N>(0.0);
        let mut hit = mask(disc, zero, |x, z| x >= z) & p.live;
        if hit == 0 {
            return LaneHits {
                hit,
                t: zero,
                b1: zero,
                b2: zero,
            };
        }
        let f2 = dot(&f, &f);
        let mut near = [0.0; N];
        let mut far = [0.0; N];
        for i in 0..N {
            let cc = f2[i] - r2;
            let q = -(b[i] + disc[i].sqrt().copysign(b[i]));
            let (t0, t1) = if q == 0.0 { (0.0, 0.0) } else { (cc / q, q) };
            (near[i], far[i]) = if t0 <= t1 { (t0, t1) } else { (t1, t0) };
        }
        // The near root if it lies in (0, t_max), else the far one.
        let near_ok = mask(
            lanes!(N, |i| if near[i] > 0.0 {
                near[i]
            } else {
                f64::INFINITY
            }),
            *t_max,
            |t, m| t < m,
        );
        let t: F64s<N> = lanes!(N, |i| if near_ok >> i & 1 == 1 {
            near[i]
        } else {
            far[i]
        });
        let far_ok = mask(
            lanes!(N, |i| if far[i] > 0.0 { far[i] } else { f64::INFINITY }),
            *t_max,
            |t, m| t < m,
        );
        hit &= near_ok | far_ok;
        LaneHits {
            hit,
            t,
            b1: zero,
            b2: zero,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bits(r: &PreparedRay) -> (Vec<u64>, u32, u32, u8) {
        let mut v: Vec<u64> = r.inv_dir.iter().map(|x| x.to_bits()).collect();
        v.extend(r.shear.to_array().iter().map(|x| x.to_bits()));
        v.extend(r.ray.origin.to_array().iter().map(|x| x.to_bits()));
        v.extend(r.ray.dir.to_array().iter().map(|x| x.to_bits()));
        (v, r.negative, r.parallel, r.permutation)
    }

    /// Directions around `base` (small, deterministic perturbations), so
    /// that they mostly share signs and permutation.
    fn rays_around(base: DVec3, seed: u64, n: usize) -> Vec<Ray> {
        let mut state = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let mut next = || {
            state = state
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (state >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        (0..n)
            .map(|_| {
                let origin = DVec3::new(next() * 1e3, next() * 1e-3, next());
                let dir = (base + 0.3 * DVec3::new(next(), next(), next())).normalize();
                Ray::new(origin, dir)
            })
            .collect()
    }

    #[test]
    fn each_lane_is_the_prepared_single_ray_bit_for_bit() {
        let mut packets = 0;
        for (b, base) in [
            DVec3::new(1.0, 0.2, 0.1),
            DVec3::new(-1.0, 0.3, -0.2),
            DVec3::new(0.2, 1.0, 0.3),
            DVec3::new(0.1, -1.0, 0.4),
            DVec3::new(0.3, 0.2, 1.0),
            DVec3::new(-0.2, 0.1, -1.0),
        ]
        .into_iter()
        .enumerate()
        {
            for seed in 0..64 {
                let rays = rays_around(base, seed * 7 + b as u64, 1 + seed as usize % 4);
                let Some(packet) = RayPacket::<4>::from_rays(&rays) else {
                    // Then the rays really disagree in signs or permutation.
                    let first = PreparedRay::new(rays[0]);
                    assert!(rays.iter().any(|r| {
                        let p = PreparedRay::new(*r);
                        p.negative != first.negative || p.permutation != first.permutation
                    }));
                    continue;
                };
                packets += 1;
                assert_eq!(packet.live, (1 << rays.len()) - 1);
                for (i, ray) in rays.iter().enumerate() {
                    assert_eq!(bits(&packet.lane(i)), bits(&PreparedRay::new(*ray)));
                }
            }
        }
        assert!(packets > 200, "most groups form packets ({packets})");
    }

    #[test]
    fn rays_that_disagree_or_are_parallel_form_no_packet() {
        let o = DVec3::ZERO;
        let right = Ray::new(o, DVec3::new(1.0, 0.1, 0.1).normalize());
        let left = Ray::new(o, DVec3::new(-1.0, 0.1, 0.1).normalize());
        let up = Ray::new(o, DVec3::new(0.1, 1.0, 0.1).normalize());
        let flat = Ray::new(o, DVec3::new(1.0, 0.0, 0.1).normalize());
        assert!(RayPacket::<4>::from_rays(&[right, left]).is_none(), "signs");
        assert!(RayPacket::<4>::from_rays(&[right, up]).is_none(), "axes");
        assert!(
            RayPacket::<4>::from_rays(&[right, flat]).is_none(),
            "parallel"
        );
        assert!(RayPacket::<4>::from_rays(&[right; 5]).is_none(), "too many");
        assert!(RayPacket::<4>::from_rays(&[]).is_none());
        assert!(RayPacket::<4>::from_rays(&[right, right]).is_some());
    }
}
