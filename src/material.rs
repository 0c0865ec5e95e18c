//! Whitted/Phong materials and point lights, colours in linear RGB.

use std::ops::RangeInclusive;

use crate::math::{Color, DVec3};

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

/// A number as people write it: `1e300` rather than its 301 digits.
pub fn format_number(x: f64) -> String {
    if x != 0.0 && x.is_finite() && !(1e-4..1e7).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
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

#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Material {
    pub name: String,
    pub color: Color,
    /// Weight of the ambient term: 1 in glint's own scenes (the local term
    /// is `ambient * color`); NFF scenes set it to their Kd, as SPD renderers
    /// weight ambient light by the diffuse coefficient.
    pub ka: f64,
    /// Diffuse weight of the Lambert term.
    pub kd: f64,
    /// Weight of the Phong highlight.
    pub ks: f64,
    /// Phong exponent of the highlight.
    pub shininess: f64,
    /// Weight of the mirror-reflected ray.
    pub reflectivity: f64,
    /// Weight of the refracted ray; also how much light a shadow ray lets through.
    pub transparency: f64,
    /// Index of refraction of the inside of the surface (outside is 1).
    pub ior: f64,
}

impl Material {
    /// Every value in its documented range, or the first that is not.
    pub fn validate(&self) -> Result<(), String> {
        let field = |name: &str, r: Result<f64, String>| r.map_err(|e| format!("{name} {e}"));
        check_color(self.color, &UNIT_RANGE).map_err(|e| format!("color: {e}"))?;
        for (name, value) in [
            ("ka", self.ka),
            ("kd", self.kd),
            ("ks", self.ks),
            ("reflectivity", self.reflectivity),
            ("transparency", self.transparency),
        ] {
            field(name, check_range(value, &UNIT_RANGE))?;
        }
        field("shininess", check_range(self.shininess, &SHININESS_RANGE))?;
        field("ior", check_range(self.ior, &IOR_RANGE))?;
        Ok(())
    }
}

impl Light {
    /// A finite position and a colour in [`INTENSITY_RANGE`].
    pub fn validate(&self) -> Result<(), String> {
        if !self.position.is_finite() {
            return Err("position must be finite".into());
        }
        check_color(self.color, &INTENSITY_RANGE).map_err(|e| format!("color: {e}"))?;
        Ok(())
    }
}

impl Default for Material {
    fn default() -> Self {
        Self {
            name: "default".into(),
            color: DVec3::splat(0.8),
            ka: 1.0,
            kd: 0.8,
            ks: 0.0,
            shininess: 32.0,
            reflectivity: 0.0,
            transparency: 0.0,
            ior: 1.5,
        }
    }
}

/// Point light with no distance falloff, as in the classic Whitted model.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Light {
    pub position: DVec3,
    pub color: Color,
}
