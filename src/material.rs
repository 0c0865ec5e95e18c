//! Whitted/Phong materials and point lights, colours in linear RGB.

use crate::math::{Color, DVec3};

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
