//! The `--stats` object: what a render was asked for, what it counted and
//! how long it took.

use std::collections::BTreeMap;

use serde::Serialize;

use crate::accel::{BvhStats, OctreeParams, OctreeStats};
use crate::color::ColorConvention;
use crate::render::{Accelerator, RenderedFrame};
use crate::scene::{DroppedPolygons, MeshCounts, Scene, SkippedElements};
use crate::settings::{Accel, AntiAliasing, Protocol, RenderSettings, Sides, ViewMode};
use crate::stats::RayCounts;

/// The `--stats` object. Its field names are a public interface: add
/// fields, never rename or repurpose them.
#[derive(Clone, Debug, Serialize)]
pub struct RenderStats {
    pub scene: String,
    pub width: u32,
    pub height: u32,
    pub samples: u32,
    pub max_depth: u32,
    pub threads: usize,
    /// Whether the octree answered the ray queries.
    pub octree: bool,
    /// What answered them: `octree`, `bvh` or `none` (brute force).
    pub accel: &'static str,
    pub octree_params: OctreeParams,
    pub view: ViewMode,
    pub protocol: Protocol,
    pub colors: ColorConvention,
    pub sides: Sides,
    pub aa: AntiAliasing,
    /// Pixels the adaptive anti-aliasing refined with the full grid, and
    /// their share of the image (0 unless `aa` is adaptive).
    pub refined_pixels: u64,
    pub refined_fraction: f64,
    pub load_s: f64,
    pub build_s: f64,
    pub render_s: f64,
    pub rays: RaysJson,
    pub mrays_per_s: f64,
    pub intersection_tests_per_ray: f64,
    pub traversal_steps_per_ray: f64,
    pub leaves_visited_per_ray: f64,
    pub nonfinite_samples: u64,
    pub dropped_degenerate_triangles: usize,
    /// The shapes rendered, by kind (`triangle`, `sphere`, `plane`,
    /// `quadric`, `cone`; kinds the scene lacks are left out).
    pub shapes: BTreeMap<&'static str, usize>,
    /// Each mesh file: its path, triangles read, folded quads split, and
    /// what it dropped or skipped.
    pub meshes: Vec<MeshCounts>,
    /// Polygons dropped at load: of zero area, or not simple.
    pub dropped_polygons: DroppedPolygons,
    /// OBJ elements not rendered (lines, points, short faces, other
    /// statements), counted.
    pub skipped_elements: SkippedElements,
    /// MTL keys not rendered, with the number of materials using each.
    pub not_rendered: BTreeMap<String, usize>,
    /// What loading had to say (unreadable material libraries, undefined
    /// material names).
    pub load_notes: Vec<String>,
    /// The image textures the scene's materials use: each file, its size
    /// and the bytes its decoded copy holds (left out when there are none).
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub textures: Vec<TextureJson>,
    /// Whether textures were drawn (`--textures`).
    pub textures_drawn: bool,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub octree_stats: Option<OctreeStats>,
    /// With `--accel bvh`: what its build made (`build_s` is its build).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub bvh_stats: Option<BvhStats>,
    /// With `--view cost` or `cost-steps`: the per-pixel count's range.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cost_per_pixel: Option<CostJson>,
}

#[derive(Clone, Debug, Serialize)]
pub struct TextureJson {
    pub path: String,
    pub width: u32,
    pub height: u32,
    pub bytes: u64,
}

#[derive(Clone, Copy, Debug, Serialize)]
pub struct CostJson {
    pub min: f64,
    pub max: f64,
    pub mean: f64,
}

#[derive(Clone, Copy, Debug, Serialize)]
pub struct RaysJson {
    #[serde(flatten)]
    pub counts: RayCounts,
    pub total: u64,
}

/// The seconds the stages of a render took.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct RenderTimes {
    pub load_s: f64,
    pub build_s: f64,
    pub render_s: f64,
}

impl RenderStats {
    /// The statistics of `rendered`: `scene` (named `scene_name`, as the
    /// user gave it) rendered with `settings` on `threads` threads through
    /// `accel`. Its work counts are zero unless the frame was rendered
    /// with work counting on.
    pub fn new(
        scene_name: &str,
        scene: &Scene,
        settings: &RenderSettings,
        threads: usize,
        accel: &Accelerator,
        rendered: &RenderedFrame,
        times: RenderTimes,
    ) -> Self {
        let (frame, counts) = (&rendered.frame, &rendered.counts);
        let total = counts.rays.total();
        let per_ray = |x: u64| {
            if total > 0 {
                x as f64 / total as f64
            } else {
                0.0
            }
        };
        Self {
            scene: scene_name.to_owned(),
            width: settings.width,
            height: settings.height,
            samples: settings.samples,
            max_depth: settings.max_depth,
            threads,
            octree: settings.accel == Accel::Octree,
            accel: settings.accel.name(),
            octree_params: scene.octree_params,
            view: settings.view,
            protocol: settings.protocol,
            colors: settings.colors,
            sides: settings.sides,
            aa: settings.anti_aliasing(),
            refined_pixels: counts.refined_pixels,
            refined_fraction: counts.refined_pixels as f64
                / (settings.width as f64 * settings.height as f64),
            load_s: times.load_s,
            build_s: times.build_s,
            render_s: times.render_s,
            rays: RaysJson {
                counts: counts.rays,
                total,
            },
            mrays_per_s: total as f64 / times.render_s.max(1e-9) / 1e6,
            intersection_tests_per_ray: per_ray(counts.work.intersection_tests),
            traversal_steps_per_ray: per_ray(counts.work.traversal_steps),
            leaves_visited_per_ray: per_ray(counts.work.leaves_visited),
            nonfinite_samples: counts.nonfinite_samples,
            dropped_degenerate_triangles: scene.dropped_triangles,
            shapes: scene
                .shapes
                .iter()
                .fold(Default::default(), |mut by_kind, s| {
                    *by_kind.entry(s.kind().name()).or_default() += 1;
                    by_kind
                }),
            meshes: scene.meshes.clone(),
            dropped_polygons: scene.dropped_polygons,
            skipped_elements: scene.skipped_elements.clone(),
            not_rendered: scene.not_rendered.clone(),
            load_notes: scene.load_notes.clone(),
            textures: scene
                .textures
                .iter()
                .map(|t| TextureJson {
                    path: t.path.display().to_string(),
                    width: t.width,
                    height: t.height,
                    bytes: t.memory_bytes(),
                })
                .collect(),
            textures_drawn: settings.textures,
            octree_stats: accel.octree().map(|t| t.stats()),
            bvh_stats: accel.bvh().map(|t| t.stats()),
            cost_per_pixel: frame.cost_summary().map(|c| CostJson {
                min: c.min,
                max: c.max,
                mean: c.mean,
            }),
        }
    }
}
