//! What the numbers of a scene's colours mean, and how a shaded value
//! becomes a pixel.
//!
//! glint's own scenes give colours in linear light: shading adds light
//! there, and the picture is encoded with the sRGB transfer function
//! (IEC 61966-2-1) at the end. The SPD's NFF scenes, and the pictures
//! published with them, treat colours as display values: shaded as they
//! are and written with no transfer function. Either convention can be
//! chosen for any scene; each format has its default.

use crate::math::{Color, DVec3};

/// How colours are shaded and written.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ColorConvention {
    /// Shade in linear light, write sRGB-encoded (glint's TOML scenes).
    #[default]
    Linear,
    /// Shade display values as they are, write them unchanged (the SPD's
    /// convention, the default for NFF scenes).
    Display,
}

impl ColorConvention {
    pub const ALL: [ColorConvention; 2] = [ColorConvention::Linear, ColorConvention::Display];

    pub fn name(self) -> &'static str {
        match self {
            ColorConvention::Linear => "linear",
            ColorConvention::Display => "display",
        }
    }

    /// A shaded value as it is displayed, in `[0, 1]`.
    #[inline]
    pub fn encode(self, x: f64) -> f64 {
        match self {
            ColorConvention::Linear => linear_to_srgb(x),
            ColorConvention::Display => x.clamp(0.0, 1.0),
        }
    }

    /// A shaded value as the 8-bit channel written for it: exactly
    /// `to_byte(self.encode(x))`, but a linear value is looked up among
    /// the 255 linear values at which the sRGB byte steps up (a bucket's
    /// start and a comparison or two instead of `powf` for every channel of
    /// every pixel).
    #[inline]
    pub fn byte(self, x: f64) -> u8 {
        match self {
            ColorConvention::Linear => srgb_byte(x),
            ColorConvention::Display => to_byte(x),
        }
    }

    /// [`ColorConvention::encode`] of each channel.
    #[inline]
    pub fn encode_rgb(self, c: Color) -> DVec3 {
        DVec3::new(self.encode(c.x), self.encode(c.y), self.encode(c.z))
    }

    /// The colour a scene file's value `c` shades as, when the file gives
    /// colours in `file` terms and the render uses `self`: display values
    /// are decoded into linear light for a linear render; nothing else
    /// changes (a display render shades the file's numbers as they are).
    pub fn shading_color(self, file: ColorConvention, c: Color) -> Color {
        match (file, self) {
            (ColorConvention::Display, ColorConvention::Linear) => DVec3::new(
                srgb_to_linear(c.x),
                srgb_to_linear(c.y),
                srgb_to_linear(c.z),
            ),
            _ => c,
        }
    }
}

impl std::str::FromStr for ColorConvention {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|c| c.name() == s)
            .ok_or_else(|| format!("unknown colour convention `{s}` (expected linear or display)"))
    }
}

/// sRGB transfer function (IEC 61966-2-1) of a linear value in `[0, 1]`.
pub fn linear_to_srgb(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// Inverse of [`linear_to_srgb`] on `[0, 1]`.
pub fn srgb_to_linear(x: f64) -> f64 {
    let x = x.clamp(0.0, 1.0);
    if x <= 0.040_45 {
        x / 12.92
    } else {
        ((x + 0.055) / 1.055).powf(2.4)
    }
}

/// A display value in `[0, 1]` as an 8-bit channel: `round(x * 255)`,
/// halves away from zero. Written with a truncating conversion because
/// `f64::round` is a library call on baseline x86-64 (no SSE4.1), dozens
/// of instructions per channel; for `y` in `[0, 255]` the fraction
/// `y - trunc(y)` is exact, so this is `round` bit for bit.
#[inline]
pub fn to_byte(x: f64) -> u8 {
    let y = x.clamp(0.0, 1.0) * 255.0;
    let whole = y as u32;
    (whole + (y - whole as f64 >= 0.5) as u32) as u8
}

/// Buckets of [`SrgbTable::start`]: a power of two, so `x * BUCKETS` is
/// exact and bucket `b` holds exactly the values in `[b, b + 1) / BUCKETS`.
const BUCKETS: usize = 4096;

/// The linear values at which the sRGB byte steps up, and where to start
/// counting them for each bucket of `[0, 1]`.
struct SrgbTable {
    /// `steps[k]`: the least linear value whose sRGB byte is at least `k`
    /// (`steps[0]` is unused).
    steps: [f64; 256],
    /// Per bucket, the steps at or below its lowest value: a value in the
    /// bucket has at least these and, the steps being more than a bucket
    /// apart (1/3,295 on sRGB's linear segment, wider above), one more at
    /// most.
    start: [u8; BUCKETS],
}

/// `to_byte(linear_to_srgb(x))` by table: the byte is the number of steps
/// at or below `x` (both are monotonic in `x`; NaN and values below the
/// first step give 0, as the formula does), counted from the bucket's
/// start instead of by eight comparisons of a bisection.
#[inline]
fn srgb_byte(x: f64) -> u8 {
    let table = srgb_table();
    // NaN and negative values saturate to bucket 0, values from 1 up to
    // the last bucket.
    let bucket = ((x * BUCKETS as f64) as usize).min(BUCKETS - 1);
    let mut k = table.start[bucket] as usize;
    while k < 255 && x >= table.steps[k + 1] {
        k += 1;
    }
    k as u8
}

#[cfg(test)]
fn srgb_steps() -> &'static [f64; 256] {
    &srgb_table().steps
}

/// The table, its steps found once by bisecting the doubles of [0, 1] in
/// their bit order with the formula itself, so it cannot disagree with it.
fn srgb_table() -> &'static SrgbTable {
    static TABLE: std::sync::OnceLock<SrgbTable> = std::sync::OnceLock::new();
    TABLE.get_or_init(|| {
        let byte = |bits: u64| to_byte(linear_to_srgb(f64::from_bits(bits)));
        let mut steps = [f64::NEG_INFINITY; 256];
        for (k, step) in steps.iter_mut().enumerate().skip(1) {
            // Least `bits` in [0, bits of 1.0] with byte >= k: byte(1.0)
            // is 255, so one exists.
            let (mut lo, mut hi) = (0u64, 1.0f64.to_bits());
            while lo < hi {
                let mid = lo + (hi - lo) / 2;
                if byte(mid) as usize >= k {
                    hi = mid;
                } else {
                    lo = mid + 1;
                }
            }
            *step = f64::from_bits(lo);
        }
        let mut start = [0u8; BUCKETS];
        let mut k = 0;
        for (b, first) in start.iter_mut().enumerate() {
            let lowest = b as f64 / BUCKETS as f64;
            while k < 255 && steps[k + 1] <= lowest {
                k += 1;
            }
            *first = k as u8;
        }
        SrgbTable { steps, start }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The table gives the formula's byte everywhere: at, just below and
    /// just above every step, on a fine grid, and for values outside
    /// [0, 1], infinities and NaN.
    #[test]
    fn the_srgb_table_is_the_formula_bit_for_bit() {
        let formula = |x: f64| to_byte(linear_to_srgb(x));
        let mut cases = vec![
            f64::NAN,
            -f64::NAN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            -0.0,
            0.0,
        ];
        cases.extend([-1.0, 1.0, 1.5, f64::MIN_POSITIVE, 5e-324, 1e-300]);
        for &step in &srgb_steps()[1..] {
            let bits = step.to_bits();
            cases.extend((bits.saturating_sub(3)..=bits + 3).map(f64::from_bits));
        }
        cases.extend((0..=100_000).map(|k| k as f64 / 100_000.0));
        // Every bucket's edges.
        for b in 0..=BUCKETS {
            let edge = b as f64 / BUCKETS as f64;
            cases.extend([edge.next_down(), edge, edge.next_up()]);
        }
        for x in cases {
            assert_eq!(ColorConvention::Linear.byte(x), formula(x), "x = {x:e}");
            assert_eq!(ColorConvention::Display.byte(x), to_byte(x), "x = {x:e}");
        }
        // No bucket holds two steps past its start (the loop takes at most
        // one more step).
        let table = srgb_table();
        for b in 0..BUCKETS {
            let (lo, hi) = (b as f64 / BUCKETS as f64, (b + 1) as f64 / BUCKETS as f64);
            let inside = steps_in(&table.steps, lo, hi);
            assert!(inside <= 1, "bucket {b}: {inside} steps inside");
        }
        // Monotonic steps, each a real step of the formula.
        let steps = srgb_steps();
        for k in 1..256 {
            assert!(steps[k] > steps[k - 1], "{k}");
            assert_eq!(formula(steps[k]) as usize, k);
            assert_eq!(formula(steps[k].next_down()) as usize, k - 1);
        }
    }

    fn steps_in(steps: &[f64; 256], lo: f64, hi: f64) -> usize {
        steps[1..].iter().filter(|&&s| s > lo && s < hi).count()
    }

    #[test]
    fn to_byte_rounds_as_f64_round_does() {
        let mut cases = vec![-1.0, 0.0, 1.0, 2.0, f64::NAN, 0.5 / 255.0, 254.5 / 255.0];
        for k in 0..=255 * 8 {
            let y = k as f64 / 8.0;
            for v in [y, y.next_up(), y.next_down()] {
                cases.push(v / 255.0);
            }
        }
        for x in cases {
            let expected = (x.clamp(0.0, 1.0) * 255.0).round() as u8;
            assert_eq!(to_byte(x), expected, "x = {x:e}");
        }
    }

    #[test]
    fn srgb_round_trips_and_hits_known_values() {
        for k in 0..=100 {
            let x = k as f64 / 100.0;
            assert!((srgb_to_linear(linear_to_srgb(x)) - x).abs() < 1e-12);
        }
        // 18% grey is about 46% in sRGB; sRGB 0.5 is 21.4% linear.
        assert!((linear_to_srgb(0.18) - 0.4614).abs() < 1e-3);
        assert!((srgb_to_linear(0.5) - 0.2140).abs() < 1e-3);
    }

    #[test]
    fn display_convention_writes_values_unchanged() {
        let c = DVec3::new(0.25, 0.5, 1.5);
        assert_eq!(
            ColorConvention::Display.encode_rgb(c),
            DVec3::new(0.25, 0.5, 1.0)
        );
        let file = ColorConvention::Display;
        assert_eq!(ColorConvention::Display.shading_color(file, c), c);
        let linear = ColorConvention::Linear.shading_color(file, DVec3::splat(0.5));
        assert!((linear.x - 0.2140).abs() < 1e-3);
        // Linear files shade as given under either convention.
        assert_eq!(
            ColorConvention::Display.shading_color(ColorConvention::Linear, c),
            c
        );
    }
}
