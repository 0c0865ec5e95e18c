//! The scene as the renderer sees it: shapes, materials, lights, camera
//! and the image settings a file stores with them, and the errors of
//! reading one. The file formats build it; `mod.rs` only dispatches.

use std::path::PathBuf;
use std::sync::Arc;

use crate::accel::OctreeParams;
use crate::camera::CameraSpec;
use crate::color::ColorConvention;
use crate::material::{Light, Material};
use crate::math::{Aabb, Color, DVec3};
use crate::shapes::{Shape, Triangle};

use super::polygon::{DroppedPolygons, triangulate};

/// Which sides of a surface rays can hit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Sides {
    /// Every surface is seen from both sides (glint's default).
    #[default]
    Two,
    /// Opaque surfaces are seen from outside only, as the SPD allows (a
    /// ray meeting one from behind passes on). Transparent surfaces, and
    /// triangles with vertex normals (NFF `pp` patches, smooth meshes:
    /// tessellated open surfaces such as the SPD's teapot, which the SPD
    /// requires two-sided) stay two-sided.
    One,
}

impl Sides {
    pub const ALL: [Sides; 2] = [Sides::Two, Sides::One];

    pub fn name(self) -> &'static str {
        match self {
            Sides::Two => "two",
            Sides::One => "one",
        }
    }
}

impl std::str::FromStr for Sides {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|p| p.name() == s)
            .ok_or_else(|| format!("unknown sidedness `{s}` (expected one or two)"))
    }
}

/// Largest image side, pixel count and recursion depth glint accepts,
/// from a file, the command line or a record: beyond these a typo would
/// ask for gigabytes or recurse without end.
pub const MAX_IMAGE_SIDE: u32 = 1 << 15;
pub const MAX_PIXELS: u64 = 1 << 28;
pub const MAX_RAY_DEPTH: u32 = 64;

/// Image and recursion settings stored with a scene; command-line flags and
/// the viewer override them.
#[derive(Clone, Debug, PartialEq)]
pub struct ImageSettings {
    pub width: u32,
    pub height: u32,
    /// Rays per pixel: 1 (the pixel centre) or 16 (a regular 4x4 grid).
    pub samples: u32,
    /// Longest ray path, the eye ray counting as depth 1.
    pub max_depth: u32,
    pub background: Color,
    pub ambient: Color,
    /// How colours are shaded and written: linear (glint's TOML default)
    /// or display values (the NFF default).
    pub colors: ColorConvention,
    pub sides: Sides,
    /// With 16 samples: refine only where the picture shows an edge.
    pub adaptive: bool,
}

impl Default for ImageSettings {
    fn default() -> Self {
        Self {
            width: 640,
            height: 480,
            samples: 16,
            max_depth: 5,
            background: DVec3::ZERO,
            ambient: DVec3::splat(0.1),
            colors: ColorConvention::Linear,
            sides: Sides::Two,
            adaptive: false,
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub struct Scene {
    /// Where the scene came from, for messages and statistics.
    pub name: String,
    pub camera: CameraSpec,
    pub image: ImageSettings,
    pub octree_enabled: bool,
    pub octree_params: OctreeParams,
    pub materials: Vec<Material>,
    pub lights: Vec<Light>,
    /// Shapes and their material indices, side by side (structure of arrays:
    /// the intersection loop touches only `shapes`). The geometry is shared,
    /// not copied, when a scene is cloned: the viewer edits lights and
    /// materials of a scene the renderer still holds, and such an edit must
    /// not copy a million triangles.
    pub shapes: Arc<Vec<Shape>>,
    pub shape_materials: Arc<Vec<u32>>,
    /// Per-triangle vertex normals of smooth-shaded triangles.
    pub vertex_normals: Arc<Vec<[DVec3; 3]>>,
    /// Degenerate triangles dropped while loading (they could never be hit).
    pub dropped_triangles: usize,
    /// Polygons dropped while loading: zero area, or not simple.
    pub dropped_polygons: DroppedPolygons,
    /// What the file's colour numbers are: linear light (TOML) or display
    /// values (NFF); a render in the other convention converts them.
    pub color_values: ColorConvention,
    /// The text the scene was parsed from, kept for reproducible exports
    /// (empty for scenes built in code).
    pub source_text: Arc<str>,
}

impl Scene {
    /// A scene with no materials, lights or shapes yet.
    pub fn empty(name: String, camera: CameraSpec, image: ImageSettings) -> Self {
        Self {
            name,
            camera,
            image,
            octree_enabled: true,
            octree_params: OctreeParams::default(),
            materials: Vec::new(),
            lights: Vec::new(),
            shapes: Arc::default(),
            shape_materials: Arc::default(),
            vertex_normals: Arc::default(),
            dropped_triangles: 0,
            dropped_polygons: DroppedPolygons::default(),
            color_values: ColorConvention::Linear,
            source_text: Arc::from(""),
        }
    }

    pub fn push(&mut self, shape: Shape, material: u32) {
        Arc::make_mut(&mut self.shapes).push(shape);
        Arc::make_mut(&mut self.shape_materials).push(material);
    }

    /// Adds triangles (with optional per-triangle vertex normals), dropping
    /// degenerate ones.
    pub(crate) fn push_mesh(
        &mut self,
        triangles: Vec<[DVec3; 3]>,
        normals: Option<Vec<[DVec3; 3]>>,
        material: u32,
    ) {
        for (i, vertices) in triangles.into_iter().enumerate() {
            self.push_triangle(vertices, normals.as_ref().map(|n| n[i]), material);
        }
    }

    /// Adds one triangle, or counts it as dropped if it is degenerate.
    fn push_triangle(&mut self, vertices: [DVec3; 3], normals: Option<[DVec3; 3]>, material: u32) {
        let Some(mut t) = Triangle::new(vertices) else {
            self.dropped_triangles += 1;
            return;
        };
        if let Some(n) = normals
            && n.iter().all(|v| v.is_finite() && v.length_squared() > 0.0)
        {
            t.vertex_normals = self.vertex_normals.len() as u32;
            Arc::make_mut(&mut self.vertex_normals).push(n);
        }
        self.push(Shape::Triangle(t), material);
    }

    /// Adds a planar polygon (any simple outline, convex or not, either
    /// winding) as the triangles of its ear-clipping triangulation, with
    /// its vertex normals if given; a polygon of zero area or that is not
    /// simple is dropped and counted in [`Scene::dropped_polygons`].
    pub(crate) fn push_polygon(
        &mut self,
        vertices: &[DVec3],
        normals: Option<&[DVec3]>,
        material: u32,
    ) {
        match triangulate(vertices) {
            Ok(triangles) => {
                for t in triangles {
                    let [a, b, c] = t.map(|i| i as usize);
                    self.push_triangle(
                        [vertices[a], vertices[b], vertices[c]],
                        normals.map(|n| [n[a], n[b], n[c]]),
                        material,
                    );
                }
            }
            Err(defect) => self.dropped_polygons.record(defect),
        }
    }

    /// Bounds of every bounded shape, the lights and the eye: the region a
    /// user looks at and moves about in.
    pub fn extent_bounds(&self) -> Aabb {
        let mut b = self
            .geometry_bounds()
            .grow(self.camera.eye)
            .grow(self.camera.lookat);
        for light in &self.lights {
            b = b.grow(light.position);
        }
        b
    }

    /// Bounds of every bounded shape and a point of every plane: the
    /// magnitude of the surface points the renderer computes. (A light far
    /// away does not make them any less precise.)
    pub fn geometry_bounds(&self) -> Aabb {
        let mut b = Aabb::EMPTY;
        for shape in self.shapes.iter() {
            match shape {
                Shape::Plane(p) => b = b.grow(p.point),
                _ => {
                    if let Some(sb) = shape.bounds() {
                        b = b.union(sb);
                    }
                }
            }
        }
        b
    }

    /// Counts of shapes by kind, e.g. `[("sphere", 3), ("triangle", 12)]`.
    pub fn shape_counts(&self) -> Vec<(&'static str, usize)> {
        let mut counts: Vec<(&'static str, usize)> = Vec::new();
        for s in self.shapes.iter() {
            match counts.iter_mut().find(|(k, _)| *k == s.kind_name()) {
                Some((_, n)) => *n += 1,
                None => counts.push((s.kind_name(), 1)),
            }
        }
        counts
    }
}

/// Where in a scene file something went wrong.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Location {
    pub path: PathBuf,
    pub line: usize,
    pub column: usize,
    /// The key (TOML) or entity (NFF) at fault.
    pub key: String,
}

impl std::fmt::Display for Location {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}:{}:{}: `{}`",
            self.path.display(),
            self.line,
            self.column,
            self.key
        )
    }
}

#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    #[error("cannot read scene file {path}")]
    Io {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{path} is not UTF-8 text (first bad byte at offset {offset})")]
    NotUtf8 { path: PathBuf, offset: usize },
    #[error("{location}: {message}")]
    Invalid { location: Location, message: String },
    #[error("{location}: mesh {mesh}: {message}")]
    Mesh {
        location: Location,
        mesh: PathBuf,
        message: String,
    },
    #[error("{path}: unknown scene format (expected a .toml or .nff file)")]
    UnknownFormat { path: PathBuf },
}

/// Anti-aliasing, as the command line, the viewer and scene files name it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum AntiAliasing {
    /// One ray through each pixel's centre.
    #[default]
    Off,
    /// The centre everywhere, the 4x4 grid where neighbours differ.
    Adaptive,
    /// The regular 4x4 grid in every pixel.
    Full,
}

impl AntiAliasing {
    pub const ALL: [AntiAliasing; 3] = [
        AntiAliasing::Off,
        AntiAliasing::Adaptive,
        AntiAliasing::Full,
    ];

    pub fn name(self) -> &'static str {
        match self {
            AntiAliasing::Off => "off",
            AntiAliasing::Adaptive => "adaptive",
            AntiAliasing::Full => "full",
        }
    }
}

impl std::str::FromStr for AntiAliasing {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|a| a.name() == s)
            .ok_or_else(|| format!("unknown anti-aliasing `{s}` (expected off, adaptive or full)"))
    }
}

/// 1-based line and column of a byte offset.
pub(super) fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(text.len());
    let before = &text[..text.floor_char_boundary(offset)];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}
