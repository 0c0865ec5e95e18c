//! One ray against four triangles at once: the watertight test (Woop,
//! Benthin & Wald 2013) with a triangle in each lane, as Embree tests a
//! leaf's triangles four at a time. A single ray's leaves and light-buffer
//! lists hold a few triangles side by side, and one by one each costs its
//! loads, its axis dispatch and its branches. Each lane runs the
//! single-ray test's operations in the same order, so its answer is
//! [`Triangle::intersect`]'s bit for bit.

use super::hit::{PreparedRay, along_axes};
use super::triangle::Triangle;

/// What four triangles' tests found: the lanes hit in `(0, t_max)`, and per
/// lane `t` and the edge values a hit's barycentrics are made of
/// (`b1 = v / det`, `b2 = w / det`, as the single-ray test divides).
#[derive(Clone, Copy, Debug)]
pub struct FourHits {
    pub hit: u32,
    pub t: [f64; 4],
    pub v: [f64; 4],
    pub w: [f64; 4],
    pub det: [f64; 4],
}

/// How a single ray tests four triangles at once: the lanes' code for a
/// SIMD level.
pub trait TriangleLanes: Copy {
    /// Whether this level tests four at once; without, callers test one by
    /// one as before.
    const FOUR_AT_ONCE: bool;

    /// Whether shadow rays skip the shapes in the plane they leave
    /// ([`crate::accel::PlaneGroups`]): a copy of the walk of its own for
    /// scenes that have such groups, so that the others pay nothing.
    const SKIPS_PLANES: bool = false;

    /// The lanes of `live` whose triangle `ray` hits with `0 < t < t_max`
    /// (the other lanes may hold any triangle). Unless a level says
    /// otherwise, four single tests (barycentrics as quotients over 1,
    /// which they equal).
    fn intersect_four(
        self,
        triangles: [&Triangle; 4],
        live: u32,
        ray: &PreparedRay,
        t_max: f64,
    ) -> FourHits {
        let mut four = FourHits {
            hit: 0,
            t: [0.0; 4],
            v: [0.0; 4],
            w: [1.0; 4],
            det: [1.0; 4],
        };
        for (j, triangle) in triangles.iter().enumerate() {
            if live >> j & 1 == 1
                && let Some(hit) = triangle.intersect(ray, t_max)
            {
                (four.t[j], four.v[j], four.w[j]) = (hit.t, hit.b1, hit.b2);
                four.hit |= 1 << j;
            }
        }
        four
    }
}

/// AVX2: the twelve vertices transposed into nine registers (two 4x4
/// transposes and one gather of four values), then the test in lanes. No
/// closures: one would be compiled without AVX2 and call the intrinsics
/// it holds instead of inlining them.
impl TriangleLanes for pulp::x86::V3 {
    const FOUR_AT_ONCE: bool = true;

    #[inline(always)]
    fn intersect_four(
        self,
        triangles: [&Triangle; 4],
        live: u32,
        ray: &PreparedRay,
        t_max: f64,
    ) -> FourHits {
        use pulp::{Simd, cast, f64x4};
        use std::arch::x86_64::__m256d;
        let avx = self.avx;
        // A triangle's nine coordinates are contiguous: the first four and
        // the next four are one load each.
        let mut first = [self.splat_f64s(0.0); 4];
        let mut second = [self.splat_f64s(0.0); 4];
        for (i, t) in triangles.iter().enumerate() {
            let flat: &[f64; 9] = pulp::bytemuck::cast_ref(&t.vertices);
            let [head @ .., _, _, _, _, _] = flat;
            let [_, _, _, _, middle @ .., _] = flat;
            first[i] = cast(*head);
            second[i] = cast(*middle);
        }
        macro_rules! transpose {
            ($rows:expr) => {{
                let [r0, r1, r2, r3]: [__m256d; 4] = $rows.map(cast);
                let (t0, t1) = (
                    avx._mm256_unpacklo_pd(r0, r1),
                    avx._mm256_unpackhi_pd(r0, r1),
                );
                let (t2, t3) = (
                    avx._mm256_unpacklo_pd(r2, r3),
                    avx._mm256_unpackhi_pd(r2, r3),
                );
                let columns: [f64x4; 4] = [
                    cast(avx._mm256_permute2f128_pd::<0x20>(t0, t2)),
                    cast(avx._mm256_permute2f128_pd::<0x20>(t1, t3)),
                    cast(avx._mm256_permute2f128_pd::<0x31>(t0, t2)),
                    cast(avx._mm256_permute2f128_pd::<0x31>(t1, t3)),
                ];
                columns
            }};
        }
        let [p_x, p_y, p_z, q_x] = transpose!(first);
        let [q_y, q_z, r_x, r_y] = transpose!(second);
        let r_z = f64x4(
            triangles[0].vertices[2].z,
            triangles[1].vertices[2].z,
            triangles[2].vertices[2].z,
            triangles[3].vertices[2].z,
        );
        let o = ray.ray.origin;
        let (o_x, o_y, o_z) = (
            self.splat_f64s(o.x),
            self.splat_f64s(o.y),
            self.splat_f64s(o.z),
        );
        let vertices = [
            [
                self.sub_f64s(p_x, o_x),
                self.sub_f64s(p_y, o_y),
                self.sub_f64s(p_z, o_z),
            ],
            [
                self.sub_f64s(q_x, o_x),
                self.sub_f64s(q_y, o_y),
                self.sub_f64s(q_z, o_z),
            ],
            [
                self.sub_f64s(r_x, o_x),
                self.sub_f64s(r_y, o_y),
                self.sub_f64s(r_z, o_z),
            ],
        ];
        along_axes!(ray.permutation, |KX, KY, KZ| four_along::<KX, KY, KZ>(
            self, vertices, ray, live, t_max
        ))
    }
}

/// The test in lanes for the permutation `(KX, KY, KZ)`, on vertices
/// relative to the ray's origin: [`Triangle::intersect`]'s operations in
/// its order (products and sums written as it writes them, no fused
/// multiply-add), its comparisons as masks, each false for NaN as there.
#[inline(always)]
fn four_along<const KX: usize, const KY: usize, const KZ: usize>(
    simd: pulp::x86::V3,
    [a, b, c]: [[pulp::f64x4; 3]; 3],
    ray: &PreparedRay,
    live: u32,
    t_max: f64,
) -> FourHits {
    use pulp::{Simd, cast};
    let (sx, sy, sz) = (
        simd.splat_f64s(ray.shear.x),
        simd.splat_f64s(ray.shear.y),
        simd.splat_f64s(ray.shear.z),
    );
    let ax = simd.sub_f64s(a[KX], simd.mul_f64s(sx, a[KZ]));
    let ay = simd.sub_f64s(a[KY], simd.mul_f64s(sy, a[KZ]));
    let bx = simd.sub_f64s(b[KX], simd.mul_f64s(sx, b[KZ]));
    let by = simd.sub_f64s(b[KY], simd.mul_f64s(sy, b[KZ]));
    let cx = simd.sub_f64s(c[KX], simd.mul_f64s(sx, c[KZ]));
    let cy = simd.sub_f64s(c[KY], simd.mul_f64s(sy, c[KZ]));
    let u = simd.sub_f64s(simd.mul_f64s(cx, by), simd.mul_f64s(cy, bx));
    let v = simd.sub_f64s(simd.mul_f64s(ax, cy), simd.mul_f64s(ay, cx));
    let w = simd.sub_f64s(simd.mul_f64s(bx, ay), simd.mul_f64s(by, ax));
    let zero = simd.splat_f64s(0.0);
    let negative = simd.or_m64s(
        simd.or_m64s(simd.less_than_f64s(u, zero), simd.less_than_f64s(v, zero)),
        simd.less_than_f64s(w, zero),
    );
    let positive = simd.or_m64s(
        simd.or_m64s(
            simd.greater_than_f64s(u, zero),
            simd.greater_than_f64s(v, zero),
        ),
        simd.greater_than_f64s(w, zero),
    );
    let det = simd.add_f64s(simd.add_f64s(u, v), w);
    let miss = simd.or_m64s(
        simd.and_m64s(negative, positive),
        simd.equal_f64s(det, zero),
    );
    let mut hit = !(simd.avx._mm256_movemask_pd(cast(miss)) as u32) & live & 0xf;
    if hit != 0 {
        let sum = simd.add_f64s(
            simd.add_f64s(simd.mul_f64s(u, a[KZ]), simd.mul_f64s(v, b[KZ])),
            simd.mul_f64s(w, c[KZ]),
        );
        let t = simd.div_f64s(simd.mul_f64s(sz, sum), det);
        let ahead = simd.and_m64s(
            simd.greater_than_f64s(t, zero),
            simd.less_than_f64s(t, simd.splat_f64s(t_max)),
        );
        hit &= simd.avx._mm256_movemask_pd(cast(ahead)) as u32;
        if hit != 0 {
            return FourHits {
                hit,
                t: cast(t),
                v: cast(v),
                w: cast(w),
                det: cast(det),
            };
        }
    }
    FourHits {
        hit: 0,
        t: [0.0; 4],
        v: [0.0; 4],
        w: [0.0; 4],
        det: [0.0; 4],
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::{DVec3, Ray, XorShift};

    /// A point in the cube of side `scale` around `centre`.
    fn point(random: &mut XorShift, scale: f64, centre: DVec3) -> DVec3 {
        let mut coordinate = || random.unit() - 0.5;
        centre + scale * DVec3::new(coordinate(), coordinate(), coordinate())
    }

    /// Four triangles' lane test answers what four single tests answer, to
    /// the bit: which are hit, where, and the barycentrics. The triangles
    /// share edges and vertices (fans, strips), are slivers, or lie 1e6
    /// from the origin at sizes 1e-4 to 1e4; the rays aim at vertices,
    /// edge midpoints and interiors, run parallel to or in a triangle's
    /// plane, start on one, and meet limits equal to a hit's `t`.
    #[test]
    fn four_lanes_answer_as_four_single_tests() {
        let Some(simd) = pulp::x86::V3::try_new() else {
            eprintln!("no AVX2 here: nothing to compare");
            return;
        };
        let mut random = XorShift(0x2545_f491_4f6c_dd1d);
        let (mut hits, mut cases) = (0, 0);
        for case in 0..4000 {
            let scale = [1e-4, 1.0, 1e4][case % 3];
            let centre = if case % 5 == 0 {
                DVec3::new(1e6, -1e6, 1e6)
            } else {
                DVec3::ZERO
            };
            // A fan around a shared vertex in one plane (coplanar, as a
            // polygon's triangulation), or four unrelated triangles.
            let hub = point(&mut random, scale, centre);
            let rim: Vec<DVec3> = (0..5).map(|_| point(&mut random, scale, centre)).collect();
            let flat = case % 4 == 1;
            let rim: Vec<DVec3> = if flat {
                rim.iter().map(|p| DVec3::new(p.x, p.y, hub.z)).collect()
            } else {
                rim
            };
            let triangles: Vec<Triangle> = (0..4)
                .map(|i| {
                    let (b, c) = if case % 2 == 0 {
                        (rim[i], rim[i + 1])
                    } else {
                        (
                            point(&mut random, scale, centre),
                            point(&mut random, scale, centre),
                        )
                    };
                    // Slivers: the third vertex nearly on the first edge.
                    let c = if case % 7 == 3 {
                        hub + (b - hub) * 0.5 + (c - hub) * 1e-9
                    } else {
                        c
                    };
                    Triangle {
                        vertices: [
                            if case % 2 == 0 {
                                hub
                            } else {
                                point(&mut random, scale, centre)
                            },
                            b,
                            c,
                        ],
                        vertex_normals: crate::shapes::NO_NORMALS,
                    }
                })
                .collect();
            let target = match case % 6 {
                0 => triangles[case % 4].vertices[0],
                1 => 0.5 * (triangles[case % 4].vertices[0] + triangles[case % 4].vertices[1]),
                2 => triangles[case % 4].vertices[1],
                _ => {
                    let [a, b, c] = triangles[case % 4].vertices;
                    let (u, v) = (random.unit(), random.unit());
                    a + u * (b - a) + v * (1.0 - u) * (c - a)
                }
            };
            let origin = match case % 9 {
                // On a triangle (a shadow ray leaving it).
                0 => target,
                // In the fan's plane.
                1 => DVec3::new(
                    point(&mut random, scale, centre).x,
                    point(&mut random, scale, centre).y,
                    hub.z,
                ),
                _ => point(&mut random, 4.0 * scale, centre),
            };
            let dir = if case % 9 == 0 {
                DVec3::new(
                    random.unit() - 0.5,
                    random.unit() - 0.5,
                    random.unit() - 0.5,
                )
            } else if case % 11 == 0 {
                // Along the fan's plane.
                DVec3::new(random.unit() - 0.5, random.unit() - 0.5, 0.0)
            } else {
                target - origin
            };
            let Some(dir) = dir.try_normalize() else {
                continue;
            };
            let ray = PreparedRay::new(Ray::new(origin, dir));
            let singles: Vec<_> = triangles
                .iter()
                .map(|t| t.intersect(&ray, f64::INFINITY))
                .collect();
            // Limits: none, a hit's own t (exclusive: that hit is cut), and
            // just past it.
            let first_t = singles.iter().flatten().map(|h| h.t).next();
            let limits = [
                f64::INFINITY,
                first_t.unwrap_or(1.0),
                crate::shapes::probe_past(first_t.unwrap_or(1.0)),
            ];
            for (live, t_max) in [0b1111u32, 0b0101, 0b0111].into_iter().zip(limits) {
                let four = simd.intersect_four(
                    [&triangles[0], &triangles[1], &triangles[2], &triangles[3]],
                    live,
                    &ray,
                    t_max,
                );
                for (j, triangle) in triangles.iter().enumerate() {
                    let single = triangle
                        .intersect(&ray, t_max)
                        .filter(|_| live >> j & 1 == 1);
                    cases += 1;
                    match single {
                        Some(h) => {
                            hits += 1;
                            assert_eq!(four.hit >> j & 1, 1, "case {case} lane {j}: missed");
                            assert_eq!(four.t[j].to_bits(), h.t.to_bits(), "case {case} lane {j}");
                            assert_eq!((four.v[j] / four.det[j]).to_bits(), h.b1.to_bits());
                            assert_eq!((four.w[j] / four.det[j]).to_bits(), h.b2.to_bits());
                        }
                        None => assert_eq!(four.hit >> j & 1, 0, "case {case} lane {j}: hit"),
                    }
                }
            }
        }
        // Enough of both answers for the comparison to mean something.
        assert!(hits > cases / 20, "{hits} hits in {cases} cases");
    }
}
