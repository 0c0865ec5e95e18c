//! Whitted/Phong materials and point lights, colours in linear RGB.

use crate::limits::{
    INTENSITY_RANGE, IOR_RANGE, SHININESS_RANGE, UNIT_RANGE, check_color, check_range,
};
use crate::math::{Color, DVec3};
use crate::texture::TextureMap;

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
    /// The texture whose colour multiplies `color` (MTL's `map_Kd`, a TOML
    /// material's `texture`) on shapes with texture coordinates.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub color_map: Option<TextureMap>,
    /// The texture that cuts the surface away where its alpha (MTL's
    /// `map_d`: its value) is below one half: eye and shadow rays pass
    /// there, as through the gaps of a leaf or a fence.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub cutout_map: Option<TextureMap>,
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
            color_map: None,
            cutout_map: None,
        }
    }
}

/// Point light with no distance falloff, as in the classic Whitted model.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Light {
    pub position: DVec3,
    pub color: Color,
}
