//! What double precision costs and buys, at the level of the intersection
//! kernels: the same ray-sphere and ray-triangle code in f32 and f64,
//! timed on the same rays, and checked for accuracy on a unit sphere and a
//! unit triangle moved 0 to 1e6 from the origin (the camera 5 units away).
//!
//! `cargo bench --bench precision` prints a markdown table;
//! docs/robustness.md ("Numerical robustness") quotes it.

use std::hint::black_box;
use std::time::Instant;

/// The arithmetic the kernels need, for f32 and f64.
trait Real:
    Copy
    + PartialOrd
    + std::ops::Add<Output = Self>
    + std::ops::Sub<Output = Self>
    + std::ops::Mul<Output = Self>
    + std::ops::Div<Output = Self>
    + std::ops::Neg<Output = Self>
{
    const ZERO: Self;
    const ONE: Self;
    fn of(x: f64) -> Self;
    fn to_f64(self) -> f64;
    fn sqrt(self) -> Self;
}

macro_rules! real {
    ($t:ty) => {
        impl Real for $t {
            const ZERO: Self = 0.0;
            const ONE: Self = 1.0;
            fn of(x: f64) -> Self {
                x as $t
            }
            fn to_f64(self) -> f64 {
                self as f64
            }
            fn sqrt(self) -> Self {
                <$t>::sqrt(self)
            }
        }
    };
}
real!(f32);
real!(f64);

#[derive(Clone, Copy)]
struct V<T>([T; 3]);

impl<T: Real> V<T> {
    fn of(v: [f64; 3]) -> Self {
        V(v.map(T::of))
    }
    fn sub(self, o: Self) -> Self {
        V([self.0[0] - o.0[0], self.0[1] - o.0[1], self.0[2] - o.0[2]])
    }
    fn dot(self, o: Self) -> T {
        self.0[0] * o.0[0] + self.0[1] * o.0[1] + self.0[2] * o.0[2]
    }
    fn cross(self, o: Self) -> Self {
        let (a, b) = (self.0, o.0);
        V([
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ])
    }
}

/// Nearest positive root of |o + t d - c|^2 = r^2 with the stable
/// quadratic form (q = -(b + sign(b) sqrt(disc)), as glint's sphere).
fn sphere<T: Real>(o: V<T>, d: V<T>, c: V<T>, r: T) -> Option<T> {
    let oc = o.sub(c);
    let a = d.dot(d);
    let h = oc.dot(d);
    let cc = oc.dot(oc) - r * r;
    let disc = h * h - a * cc;
    if disc < T::ZERO {
        return None;
    }
    let s = disc.sqrt();
    let q = if h > T::ZERO { -(h + s) } else { -h + s };
    let (t0, t1) = (cc / q, q / a);
    let (near, far) = if t0 < t1 { (t0, t1) } else { (t1, t0) };
    if near > T::ZERO {
        Some(near)
    } else if far > T::ZERO {
        Some(far)
    } else {
        None
    }
}

/// Möller–Trumbore (1997) ray-triangle test.
fn triangle<T: Real>(o: V<T>, d: V<T>, p: [V<T>; 3]) -> Option<T> {
    let (e1, e2) = (p[1].sub(p[0]), p[2].sub(p[0]));
    let pv = d.cross(e2);
    let det = e1.dot(pv);
    if det == T::ZERO {
        return None;
    }
    let inv = T::ONE / det;
    let tv = o.sub(p[0]);
    let u = tv.dot(pv) * inv;
    if u < T::ZERO || u > T::ONE {
        return None;
    }
    let qv = tv.cross(e1);
    let v = d.dot(qv) * inv;
    if v < T::ZERO || u + v > T::ONE {
        return None;
    }
    let t = e2.dot(qv) * inv;
    (t > T::ZERO).then_some(t)
}

/// A small deterministic generator (xorshift64*), so both precisions see
/// the same rays.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        (self.0.wrapping_mul(0x2545_f491_4f6c_dd1d) >> 11) as f64 / (1u64 << 53) as f64
    }
}

struct Case {
    origin: [f64; 3],
    dir: [f64; 3],
}

/// Centre of the unit sphere (and the triangles) for a distance `offset`
/// from the origin: deliberately not a round number, as in a real scene.
fn centre_at(offset: f64) -> [f64; 3] {
    [
        offset * 1.0 + 0.123_456_7,
        offset * -0.8 + 0.765_432_1,
        offset * 0.6 + 0.314_159_3,
    ]
}

/// Rays from 5 units in front of the unit sphere at `offset` towards
/// points inside 0.95 of its silhouette: every one must hit.
fn rays_at(offset: f64, n: usize) -> Vec<Case> {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let c = centre_at(offset);
    let eye = [c[0] + 0.271_828, c[1] - 0.161_803, c[2] + 5.0];
    (0..n)
        .map(|_| {
            let (a, r) = (rng.next() * std::f64::consts::TAU, 0.95 * rng.next().sqrt());
            let target = [c[0] + r * a.cos(), c[1] + r * a.sin(), c[2]];
            let d = [target[0] - eye[0], target[1] - eye[1], target[2] - eye[2]];
            let l = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt();
            Case {
                origin: eye,
                dir: [d[0] / l, d[1] / l, d[2] / l],
            }
        })
        .collect()
}

/// Misses and the largest error of the hit distance (in units of the
/// sphere's radius) against the exact answer computed in f64 relative to
/// the sphere's centre.
fn sphere_accuracy<T: Real>(offset: f64, cases: &[Case]) -> (usize, f64) {
    let c = centre_at(offset);
    let (mut misses, mut worst) = (0, 0.0f64);
    for case in cases {
        // Reference: the same ray expressed relative to the centre, in f64.
        let local = [
            case.origin[0] - c[0],
            case.origin[1] - c[1],
            case.origin[2] - c[2],
        ];
        let exact = sphere(V::<f64>(local), V::<f64>(case.dir), V::<f64>([0.0; 3]), 1.0);
        let got = sphere(
            V::<T>::of(case.origin),
            V::<T>::of(case.dir),
            V::<T>::of(c),
            T::ONE,
        );
        match (exact, got) {
            (Some(e), Some(g)) => worst = worst.max((g.to_f64() - e).abs()),
            (Some(_), None) => misses += 1,
            _ => {}
        }
    }
    (misses, worst)
}

fn triangle_accuracy<T: Real>(offset: f64, cases: &[Case]) -> usize {
    // Two triangles covering the square [-1, 1]^2 around the centre: every
    // ray aimed inside the silhouette must hit one of them.
    let c = centre_at(offset);
    let corner = |x: f64, y: f64| V::<T>::of([c[0] + x, c[1] + y, c[2]]);
    let tris = [
        [corner(-1.0, -1.0), corner(1.0, -1.0), corner(1.0, 1.0)],
        [corner(-1.0, -1.0), corner(1.0, 1.0), corner(-1.0, 1.0)],
    ];
    cases
        .iter()
        .filter(|case| {
            let (o, d) = (V::<T>::of(case.origin), V::<T>::of(case.dir));
            tris.iter().all(|t| triangle(o, d, *t).is_none())
        })
        .count()
}

/// Nanoseconds per test of one run over `cases`.
fn time_per_test<T: Real>(cases: &[(V<T>, V<T>)], f: &impl Fn(V<T>, V<T>) -> Option<T>) -> f64 {
    let start = Instant::now();
    let mut hits = 0usize;
    for _ in 0..8 {
        for &(o, d) in cases {
            hits += f(black_box(o), black_box(d)).is_some() as usize;
        }
    }
    black_box(hits);
    start.elapsed().as_secs_f64() * 1e9 / (8 * cases.len()) as f64
}

fn prepare<T: Real>(cases: &[Case]) -> Vec<(V<T>, V<T>)> {
    cases
        .iter()
        .map(|c| (V::<T>::of(c.origin), V::<T>::of(c.dir)))
        .collect()
}

/// Best of `runs` interleaved runs of the f32 and f64 versions (after a
/// warm-up), so clock changes affect both alike.
fn compare(
    cases: &[Case],
    f32_test: impl Fn(V<f32>, V<f32>) -> Option<f32>,
    f64_test: impl Fn(V<f64>, V<f64>) -> Option<f64>,
) -> (f64, f64) {
    let (a, b) = (prepare::<f32>(cases), prepare::<f64>(cases));
    let (mut best32, mut best64) = (f64::INFINITY, f64::INFINITY);
    time_per_test(&a, &f32_test);
    time_per_test(&b, &f64_test);
    for _ in 0..7 {
        best32 = best32.min(time_per_test(&a, &f32_test));
        best64 = best64.min(time_per_test(&b, &f64_test));
    }
    (best32, best64)
}

fn main() {
    let n = 200_000;
    let base = rays_at(0.0, n);
    let c = centre_at(0.0);
    let (c32, c64) = (V::<f32>::of(c), V::<f64>::of(c));
    let (s32, s64) = compare(
        &base,
        |o, d| sphere(o, d, c32, 1.0),
        |o, d| sphere(o, d, c64, 1.0),
    );
    let tri = |x: f64, y: f64| [c[0] + x, c[1] + y, c[2]];
    let t = [tri(-1.0, -1.0), tri(1.0, -1.0), tri(1.0, 1.0)];
    let (t32, t64) = (t.map(V::<f32>::of), t.map(V::<f64>::of));
    let (t32, t64) = compare(
        &base,
        |o, d| triangle(o, d, t32),
        |o, d| triangle(o, d, t64),
    );
    println!(
        "## Kernel cost (ns per test, best of 7 interleaved runs, one thread, {n} rays x 8)\n"
    );
    println!("| kernel | f32 | f64 | f64 / f32 |");
    println!("|---|---:|---:|---:|");
    println!("| ray-sphere | {s32:.2} | {s64:.2} | {:.2}x |", s64 / s32);
    println!("| ray-triangle | {t32:.2} | {t64:.2} | {:.2}x |", t64 / t32);
    println!();
    println!("## Accuracy: a unit sphere and a 2x2 square of triangles moved from the origin\n");
    println!(
        "Distance errors are in units of the sphere's radius, against the same ray computed in f64 relative to the centre.\n"
    );
    println!(
        "Rays from 5 units away aimed inside 95% of the silhouette ({} rays): every one should hit.\n",
        n / 10
    );
    println!(
        "| offset | sphere misses f32 | sphere misses f64 | worst distance error f32 | worst distance error f64 | triangle misses f32 | triangle misses f64 |"
    );
    println!("|---:|---:|---:|---:|---:|---:|---:|");
    for offset in [0.0, 1e3, 1e4, 1e5, 1e6] {
        let cases = rays_at(offset, n / 10);
        let (m32, e32) = sphere_accuracy::<f32>(offset, &cases);
        let (m64, e64) = sphere_accuracy::<f64>(offset, &cases);
        let (tm32, tm64) = (
            triangle_accuracy::<f32>(offset, &cases),
            triangle_accuracy::<f64>(offset, &cases),
        );
        println!("| {offset:e} | {m32} | {m64} | {e32:.2e} | {e64:.2e} | {tm32} | {tm64} |");
    }
}
