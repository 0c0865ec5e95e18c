//! The scene as the renderer sees it: shapes, materials, lights, camera
//! and the image settings a file stores with them, and the errors of
//! reading one. The file formats build it; `mod.rs` only dispatches.

use crate::settings::Accel;
use std::path::PathBuf;
use std::sync::Arc;

use crate::accel::{LightBuffer, Octree, OctreeError, OctreeParams};
use crate::camera::CameraSpec;
use crate::color::ColorConvention;
use crate::material::{Light, Material};
use crate::math::{Aabb, Color, DVec3};
use crate::settings::{Protocol, RenderSettings, Sides, ViewMode};
use crate::shapes::{Shape, Triangle, unit_or_none};

use super::obj::SkippedElements;
use super::polygon::{DroppedPolygons, triangulate};

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
            samples: crate::settings::AntiAliasing::SAMPLES,
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
    /// The camera path a TOML scene's `[[camera.keyframes]]` give, if any.
    pub camera_path: Option<crate::camera_path::CameraPath>,
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
    /// Per-triangle vertex normals of smooth-shaded triangles, unit length.
    pub vertex_normals: Arc<Vec<[DVec3; 3]>>,
    /// Per-triangle vertex colours (an OBJ's `v x y z r g b`), in [0, 1].
    pub vertex_colors: Arc<Vec<[DVec3; 3]>>,
    /// For each shape, its entry in `vertex_colors` (`u32::MAX`: none;
    /// shapes past the end have none): the colour replaces the material's
    /// diffuse colour, interpolated across the face.
    pub shape_colors: Arc<Vec<u32>>,
    /// Per-triangle texture coordinates (an OBJ's `vt`, a TOML triangle's
    /// `uvs`), for the materials' textures.
    pub vertex_uvs: Arc<Vec<[[f64; 2]; 3]>>,
    /// For each shape, its entry in `vertex_uvs` (`u32::MAX`: none; shapes
    /// past the end have none): a shape without one is drawn untextured.
    pub shape_uvs: Arc<Vec<u32>>,
    /// The images materials' texture maps name, each file decoded once.
    pub textures: Vec<Arc<crate::texture::Texture>>,
    /// Degenerate triangles dropped while loading (they could never be hit).
    pub dropped_triangles: usize,
    /// Polygons dropped while loading: zero area, or not simple.
    pub dropped_polygons: DroppedPolygons,
    /// OBJ elements glint does not render (lines, points, curves, faces
    /// with fewer than three distinct vertices), counted.
    pub skipped_elements: SkippedElements,
    /// MTL keywords glint does not render (texture maps, bump, emission),
    /// with the number of materials that use each.
    pub not_rendered: std::collections::BTreeMap<String, usize>,
    /// What loading had to tell the user (a material library that could
    /// not be read, a material no library defines), once each.
    pub load_notes: Vec<String>,
    /// What the file's colour numbers are: linear light (TOML) or display
    /// values (NFF); a render in the other convention converts them.
    pub color_values: ColorConvention,
    /// The text the scene was parsed from, kept for reproducible exports
    /// (empty for scenes built in code).
    pub source_text: Arc<str>,
    /// Which materials a TOML scene's meshes brought from their MTL files:
    /// "Save scene" writes edits to them into the mesh object.
    pub mesh_material_origins: Vec<MeshMaterialOrigin>,
    /// The files besides its text the scene was built from (meshes, MTL
    /// libraries), with their SHA-256, in the order read.
    pub files_read: Vec<super::file_source::FileRead>,
    /// What each mesh file gave, in the order loaded.
    pub meshes: Vec<MeshCounts>,
}

/// What one mesh file gave: triangles loaded, and what was not.
#[derive(Clone, Debug, Default, PartialEq, Eq, serde::Serialize)]
pub struct MeshCounts {
    pub path: String,
    pub triangles: usize,
    /// Self-crossing quads split into their two triangles.
    pub folded_quads: usize,
    pub dropped_polygons: DroppedPolygons,
    pub skipped_elements: SkippedElements,
    /// The header comment the file opens with (the exporter, usually).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub header: Option<String>,
}

/// A material a mesh object of a TOML scene took from its own file.
#[derive(Clone, Debug, PartialEq)]
pub struct MeshMaterialOrigin {
    /// Index into [`Scene::materials`].
    pub material: u32,
    /// Index of the object in the file's `objects`.
    pub object: usize,
    /// Its name in the mesh's MTL file (`default` for faces with none),
    /// the key under the object's `materials`.
    pub name: String,
}

impl Scene {
    /// The scene's accelerator: an octree over its shapes with the scene's
    /// own parameters (the one place a scene's octree is built; callers
    /// that vary the parameters build with [`Octree::build`]).
    pub fn build_octree(&self) -> Result<Octree, OctreeError> {
        Octree::build(&self.shapes, self.octree_params)
    }

    /// The light buffer of this scene's lights over its shapes, for
    /// [`crate::render::Accelerator::build`]; `None` without
    /// lights or for a scene too large to project quickly.
    pub fn build_light_buffer(&self) -> Option<LightBuffer> {
        let lights: Vec<_> = self.lights.iter().map(|l| l.position).collect();
        LightBuffer::build(&self.shapes, &lights)
    }

    /// The settings the scene file asks for: its image size, samples,
    /// depth, colours and sides, the octree switch; glint's protocol and the
    /// shaded view. Command-line flags and the viewer override them.
    pub fn render_settings(&self) -> RenderSettings {
        RenderSettings {
            width: self.image.width,
            height: self.image.height,
            samples: self.image.samples,
            max_depth: self.image.max_depth,
            accel: Accel::from_octree_switch(self.octree_enabled),
            view: ViewMode::Shaded,
            protocol: Protocol::Glint,
            colors: self.image.colors,
            sides: self.image.sides,
            adaptive: self.image.adaptive,
            shadows: true,
            textures: true,
        }
    }

    /// A scene with no materials, lights or shapes yet.
    pub fn empty(name: String, camera: CameraSpec, image: ImageSettings) -> Self {
        Self {
            name,
            camera,
            camera_path: None,
            image,
            octree_enabled: true,
            octree_params: OctreeParams::default(),
            materials: Vec::new(),
            lights: Vec::new(),
            shapes: Arc::default(),
            shape_materials: Arc::default(),
            vertex_normals: Arc::default(),
            vertex_colors: Arc::default(),
            shape_colors: Arc::default(),
            vertex_uvs: Arc::default(),
            shape_uvs: Arc::default(),
            textures: Vec::new(),
            dropped_triangles: 0,
            dropped_polygons: DroppedPolygons::default(),
            skipped_elements: SkippedElements::default(),
            not_rendered: Default::default(),
            load_notes: Vec::new(),
            color_values: ColorConvention::Linear,
            source_text: Arc::from(""),
            mesh_material_origins: Vec::new(),
            files_read: Vec::new(),
            meshes: Vec::new(),
        }
    }

    /// What loading dropped, skipped or could not read, one sentence each,
    /// for the command line's notes and the viewer's messages.
    pub fn notes(&self) -> Vec<String> {
        let mut notes = Vec::new();
        if self.shapes.is_empty() {
            notes.push("the scene has no objects: the picture is its background".into());
        }
        if self.lights.is_empty() {
            notes.push("the scene has no lights: surfaces get the ambient term only".into());
        }
        if self.dropped_triangles > 0 {
            notes.push(format!(
                "{} degenerate triangles were skipped",
                self.dropped_triangles
            ));
        }
        let dropped = self.dropped_polygons;
        if dropped.total() > 0 {
            notes.push(format!(
                "{} polygons were skipped ({} with crossing edges, {} with no area)",
                dropped.total(),
                dropped.not_simple,
                dropped.zero_area
            ));
        }
        notes.extend(self.load_notes.iter().cloned());
        if !self.not_rendered.is_empty() {
            let listed: Vec<String> = self
                .not_rendered
                .iter()
                .map(|(k, n)| format!("{k} ({n} material{})", if *n == 1 { "" } else { "s" }))
                .collect();
            notes.push(format!(
                "glint does not render these material keys: {}",
                listed.join(", ")
            ));
        }
        let skipped = &self.skipped_elements;
        let mut parts = Vec::new();
        for (n, what) in [
            (skipped.lines, "lines (l)"),
            (skipped.points, "points (p)"),
            (
                skipped.short_faces,
                "faces with fewer than 3 distinct vertices",
            ),
        ] {
            if n > 0 {
                parts.push(format!("{n} {what}"));
            }
        }
        for (k, n) in &skipped.statements {
            parts.push(format!("{n} `{k}` statements"));
        }
        if !parts.is_empty() {
            notes.push(format!("OBJ elements skipped: {}", parts.join(", ")));
        }
        if skipped.faces_with_missing_normals > 0 {
            notes.push(format!(
                "{} OBJ faces refer to normals the file does not have; they are shaded without them",
                skipped.faces_with_missing_normals
            ));
        }
        if skipped.faces_with_repeated_vertices > 0 {
            notes.push(format!(
                "{} OBJ faces listed a vertex more than once; the repeats were removed",
                skipped.faces_with_repeated_vertices
            ));
        }
        notes
    }

    pub fn push(&mut self, shape: Shape, material: u32) {
        Arc::make_mut(&mut self.shapes).push(shape);
        Arc::make_mut(&mut self.shape_materials).push(material);
    }

    /// Adds triangles (with optional per-triangle vertex normals, colours
    /// and texture coordinates), each with the material `material(i)`,
    /// dropping degenerate ones.
    pub(crate) fn push_mesh(
        &mut self,
        triangles: Vec<[DVec3; 3]>,
        normals: Option<Vec<[DVec3; 3]>>,
        colors: &[Option<[DVec3; 3]>],
        uvs: &[Option<[[f64; 2]; 3]>],
        material: impl Fn(usize) -> u32,
    ) {
        for (i, vertices) in triangles.into_iter().enumerate() {
            let before = self.shapes.len();
            self.push_triangle(vertices, normals.as_ref().map(|n| n[i]), material(i));
            if self.shapes.len() == before {
                continue;
            }
            if let Some(Some(c)) = colors.get(i) {
                let shape_colors = Arc::make_mut(&mut self.shape_colors);
                shape_colors.resize(before, u32::MAX);
                shape_colors.push(self.vertex_colors.len() as u32);
                Arc::make_mut(&mut self.vertex_colors).push(*c);
            }
            if let Some(Some(uv)) = uvs.get(i) {
                self.set_uvs(before, *uv);
            }
        }
    }

    /// Gives shape `shape` (a triangle) the texture coordinates `uv` of
    /// its three corners.
    pub(crate) fn set_uvs(&mut self, shape: usize, uv: [[f64; 2]; 3]) {
        let shape_uvs = Arc::make_mut(&mut self.shape_uvs);
        shape_uvs.resize(shape.max(shape_uvs.len()), u32::MAX);
        let entry = self.vertex_uvs.len() as u32;
        match shape_uvs.get_mut(shape) {
            Some(slot) => *slot = entry,
            None => shape_uvs.push(entry),
        }
        Arc::make_mut(&mut self.vertex_uvs).push(uv);
    }

    /// Bytes the decoded textures hold.
    pub fn texture_bytes(&self) -> u64 {
        self.textures.iter().map(|t| t.memory_bytes()).sum()
    }

    /// The texture coordinates of triangle `shape` at barycentric
    /// coordinates `(b1, b2)`, if it has them.
    #[inline]
    pub fn uv_at(&self, shape: u32, b1: f64, b2: f64) -> Option<[f64; 2]> {
        let &entry = self.shape_uvs.get(shape as usize)?;
        let [t0, t1, t2] = self.vertex_uvs.get(entry as usize)?;
        let b0 = 1.0 - b1 - b2;
        Some([
            b0 * t0[0] + b1 * t1[0] + b2 * t2[0],
            b0 * t0[1] + b1 * t1[1] + b2 * t2[1],
        ])
    }

    /// Adds one triangle, or counts it as dropped if it is degenerate.
    fn push_triangle(&mut self, vertices: [DVec3; 3], normals: Option<[DVec3; 3]>, material: u32) {
        let Some(mut t) = Triangle::new(vertices) else {
            self.dropped_triangles += 1;
            return;
        };
        // Stored as unit vectors: shading reads them at every hit
        // (Triangle::smooth_point needs each one unit) and normalizing
        // once here spares three square roots and divisions per hit.
        if let Some([Some(a), Some(b), Some(c)]) = normals.map(|n| n.map(unit_or_none)) {
            let n = [a, b, c];
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
            match counts.iter_mut().find(|(k, _)| *k == s.kind().name()) {
                Some((_, n)) => *n += 1,
                None => counts.push((s.kind().name(), 1)),
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
    #[error(
        "{path} is a PNG image, not a scene; to render the scene a PNG of glint's was made \
         from, use `glint render --from-png {path}` (`glint info {path}` says what it holds)"
    )]
    Png { path: PathBuf },
    #[error("{location}: {message}")]
    Invalid { location: Location, message: String },
    #[error("{location}: mesh {mesh}: {message}")]
    Mesh {
        location: Location,
        mesh: PathBuf,
        message: String,
    },
    /// A model opened directly ([`super::load`] of an `.obj`) that cannot
    /// be read: the file and, in `message`, the line.
    #[error("{path}: {message}")]
    Model { path: PathBuf, message: String },
    #[error("{path}: unknown scene format (expected a .toml, .nff or .obj file)")]
    UnknownFormat { path: PathBuf },
}

/// 1-based line and column of a byte offset.
pub(super) fn line_column(text: &str, offset: usize) -> (usize, usize) {
    let offset = offset.min(text.len());
    let before = &text[..text.floor_char_boundary(offset)];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn empty() -> Scene {
        let camera = CameraSpec {
            eye: DVec3::new(0.0, 0.0, 10.0),
            lookat: DVec3::ZERO,
            up: DVec3::Y,
            fov: 40.0,
        };
        Scene::empty("normals".into(), camera, ImageSettings::default())
    }

    /// Shading reads vertex normals as unit vectors, whatever length the
    /// file gave them (even where the squared length over- or underflows);
    /// normals with no direction leave the triangle flat.
    #[test]
    fn vertex_normals_are_stored_unit_length() {
        let triangle = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let lengths = [1e-200, 1e-150, 1e-3, 1.0, 7.5, 1e150, 1e300];
        let mut scene = empty();
        let normals = lengths.map(|s| [DVec3::new(0.0, 0.6, 0.8) * s; 3]);
        scene.push_mesh(
            vec![triangle; lengths.len()],
            Some(normals.to_vec()),
            &[],
            &[],
            |_| 0,
        );
        assert_eq!(scene.vertex_normals.len(), lengths.len());
        for n in scene.vertex_normals.iter().flatten() {
            assert!((n.length() - 1.0).abs() < 1e-15, "{n}");
            assert!((*n - DVec3::new(0.0, 0.6, 0.8)).length() < 1e-15, "{n}");
        }
        let mut scene = empty();
        for bad in [
            DVec3::ZERO,
            DVec3::splat(f64::NAN),
            DVec3::new(1.0, f64::INFINITY, 0.0),
        ] {
            scene.push_mesh(
                vec![triangle],
                Some(vec![[DVec3::Z, bad, DVec3::Z]]),
                &[],
                &[],
                |_| 0,
            );
        }
        assert!(scene.vertex_normals.is_empty());
        assert_eq!(scene.shapes.len(), 3);
        assert!(scene.shapes.iter().all(|s| !s.has_vertex_normals()));
    }
}
