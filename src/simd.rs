//! SIMD levels and the lanes the packet kernels compute in.
//!
//! The kernels are written once over arrays of `N` lanes (`[f64; N]`) and
//! run inside a function compiled for the machine's best instruction set,
//! chosen at run time through `pulp` (no `unsafe`, no `-C target-cpu`): with
//! AVX2 four lanes (the default, see [`SimdChoice::choose`]), with AVX-512
//! eight when forced; without either, glint traces single rays. Each lane performs the same IEEE operations in the same order as
//! the single-ray code (Rust never fuses a multiply and an add by itself),
//! so every level gives the same bytes.

// Lane loops index several arrays by the same lane number.
#![allow(clippy::needless_range_loop)]

use std::sync::OnceLock;

/// The instruction sets glint's kernels use.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum SimdLevel {
    /// No packets: every ray on its own.
    Scalar,
    /// Packets of four rays (x86-64-v3: AVX2, FMA, BMI, POPCNT).
    Avx2,
    /// Packets of eight rays (x86-64-v4: AVX-512 F, BW, CD, DQ, VL).
    Avx512,
}

impl SimdLevel {
    pub const ALL: [SimdLevel; 3] = [SimdLevel::Scalar, SimdLevel::Avx2, SimdLevel::Avx512];

    pub fn name(self) -> &'static str {
        match self {
            SimdLevel::Scalar => "scalar",
            SimdLevel::Avx2 => "avx2",
            SimdLevel::Avx512 => "avx512",
        }
    }

    /// Rays in a packet at this level (1: no packets).
    pub fn packet_width(self) -> usize {
        match self {
            SimdLevel::Scalar => 1,
            SimdLevel::Avx2 => 4,
            SimdLevel::Avx512 => 8,
        }
    }

    /// Whether this machine runs the level.
    pub fn is_available(self) -> bool {
        match self {
            SimdLevel::Scalar => true,
            SimdLevel::Avx2 => pulp::x86::V3::try_new().is_some(),
            SimdLevel::Avx512 => pulp::x86::V4::try_new().is_some(),
        }
    }

    /// The best level this machine runs.
    pub fn best() -> Self {
        *SimdLevel::ALL
            .iter()
            .rev()
            .find(|l| l.is_available())
            .unwrap_or(&SimdLevel::Scalar)
    }

    /// The level glint uses ([`SimdChoice`]). Read once.
    pub fn current() -> Self {
        SimdChoice::current().level
    }
}

/// The level glint runs at, and why.
#[derive(Clone, Debug, PartialEq, Eq, serde::Serialize)]
pub struct SimdChoice {
    pub level: SimdLevel,
    pub reason: String,
}

impl SimdChoice {
    /// The default, unless the environment variable `GLINT_SIMD`
    /// (`scalar`, `avx2` or `avx512`) forces a level this machine runs.
    /// Read once.
    pub fn current() -> &'static SimdChoice {
        static CHOICE: OnceLock<SimdChoice> = OnceLock::new();
        CHOICE.get_or_init(|| Self::choose(std::env::var("GLINT_SIMD").ok().as_deref()))
    }

    /// The level for a `GLINT_SIMD` value (`None`: unset).
    ///
    /// The default is AVX2 wherever the machine has it, AVX-512 or not:
    /// the 8-lane AVX-512 build measured slower than the 4-lane AVX2 one on
    /// every workload of the "SIMD levels" table in docs/benchmarks.md (LLVM splits most
    /// of its lane loops into 256- and 128-bit halves anyway, and the
    /// packets' idle lanes pay the arithmetic too), so AVX-512 runs only
    /// when forced.
    pub fn choose(forced: Option<&str>) -> SimdChoice {
        let default = || {
            if SimdLevel::Avx2.is_available() {
                let reason = if SimdLevel::Avx512.is_available() {
                    "the default: this CPU also runs AVX-512, whose 8 lanes measured slower than \
                     AVX2's 4 (docs/benchmarks.md, \"SIMD levels\"); GLINT_SIMD=avx512 forces them"
                } else {
                    "the best this CPU runs (it has no AVX-512)"
                };
                (SimdLevel::Avx2, reason.to_string())
            } else {
                (
                    SimdLevel::Scalar,
                    "this CPU has neither AVX2 nor AVX-512: single rays".to_string(),
                )
            }
        };
        let (level, reason) = match forced.map(|v| (v, v.parse::<SimdLevel>())) {
            None | Some(("", _)) => default(),
            Some((v, Ok(level))) if level.is_available() => {
                (level, format!("forced by GLINT_SIMD={v}"))
            }
            Some((v, Ok(_))) => {
                let (level, reason) = default();
                (
                    level,
                    format!("GLINT_SIMD={v} asks for a level this CPU lacks; {reason}"),
                )
            }
            Some((v, Err(_))) => {
                let (level, reason) = default();
                (
                    level,
                    format!("GLINT_SIMD={v} is not a level (scalar, avx2, avx512); {reason}"),
                )
            }
        };
        SimdChoice { level, reason }
    }
}

impl std::str::FromStr for SimdLevel {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|l| l.name() == s)
            .ok_or_else(|| format!("unknown SIMD level `{s}` (expected scalar, avx2 or avx512)"))
    }
}

/// Work generic over the number of lanes, run by [`dispatch`].
pub trait LaneWork {
    type Output;
    /// Runs with `N` lanes; called inside a function compiled for the
    /// level's instruction set, so what it inlines uses it. `simd` compiles
    /// further functions for the same set ([`pulp::Simd::vectorize`]):
    /// work called from several places then exists once, not once per
    /// place it would be inlined into.
    fn run<S: pulp::Simd, const N: usize>(self, simd: S) -> Self::Output;
}

/// Runs `work` at `level`: with eight lanes under AVX-512, four under
/// AVX2. `None` at the scalar level or where the machine lacks the level:
/// the caller then takes its single-ray path. (A one-lane instance of the
/// packet kernel would never run, and compiling it costs as much as a
/// SIMD one.)
#[inline(always)]
pub fn dispatch<W: LaneWork>(level: SimdLevel, work: W) -> Option<W::Output> {
    match level {
        SimdLevel::Avx512 => {
            pulp::x86::V4::try_new().and_then(|simd| pulp::Simd::vectorize(simd, Lanes(work)))
        }
        SimdLevel::Avx2 => {
            pulp::x86::V3::try_new().and_then(|simd| pulp::Simd::vectorize(simd, Lanes(work)))
        }
        SimdLevel::Scalar => None,
    }
}

/// Whether coherent rays are traced in packets: yes unless the environment
/// variable `GLINT_PACKETS` is `off`, which traces every ray on its own at
/// the same SIMD level (to measure the single-ray walk on any workload;
/// the bytes are the same). Read once.
pub fn packets_enabled() -> bool {
    static ENABLED: OnceLock<bool> = OnceLock::new();
    *ENABLED.get_or_init(|| std::env::var("GLINT_PACKETS").map_or(true, |v| v != "off"))
}

/// Where single rays' queries run: in a function compiled for AVX2 when
/// the level has it (the wide walk's eight boxes then take one register),
/// in baseline x86-64 code otherwise. The token is taken once per render,
/// so a query pays a call, not a check of the CPU.
#[derive(Clone, Copy, Debug)]
pub struct SingleRays(Option<pulp::x86::V3>);

impl SingleRays {
    /// AVX2 at the AVX2 and AVX-512 levels (AVX-512's wider registers
    /// give a single ray nothing), baseline at the scalar level.
    pub fn at(level: SimdLevel) -> Self {
        Self(match level {
            SimdLevel::Scalar => None,
            SimdLevel::Avx2 | SimdLevel::Avx512 => pulp::x86::V3::try_new(),
        })
    }

    /// The AVX2 token single rays' work runs with (`None`: baseline).
    #[inline(always)]
    pub fn avx2(self) -> Option<pulp::x86::V3> {
        self.0
    }
}

/// Adapts [`LaneWork`] to pulp: the lane count is the instruction set's
/// number of `f64` lanes, and `run` is inlined into the function pulp
/// compiles for that instruction set.
struct Lanes<W>(W);

impl<W: LaneWork> pulp::WithSimd for Lanes<W> {
    type Output = Option<W::Output>;

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) -> Option<W::Output> {
        match S::F64_LANES {
            8 => Some(self.0.run::<S, 8>(simd)),
            4 => Some(self.0.run::<S, 4>(simd)),
            _ => None,
        }
    }
}

/// `N` lanes of `f64`.
pub type F64s<const N: usize> = [f64; N];

/// `[f64; N]` whose lane `i` is `expr`, built by a plain loop: it stays in
/// the function being compiled for the SIMD level, where the closures of
/// `std::array::from_fn` may be left out of line (and then compiled for
/// baseline x86-64, lane by lane).
macro_rules! lanes {
    ($n:expr, |$i:ident| $e:expr) => {{
        let mut out = [0.0f64; $n];
        for $i in 0..$n {
            out[$i] = $e;
        }
        out
    }};
}
pub(crate) use lanes;

/// `[x, y, z]` whose entry `k` is `expr`, written out (no closure).
macro_rules! per_axis {
    (|$k:ident| $e:expr) => {
        [
            {
                let $k = 0;
                $e
            },
            {
                let $k = 1;
                $e
            },
            {
                let $k = 2;
                $e
            },
        ]
    };
}
pub(crate) use per_axis;

#[inline(always)]
pub fn splat<const N: usize>(x: f64) -> F64s<N> {
    [x; N]
}

#[inline(always)]
pub fn map2<const N: usize>(a: F64s<N>, b: F64s<N>, f: impl Fn(f64, f64) -> f64) -> F64s<N> {
    lanes!(N, |i| f(a[i], b[i]))
}

/// The larger of `a` and `b` lane by lane, for values that are never NaN
/// (a plain comparison, which compiles to one vector instruction).
#[inline(always)]
pub fn max<const N: usize>(a: F64s<N>, b: F64s<N>) -> F64s<N> {
    lanes!(N, |i| if a[i] > b[i] { a[i] } else { b[i] })
}

/// The smaller of `a` and `b` lane by lane, for values that are never NaN.
#[inline(always)]
pub fn min<const N: usize>(a: F64s<N>, b: F64s<N>) -> F64s<N> {
    lanes!(N, |i| if a[i] < b[i] { a[i] } else { b[i] })
}

/// Lane `i` of the result is `a[i]` where bit `i` of `mask` is set, `b[i]`
/// elsewhere.
#[inline(always)]
pub fn select<const N: usize>(mask: u32, a: F64s<N>, b: F64s<N>) -> F64s<N> {
    lanes!(N, |i| if mask >> i & 1 == 1 { a[i] } else { b[i] })
}

/// Bit `i` set where `f(a[i], b[i])` holds (a vector compare and a
/// move-mask when `f` is a comparison).
#[inline(always)]
pub fn mask<const N: usize>(a: F64s<N>, b: F64s<N>, f: impl Fn(f64, f64) -> bool) -> u32 {
    let mut m = 0;
    for i in 0..N {
        m |= (f(a[i], b[i]) as u32) << i;
    }
    m
}

/// The lanes a mask of `N` lanes can hold.
#[inline(always)]
pub fn all_lanes<const N: usize>() -> u32 {
    if N >= 32 { u32::MAX } else { (1u32 << N) - 1 }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lane_helpers_compute_lane_by_lane() {
        let a = [1.0, -2.0, 3.0, f64::INFINITY];
        let b = [0.5, -3.0, 3.0, 1.0];
        assert_eq!(map2(a, b, |x, y| x.max(y)), [1.0, -2.0, 3.0, f64::INFINITY]);
        assert_eq!(mask(a, b, |x, y| x <= y), 0b0100);
        assert_eq!(select(0b1010, a, b), [0.5, -2.0, 3.0, f64::INFINITY]);
        assert_eq!(all_lanes::<4>(), 0b1111);
        assert_eq!(all_lanes::<1>(), 1);
    }

    #[test]
    fn levels_parse_and_the_best_is_available() {
        for level in SimdLevel::ALL {
            assert_eq!(level.name().parse::<SimdLevel>(), Ok(level));
        }
        assert!(SimdLevel::best().is_available());
        assert!(SimdLevel::Scalar.is_available());
        assert!(SimdLevel::current().is_available());
    }

    #[test]
    fn avx2_is_the_default_wherever_the_machine_has_it() {
        let default = SimdChoice::choose(None);
        let expected = if SimdLevel::Avx2.is_available() {
            SimdLevel::Avx2
        } else {
            SimdLevel::Scalar
        };
        assert_eq!(default.level, expected);
        assert_eq!(SimdChoice::choose(Some("")), default);
        // A forced level the machine runs is taken; scalar always is.
        let scalar = SimdChoice::choose(Some("scalar"));
        assert_eq!(scalar.level, SimdLevel::Scalar);
        assert!(
            scalar.reason.contains("GLINT_SIMD=scalar"),
            "{}",
            scalar.reason
        );
        for level in SimdLevel::ALL {
            let forced = SimdChoice::choose(Some(level.name()));
            if level.is_available() {
                assert_eq!(forced.level, level);
            } else {
                assert_eq!(forced.level, default.level);
                assert!(forced.reason.contains("lacks"), "{}", forced.reason);
            }
        }
        // Nonsense falls back to the default and says so.
        let bad = SimdChoice::choose(Some("avx9"));
        assert_eq!(bad.level, default.level);
        assert!(bad.reason.contains("not a level"), "{}", bad.reason);
    }
}
