//! How far one image is from another: the error figures `glint study` and
//! the viewer report.

use crate::color::ColorConvention;
use crate::math::DVec3;

/// Root-mean-square error and PSNR of an image against a reference, in
/// shading values (linear light, or display values under
/// [`ColorConvention::Display`]) and as displayed (after the convention's
/// encoding: sRGB for linear frames), both on [0, 1] with channels clamped.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ImageError {
    pub rmse_shaded: f64,
    pub psnr_shaded: f64,
    pub rmse_display: f64,
    pub psnr_display: f64,
    /// Fraction of pixels differing by more than 1/255 as displayed.
    pub visible_fraction: f64,
}

pub fn image_error(a: &[DVec3], reference: &[DVec3], colors: ColorConvention) -> ImageError {
    let (mut shaded, mut display, mut visible) = (0.0, 0.0, 0usize);
    for (p, q) in a.iter().zip(reference) {
        let (p, q) = (
            p.clamp(DVec3::ZERO, DVec3::ONE),
            q.clamp(DVec3::ZERO, DVec3::ONE),
        );
        shaded += (p - q).length_squared();
        let d = colors.encode_rgb(p) - colors.encode_rgb(q);
        display += d.length_squared();
        if d.abs().max_element() > 1.0 / 255.0 {
            visible += 1;
        }
    }
    let n = (a.len() * 3).max(1) as f64;
    let (rs, rd) = ((shaded / n).sqrt(), (display / n).sqrt());
    let psnr = |r: f64| {
        if r > 0.0 {
            -20.0 * r.log10()
        } else {
            f64::INFINITY
        }
    };
    ImageError {
        rmse_shaded: rs,
        psnr_shaded: psnr(rs),
        rmse_display: rd,
        psnr_display: psnr(rd),
        visible_fraction: visible as f64 / a.len().max(1) as f64,
    }
}

/// The PSNR in dB of 8-bit image `a` against `reference`, over the colour
/// channels (the first three bytes of every `stride`-byte pixel: 3 for
/// RGB, 4 for RGBA); infinite for equal images.
pub fn psnr_8bit(a: &[u8], reference: &[u8], stride: usize) -> f64 {
    let (mut sum, mut n) = (0.0, 0usize);
    for (p, q) in a.chunks_exact(stride).zip(reference.chunks_exact(stride)) {
        for c in 0..3 {
            sum += (f64::from(p[c]) - f64::from(q[c])).powi(2);
        }
        n += 3;
    }
    if sum == 0.0 {
        return f64::INFINITY;
    }
    10.0 * (255.0f64.powi(2) * n as f64 / sum).log10()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn psnr_of_one_level_everywhere_is_that_of_255_to_1() {
        let a = [10u8, 20, 30, 255, 40, 50, 60, 255];
        let mut b = a.map(|v| v + 1);
        // The alpha byte does not count.
        b[3] = 0;
        b[7] = 7;
        let expected = 20.0 * 255.0f64.log10();
        assert!((psnr_8bit(&a, &b, 4) - expected).abs() < 1e-12);
        let rgb = [10u8, 20, 30, 40, 50, 60];
        assert!((psnr_8bit(&rgb, &rgb.map(|v| v - 1), 3) - expected).abs() < 1e-12);
        assert_eq!(psnr_8bit(&a, &a, 4), f64::INFINITY);
    }
}
