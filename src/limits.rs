//! Every limit glint holds its inputs to, in one place: scene files, the
//! command line, the viewer and the records inside exported PNGs all check
//! against these, so what one path writes every other path reads.
//!
//! The ranges are wide: they exist so that a typo cannot ask for gigabytes,
//! recurse without end or overflow a pixel, not to second-guess a scene.

use std::ops::RangeInclusive;

use crate::math::DVec3;

/// Largest image side, pixel count and recursion depth glint accepts:
/// beyond these a typo would ask for gigabytes or recurse without end.
pub const MAX_IMAGE_SIDE: u32 = 1 << 15;
pub const MAX_PIXELS: u64 = 1 << 28;
pub const MAX_RAY_DEPTH: u32 = 64;

/// Most render threads per core: more only add switching, which grows
/// without bound (docs/notes/experiments.md, "Figures behind constants").
pub const MAX_THREADS_PER_CORE: usize = 8;

/// Largest image side the viewer renders: it keeps several frames of this
/// size (display, passes, compare) in memory at once and draws them as
/// textures; larger images are for `glint render`.
pub const MAX_VIEWER_SIDE: u32 = 8192;

/// Smallest viewer window, in points: below it the panels cannot show.
pub const MIN_WINDOW: (u32, u32) = (480, 320);

/// Largest side of the regular sample grid in a pixel (16x16 = 256 rays):
/// scene files and the command line offer 1 and 16 samples; the study also
/// measures 4, 64 and 256.
pub const MAX_GRID_SIDE: u32 = 16;

/// Deepest octree level glint builds: 2^21 cells per axis is far below
/// any useful resolution and keeps the traversal stack small.
pub const MAX_OCTREE_DEPTH: u32 = 21;

/// Largest octree leaf size a scene file gives: far above any useful
/// leaf (the default is 4).
pub const MAX_LEAF_SIZE: u32 = 1_000_000;

/// The octree overlay's deepest level unless one is asked for (the
/// command line and the viewer alike).
pub const DEFAULT_OVERLAY_DEPTH: u32 = 4;

/// The octree's duplication limit: its children may hold at most this many
/// times a node's references (8 never stops a split: eight children hold at
/// most 8x).
pub const MAX_DUPLICATION_RANGE: RangeInclusive<u32> = 1..=8;

/// Largest octree memory budget: references are 31-bit counts and 32-bit
/// indices.
pub const MAX_MEMORY_BUDGET_MIB: u32 = 4096;

/// Surface colours and the weights `kd`, `ks`, `reflectivity` and
/// `transparency`: a surface sends on at most what it receives.
pub const UNIT_RANGE: RangeInclusive<f64> = 0.0..=1.0;
/// Light colours, the ambient light and the background: intensities, which
/// may exceed 1 (the picture then clips).
pub const INTENSITY_RANGE: RangeInclusive<f64> = 0.0..=1000.0;
/// The Phong exponent (the SPD's scenes use 100,000 for "no highlight").
pub const SHININESS_RANGE: RangeInclusive<f64> = 0.0..=1.0e6;
/// Index of refraction of a surface's inside (below 1: a bubble).
pub const IOR_RANGE: RangeInclusive<f64> = 0.01..=100.0;

// Within these ranges no pixel can overflow: a hit adds at most
// 1000 (ambient) + 2000 per light, and each of at most 64 recursion levels
// at most doubles it (reflectivity + transparency <= 2).

/// A setting outside its limit.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum LimitError {
    #[error(
        "an image of {0}x{1} pixels is outside the limits: glint renders at most {max} pixels \
         ({side} on a side, at least 1)",
        max = MAX_PIXELS,
        side = MAX_IMAGE_SIDE
    )]
    ImageSize(u32, u32),
    #[error(
        "samples must be a square grid of 1 to {max} rays (1, 4, 9, 16, ...), got {0}",
        max = MAX_GRID_SIDE * MAX_GRID_SIDE
    )]
    Samples(u32),
    #[error("max depth {0} is outside 1..={MAX_RAY_DEPTH}")]
    MaxDepth(u32),
    #[error("octree max depth {0} is above {MAX_OCTREE_DEPTH}")]
    OctreeDepth(u32),
    #[error("octree leaf size must be at least 1")]
    LeafSize,
    #[error("octree max duplication {0} is outside 1..=8")]
    MaxDuplication(u32),
    #[error("octree memory budget {0} MiB is outside 1..={MAX_MEMORY_BUDGET_MIB}")]
    MemoryBudget(u32),
    #[error("overlay depth {0} is above the octree's limit of {MAX_OCTREE_DEPTH}")]
    OverlayDepth(u32),
}

/// An image of `width` x `height` pixels.
pub fn check_image_size(width: u32, height: u32) -> Result<(), LimitError> {
    if width == 0
        || height == 0
        || width.max(height) > MAX_IMAGE_SIDE
        || width as u64 * height as u64 > MAX_PIXELS
    {
        return Err(LimitError::ImageSize(width, height));
    }
    Ok(())
}

/// Rays per pixel on a square grid.
pub fn check_samples(samples: u32) -> Result<(), LimitError> {
    let side = (samples as f64).sqrt().round() as u32;
    if samples == 0 || side * side != samples || side > MAX_GRID_SIDE {
        return Err(LimitError::Samples(samples));
    }
    Ok(())
}

/// The longest ray path (the eye ray is depth 1).
pub fn check_max_depth(depth: u32) -> Result<(), LimitError> {
    if !(1..=MAX_RAY_DEPTH).contains(&depth) {
        return Err(LimitError::MaxDepth(depth));
    }
    Ok(())
}

/// A number as people write it: `1e300` rather than its 301 digits.
pub fn format_number(x: f64) -> String {
    if x != 0.0 && x.is_finite() && !(1e-4..1e7).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// A finite number, or why not (scene files' wording).
pub fn check_finite(x: f64) -> Result<f64, String> {
    if x.is_finite() {
        Ok(x)
    } else {
        Err(format!("must be a finite number, got {x}"))
    }
}

/// Three finite numbers, or why not.
pub fn check_finite_vec3(p: DVec3) -> Result<DVec3, String> {
    if p.is_finite() {
        Ok(p)
    } else {
        Err(format!("must be three finite numbers, got {p}"))
    }
}

/// A whole number in `range`, or why not.
pub fn check_integer(x: i64, range: &RangeInclusive<i64>) -> Result<u32, String> {
    match u32::try_from(x) {
        Ok(n) if range.contains(&x) => Ok(n),
        _ => Err(format!(
            "must be an integer from {} to {}, got {x}",
            range.start(),
            range.end()
        )),
    }
}

/// Why a value is out of its range, e.g. "must lie in [0, 1], got 2".
pub fn check_range(x: f64, range: &RangeInclusive<f64>) -> Result<f64, String> {
    if range.contains(&x) {
        Ok(x)
    } else {
        Err(format!(
            "must lie in [{}, {}], got {}",
            range.start(),
            range.end(),
            format_number(x)
        ))
    }
}

/// Like [`check_range`] for each component of a colour.
pub fn check_color(c: DVec3, range: &RangeInclusive<f64>) -> Result<DVec3, String> {
    if c.to_array().iter().all(|x| range.contains(x)) {
        Ok(c)
    } else {
        Err(format!(
            "each component must lie in [{}, {}], got [{}, {}, {}]",
            range.start(),
            range.end(),
            format_number(c.x),
            format_number(c.y),
            format_number(c.z)
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn image_sizes_at_and_past_each_limit() {
        assert!(check_image_size(1, 1).is_ok());
        assert!(check_image_size(MAX_IMAGE_SIDE, 1).is_ok());
        assert!(check_image_size(0, 5).is_err());
        assert!(check_image_size(MAX_IMAGE_SIDE + 1, 1).is_err());
        // Both sides within the limit, the pixel count past it.
        assert!(check_image_size(MAX_IMAGE_SIDE, MAX_IMAGE_SIDE).is_err());
        assert!(
            check_image_size(MAX_IMAGE_SIDE, (MAX_PIXELS / MAX_IMAGE_SIDE as u64) as u32).is_ok()
        );
    }

    #[test]
    fn samples_are_square_grids_up_to_sixteen_a_side() {
        let accepted: Vec<u32> = (0..=300).filter(|&n| check_samples(n).is_ok()).collect();
        let squares: Vec<u32> = (1..=16).map(|k| k * k).collect();
        assert_eq!(accepted, squares);
    }

    #[test]
    fn ranges_name_what_they_got() {
        assert_eq!(
            check_range(2.0, &UNIT_RANGE).unwrap_err(),
            "must lie in [0, 1], got 2"
        );
        assert_eq!(format_number(1e300), "1e300");
        assert!(check_color(DVec3::new(0.0, 0.5, 1.0), &UNIT_RANGE).is_ok());
        assert!(check_color(DVec3::new(0.0, f64::NAN, 1.0), &UNIT_RANGE).is_err());
    }
}
