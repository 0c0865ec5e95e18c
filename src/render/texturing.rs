//! What a render needs to draw textures, set up once per render: how it
//! shades texels and which materials cut their triangles out.

use crate::texture::TexelValues;

/// What a render needs to draw textures: which materials cut out, and how
/// it shades texels. `None` in a render without textures (or with them off).
pub(super) struct Texturing {
    pub values: TexelValues,
    /// Per material: whether it has a cut-out map.
    pub cuts: Vec<bool>,
    /// Whether any triangle with texture coordinates has such a material.
    pub any_cut: bool,
}

impl Texturing {
    /// `None` where `textures` is off or the scene has none.
    pub fn new(
        scene: &crate::scene::Scene,
        settings: &crate::settings::RenderSettings,
    ) -> Option<Self> {
        if !settings.textures || scene.textures.is_empty() {
            return None;
        }
        let cuts: Vec<bool> = scene
            .materials
            .iter()
            .map(|m| m.cutout_map.is_some())
            .collect();
        let any_cut = scene.shape_uvs.iter().enumerate().any(|(shape, &entry)| {
            entry != u32::MAX && cuts[scene.shape_materials[shape] as usize]
        });
        Some(Self {
            values: TexelValues::new(settings.colors),
            cuts,
            any_cut,
        })
    }

    /// Whether shape `shape` can be cut away somewhere: a triangle with
    /// texture coordinates and a cut-out material.
    pub fn cuts_shape(&self, scene: &crate::scene::Scene, shape: usize) -> bool {
        scene.shape_uvs.get(shape).is_some_and(|&e| e != u32::MAX)
            && self.cuts[scene.shape_materials[shape] as usize]
    }
}
