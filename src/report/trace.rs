//! The `--trace-pixel` object: the tree of rays one pixel's centre ray
//! spawns, each with its octree walk (schema in docs/inspection.md, "A
//! pixel's ray tree").

use crate::settings::Accel;
use serde::Serialize;

use crate::color::ColorConvention;
use crate::math::DVec3;
use crate::render::Renderer;
use crate::render::ray_tree::RayNode;
use crate::scene::Scene;
use crate::settings::{Protocol, RenderSettings, ViewMode};

/// The `--trace-pixel` object. Its field names are a public interface.
#[derive(Clone, Debug, Serialize)]
pub struct TraceReport {
    pub scene: String,
    pub pixel: [u32; 2],
    pub width: u32,
    pub height: u32,
    pub max_depth: u32,
    pub octree: bool,
    /// Under `spd` the tree is the pixel's top-left corner ray's.
    pub protocol: Protocol,
    pub colors: ColorConvention,
    /// The pixel's value at 1 sample (shading values) and as written to
    /// PNG (encoded by the colour convention; the name is historical).
    pub color: [f64; 3],
    pub srgb8: [u8; 3],
    pub lights: Vec<LightJson>,
    pub tree: RayNode,
}

#[derive(Clone, Copy, Debug, Serialize)]
pub struct LightJson {
    pub position: [f64; 3],
    pub color: [f64; 3],
}

/// A pixel asked for that the image does not have.
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
#[error("pixel {x},{y} is outside the {width}x{height} image")]
pub struct PixelOutside {
    pub x: u32,
    pub y: u32,
    pub width: u32,
    pub height: u32,
}

/// The settings a pixel's tree is traced with, from a frame's: one sample
/// (the centre ray) in the shaded view, so the root's colour is the
/// pixel's at 1 sample.
pub fn trace_settings(frame: RenderSettings) -> RenderSettings {
    RenderSettings {
        samples: 1,
        view: ViewMode::Shaded,
        ..frame
    }
}

impl TraceReport {
    /// Pixel `(x, y)`'s tree (counted from the top left, from 0), traced
    /// by `renderer`, whose settings are [`trace_settings`]'s, of `scene`
    /// (named `scene_name` as the user gave it).
    pub fn new(
        renderer: &Renderer,
        scene: &Scene,
        scene_name: &str,
        x: u32,
        y: u32,
    ) -> Result<Self, PixelOutside> {
        let settings = renderer.settings();
        if x >= settings.width || y >= settings.height {
            return Err(PixelOutside {
                x,
                y,
                width: settings.width,
                height: settings.height,
            });
        }
        let tree = renderer.ray_tree(x, y);
        let color = DVec3::from_array(tree.color);
        let srgb8 = [color.x, color.y, color.z].map(|c| settings.colors.byte(c));
        Ok(Self {
            scene: scene_name.to_owned(),
            pixel: [x, y],
            width: settings.width,
            height: settings.height,
            max_depth: settings.max_depth,
            octree: settings.accel == Accel::Octree,
            protocol: settings.protocol,
            colors: settings.colors,
            color: tree.color,
            srgb8,
            lights: scene
                .lights
                .iter()
                .map(|l| LightJson {
                    position: l.position.to_array(),
                    color: l.color.to_array(),
                })
                .collect(),
            tree,
        })
    }
}
