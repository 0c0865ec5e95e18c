//! Writing a scene back to its file: the viewer's "Save scene". A TOML
//! scene's own text is edited in place (`toml_edit`), so its comments, its
//! order and every number nobody changed stay as they were; only values
//! that differ from the scene as loaded are written. An NFF scene keeps its
//! text too, with the numbers the viewer edits rewritten; what NFF cannot
//! say is listed in [`SavedText::left_out`], not lost silently.

use std::ops::Range;
use std::path::{Path, PathBuf};

use toml_edit::{Array, DocumentMut, Item, TableLike, Value};

use super::{MeshMaterialOrigin, Scene};
use crate::camera::CameraSpec;
use crate::material::{Light, Material};
use crate::math::DVec3;
use crate::settings::{Protocol, RenderSettings};

/// Why a scene cannot be written as TOML.
#[derive(Debug, thiserror::Error)]
pub enum SaveError {
    #[error(
        "{path} is an NFF scene: it is saved as NFF (name the file .nff); TOML has no cones or polygons"
    )]
    NotToml { path: PathBuf },
    #[error("{path} is not an NFF scene: it is saved as TOML (name the file .toml)")]
    NotNff { path: PathBuf },
    #[error("the scene text of {path} is not TOML glint can edit: {message}")]
    Unreadable { path: PathBuf, message: String },
    #[error("the edited scene has {edited} lights where its file has {loaded}")]
    LightCount { loaded: usize, edited: usize },
}

/// Where the saved file's meshes are found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshPaths {
    /// As the scene file says, anchored at the folder it was loaded from:
    /// kept when saving into that folder, made absolute elsewhere.
    Anchored,
    /// Beside the saved file, under their own file names (the built-in
    /// scene, whose mesh the caller writes there).
    Beside,
}

/// What to save: the scene as loaded and as edited.
pub struct SaveRequest<'a> {
    /// The scene as its file describes it: values equal to these are left
    /// as the file writes them.
    pub loaded: &'a Scene,
    /// The file it was loaded from (anchors relative mesh paths).
    pub loaded_path: &'a Path,
    /// The camera to save.
    pub camera: &'a CameraSpec,
    /// Lights as edited (as many as the scene has).
    pub lights: &'a [Light],
    /// Materials as edited (the scene's, in its order).
    pub materials: &'a [Material],
    /// Image size, samples, depth, colours, sides and the octree switch.
    /// Under the SPD protocol the image settings are the protocol's, not
    /// the scene's, so only the octree switch is written.
    pub settings: &'a RenderSettings,
    pub mesh_paths: MeshPaths,
}

/// A saved scene's text, and what it could not hold.
#[derive(Clone, Debug, PartialEq)]
pub struct SavedText {
    pub text: String,
    /// Edits the format has no place for: they are not in `text`.
    pub left_out: Vec<LeftOut>,
}

/// An edit a scene format has no place for. The viewer keeps the file's
/// value of a setting left out as its baseline, so the edit stays marked
/// unsaved; `Display` says it in a few words.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum LeftOut {
    /// Samples per pixel and adaptive anti-aliasing (NFF).
    Samples,
    MaxDepth,
    Colors,
    Sides,
    /// The octree on or off (NFF).
    OctreeSwitch,
    /// A reflectivity apart from Ks: NFF has one coefficient for both.
    Reflectivity {
        material: String,
    },
    /// A material edited equal to an earlier one, which NFF reads back as
    /// that one.
    EqualMaterial {
        material: String,
        equal_to: String,
    },
    /// A material the TOML file has no table to write into.
    Material {
        name: String,
    },
}

impl std::fmt::Display for LeftOut {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LeftOut::Samples => f.write_str("samples"),
            LeftOut::MaxDepth => f.write_str("max depth"),
            LeftOut::Colors => f.write_str("colours"),
            LeftOut::Sides => f.write_str("sides"),
            LeftOut::OctreeSwitch => f.write_str("the octree switch"),
            LeftOut::Reflectivity { material } => {
                write!(f, "the reflectivity of {material} (NFF uses Ks)")
            }
            LeftOut::EqualMaterial { material, equal_to } => write!(
                f,
                "{material} apart from {equal_to} (equal materials are one in NFF)"
            ),
            LeftOut::Material { name } => write!(f, "material {name}"),
        }
    }
}

/// The TOML text of `request` to be written at `destination`.
pub fn scene_toml(request: &SaveRequest, destination: &Path) -> Result<SavedText, SaveError> {
    let loaded = request.loaded;
    let path = request.loaded_path;
    let is_nff = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("nff"));
    if is_nff {
        return Err(SaveError::NotToml {
            path: path.to_owned(),
        });
    }
    let mut doc: DocumentMut = loaded
        .source_text
        .parse()
        .map_err(|e: toml_edit::TomlError| SaveError::Unreadable {
            path: path.to_owned(),
            message: e.message().to_owned(),
        })?;

    write_camera(&mut doc, &loaded.camera, request.camera);
    write_settings(&mut doc, loaded, request.settings);
    if request.lights.len() != loaded.lights.len() {
        return Err(SaveError::LightCount {
            loaded: loaded.lights.len(),
            edited: request.lights.len(),
        });
    }
    write_lights(&mut doc, &loaded.lights, request.lights);
    let left_out = write_materials(
        &mut doc,
        &loaded.materials,
        request.materials,
        &loaded.mesh_material_origins,
    );
    write_mesh_paths(&mut doc, path, destination, request.mesh_paths);
    Ok(SavedText {
        text: doc.to_string(),
        left_out: left_out
            .into_iter()
            .map(|name| LeftOut::Material { name })
            .collect(),
    })
}

/// The NFF text of `request`: the loaded file with the numbers the viewer
/// edits (viewpoint, resolution, lights, `f` materials) rewritten and
/// everything else, comments included, as it was. What NFF cannot say
/// (samples, depth, colours, sides, the octree switch, a reflectivity
/// apart from Ks) is listed in `left_out`.
pub fn scene_nff(request: &SaveRequest) -> Result<SavedText, SaveError> {
    let loaded = request.loaded;
    let path = request.loaded_path;
    let is_nff = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("nff"));
    if !is_nff {
        return Err(SaveError::NotNff {
            path: path.to_owned(),
        });
    }
    let text = &*loaded.source_text;
    let layout = super::nff::layout(text, path).map_err(|e| SaveError::Unreadable {
        path: path.to_owned(),
        message: e.to_string(),
    })?;
    if request.lights.len() != loaded.lights.len() {
        return Err(SaveError::LightCount {
            loaded: loaded.lights.len(),
            edited: request.lights.len(),
        });
    }
    let number = |x: f64| format!("{x:?}");
    let mut edits: Vec<(Range<usize>, String)> = Vec::new();
    let mut put = |ranges: &[Range<usize>], values: &[f64]| {
        for (r, &x) in ranges.iter().zip(values) {
            edits.push((r.clone(), number(x)));
        }
    };
    let mut left_out = Vec::new();

    let s = request.settings;
    let im = &loaded.image;
    let resize = s.protocol == Protocol::Glint && (s.width, s.height) != (im.width, im.height);
    let rows = if resize { s.height } else { im.height };
    if let Some(view) = &layout.view {
        let (old, new) = (&loaded.camera, request.camera);
        for (ranges, a, b) in [
            (&view.from, old.eye, new.eye),
            (&view.at, old.lookat, new.lookat),
            (&view.up, old.up, new.up),
        ] {
            if a != b {
                put(ranges, &b.to_array());
            }
        }
        // NFF's angle depends on the row count; the field of view is kept.
        if old.fov != new.fov || resize {
            put(
                std::slice::from_ref(&view.angle),
                &[super::nff::nff_angle_from_fov(new.fov, rows)],
            );
        }
        if resize {
            edits.push((view.resolution[0].clone(), s.width.to_string()));
            edits.push((view.resolution[1].clone(), s.height.to_string()));
        }
    }
    if s.protocol == Protocol::Glint {
        for (what, differs) in [
            (
                LeftOut::Samples,
                (s.samples, s.adaptive) != (im.samples, im.adaptive),
            ),
            (LeftOut::MaxDepth, s.max_depth != im.max_depth),
            (LeftOut::Colors, s.colors != im.colors),
            (LeftOut::Sides, s.sides != im.sides),
        ] {
            if differs {
                left_out.push(what);
            }
        }
    }
    if s.use_octree != loaded.octree_enabled {
        left_out.push(LeftOut::OctreeSwitch);
    }

    for ((place, old), new) in layout.lights.iter().zip(&loaded.lights).zip(request.lights) {
        let mut put = |ranges: &[Range<usize>], values: &[f64]| {
            for (r, &x) in ranges.iter().zip(values) {
                edits.push((r.clone(), number(x)));
            }
        };
        if old.position != new.position {
            put(&place.position, &new.position.to_array());
        }
        if old.color != new.color {
            match &place.color {
                Some(ranges) => put(ranges, &new.color.to_array()),
                None => {
                    let end = place.position[2].end;
                    let c = new.color;
                    edits.push((
                        end..end,
                        format!(" {} {} {}", number(c.x), number(c.y), number(c.z)),
                    ));
                }
            }
        }
    }

    for (i, (old, new)) in loaded.materials.iter().zip(request.materials).enumerate() {
        if old == new {
            continue;
        }
        // NFF has one coefficient for the highlight and the mirror ray, and
        // weights the ambient term by Kd.
        if new.reflectivity != new.ks {
            left_out.push(LeftOut::Reflectivity {
                material: old.name.clone(),
            });
        }
        // Every number of the material's `f` lines is written: the file's
        // own may differ from the loaded value (an opaque material's index
        // of refraction is often written 0 and loaded as 1).
        let values = [
            new.color.x,
            new.color.y,
            new.color.z,
            new.kd,
            new.ks,
            new.shininess,
            new.transparency,
            new.ior,
        ];
        for entity in layout.materials.get(i).into_iter().flatten() {
            for (r, &x) in entity.iter().zip(&values) {
                edits.push((r.clone(), number(x)));
            }
        }
    }
    // NFF gives one material to equal `f` lines: materials edited to be
    // equal are one material when the file is read again.
    let nff_key = |m: &Material| {
        [
            m.color.x,
            m.color.y,
            m.color.z,
            m.kd,
            m.ks,
            m.shininess,
            m.transparency,
            m.ior,
        ]
    };
    for (i, a) in request.materials.iter().enumerate() {
        if let Some(b) = request.materials[..i]
            .iter()
            .find(|b| nff_key(b) == nff_key(a))
        {
            left_out.push(LeftOut::EqualMaterial {
                material: a.name.clone(),
                equal_to: b.name.clone(),
            });
        }
    }

    edits.sort_by_key(|(r, _)| (r.start, r.end));
    let mut out = String::with_capacity(text.len() + 64 * edits.len());
    let mut at = 0;
    for (r, new) in edits {
        out.push_str(&text[at..r.start]);
        out.push_str(&new);
        at = r.end;
    }
    out.push_str(&text[at..]);
    Ok(SavedText {
        text: out,
        left_out,
    })
}

/// Sets `key` in `table` to `new`, keeping the old value's surrounding
/// whitespace and trailing comment.
fn set(table: &mut dyn TableLike, key: &str, mut new: Value) {
    match table.get_mut(key) {
        Some(Item::Value(old)) => {
            *new.decor_mut() = old.decor().clone();
            *old = new;
        }
        _ => {
            table.insert(key, Item::Value(new));
        }
    }
}

fn vec3(v: DVec3) -> Value {
    Value::Array(Array::from_iter([v.x, v.y, v.z]))
}

/// The table `key` of the document, made if the file has none.
fn table<'d>(doc: &'d mut DocumentMut, key: &str) -> Option<&'d mut dyn TableLike> {
    doc.entry(key)
        .or_insert_with(toml_edit::table)
        .as_table_like_mut()
}

fn write_camera(doc: &mut DocumentMut, loaded: &CameraSpec, camera: &CameraSpec) {
    if loaded == camera {
        return;
    }
    let Some(t) = table(doc, "camera") else {
        return;
    };
    for (key, old, new) in [
        ("eye", loaded.eye, camera.eye),
        ("lookat", loaded.lookat, camera.lookat),
        ("up", loaded.up, camera.up),
    ] {
        if old != new {
            set(t, key, vec3(new));
        }
    }
    if loaded.fov != camera.fov {
        set(t, "fov", Value::from(camera.fov));
    }
}

fn write_settings(doc: &mut DocumentMut, loaded: &Scene, s: &RenderSettings) {
    if s.use_octree != loaded.octree_enabled
        && let Some(t) = table(doc, "octree")
    {
        set(t, "enabled", Value::from(s.use_octree));
    }
    if s.protocol != Protocol::Glint {
        return;
    }
    let im = &loaded.image;
    let changed = (
        s.width,
        s.height,
        s.samples,
        s.adaptive,
        s.max_depth,
        s.colors,
        s.sides,
    ) != (
        im.width,
        im.height,
        im.samples,
        im.adaptive,
        im.max_depth,
        im.colors,
        im.sides,
    );
    if !changed {
        return;
    }
    let Some(t) = table(doc, "image") else {
        return;
    };
    for (key, old, new) in [
        ("width", im.width, s.width),
        ("height", im.height, s.height),
        ("max_depth", im.max_depth, s.max_depth),
    ] {
        if old != new {
            set(t, key, Value::from(i64::from(new)));
        }
    }
    if (im.samples, im.adaptive) != (s.samples, s.adaptive) {
        // `aa` says all three settings; `samples` only off or full.
        if (s.adaptive && s.samples > 1) || t.contains_key("aa") {
            t.remove("samples");
            set(t, "aa", Value::from(s.anti_aliasing().name()));
        } else {
            set(t, "samples", Value::from(i64::from(s.samples)));
        }
    }
    if im.colors != s.colors {
        set(t, "colors", Value::from(s.colors.name()));
    }
    if im.sides != s.sides {
        set(t, "sides", Value::from(s.sides.name()));
    }
}

/// The tables of an array of tables (`[[lights]]`) or of an inline array
/// of tables (`lights = [{ ... }]`).
fn tables_of(item: &mut Item) -> Vec<&mut dyn TableLike> {
    match item {
        Item::ArrayOfTables(a) => a.iter_mut().map(|t| t as &mut dyn TableLike).collect(),
        Item::Value(Value::Array(a)) => a
            .iter_mut()
            .filter_map(|v| v.as_inline_table_mut().map(|t| t as &mut dyn TableLike))
            .collect(),
        _ => Vec::new(),
    }
}

fn write_lights(doc: &mut DocumentMut, loaded: &[Light], lights: &[Light]) {
    if loaded == lights {
        return;
    }
    let Some(item) = doc.get_mut("lights") else {
        return;
    };
    for ((t, old), new) in tables_of(item).into_iter().zip(loaded).zip(lights) {
        if old.position != new.position {
            set(t, "position", vec3(new.position));
        }
        if old.color != new.color {
            set(t, "color", vec3(new.color));
        }
    }
}

/// Writes edited materials: the file's own into `[materials]`, a mesh's
/// MTL materials into its object's `materials`. Returns the names of any
/// it has no place for.
fn write_materials(
    doc: &mut DocumentMut,
    loaded: &[Material],
    materials: &[Material],
    origins: &[MeshMaterialOrigin],
) -> Vec<String> {
    let mut left_out = Vec::new();
    for (index, (old, new)) in loaded.iter().zip(materials).enumerate() {
        if old == new {
            continue;
        }
        let origin = origins.iter().find(|o| o.material as usize == index);
        let written = match origin {
            Some(o) => mesh_material_table(doc, o).map(|t| write_material(t, old, new)),
            None => doc
                .get_mut("materials")
                .and_then(Item::as_table_like_mut)
                .and_then(|t| t.get_mut(&old.name))
                .and_then(Item::as_table_like_mut)
                .map(|t| write_material(t, old, new)),
        };
        if written.is_none() {
            left_out.push(old.name.clone());
        }
    }
    left_out
}

/// The table `objects[k].materials.NAME` of a mesh material, made if the
/// file has none.
fn mesh_material_table<'d>(
    doc: &'d mut DocumentMut,
    origin: &MeshMaterialOrigin,
) -> Option<&'d mut dyn TableLike> {
    let object = tables_of(doc.get_mut("objects")?)
        .into_iter()
        .nth(origin.object)?;
    let materials = object.entry("materials").or_insert_with(|| {
        let mut t = toml_edit::Table::new();
        // Only `[objects.materials.NAME]` headers are written.
        t.set_implicit(true);
        Item::Table(t)
    });
    materials
        .as_table_like_mut()?
        .entry(&origin.name)
        .or_insert_with(toml_edit::table)
        .as_table_like_mut()
}

fn write_material(t: &mut dyn TableLike, old: &Material, new: &Material) {
    if old.color != new.color {
        set(t, "color", vec3(new.color));
    }
    for (key, a, b) in [
        ("kd", old.kd, new.kd),
        ("ks", old.ks, new.ks),
        ("shininess", old.shininess, new.shininess),
        ("reflectivity", old.reflectivity, new.reflectivity),
        ("transparency", old.transparency, new.transparency),
        ("ior", old.ior, new.ior),
    ] {
        if a != b {
            set(t, key, Value::from(b));
        }
    }
}

/// Rewrites relative mesh paths so the saved file finds the same meshes.
fn write_mesh_paths(doc: &mut DocumentMut, loaded_path: &Path, destination: &Path, how: MeshPaths) {
    let from = folder(loaded_path);
    let to = folder(destination);
    let same_folder = match (std::fs::canonicalize(&from), std::fs::canonicalize(&to)) {
        (Ok(a), Ok(b)) => a == b,
        _ => std::path::absolute(&from).ok() == std::path::absolute(&to).ok(),
    };
    if how == MeshPaths::Anchored && same_folder {
        return;
    }
    let Some(item) = doc.get_mut("objects") else {
        return;
    };
    for t in tables_of(item) {
        let Some(old) = t.get("path").and_then(Item::as_str).map(PathBuf::from) else {
            continue;
        };
        let new = match how {
            MeshPaths::Beside => match old.file_name() {
                Some(name) => PathBuf::from(name),
                None => continue,
            },
            MeshPaths::Anchored if old.is_absolute() => continue,
            MeshPaths::Anchored => {
                let joined = from.join(&old);
                std::fs::canonicalize(&joined)
                    .or_else(|_| std::path::absolute(&joined))
                    .unwrap_or(joined)
            }
        };
        // A path that is not UTF-8 cannot be written in TOML; it stays.
        if let Some(s) = new.to_str() {
            set(t, "path", Value::from(s));
        }
    }
}

/// The folder a file is in (`.` for a bare name).
fn folder(file: &Path) -> PathBuf {
    match file.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_owned(),
        _ => PathBuf::from("."),
    }
}

#[cfg(test)]
mod tests;
