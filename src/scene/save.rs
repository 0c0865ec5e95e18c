//! Writing a scene back as TOML: the viewer's "Save scene". The scene's own
//! text is edited in place (`toml_edit`), so its comments, its order and
//! every number nobody changed stay as they were; only values that differ
//! from the scene as loaded are written.

use std::path::{Path, PathBuf};

use toml_edit::{Array, DocumentMut, Item, TableLike, Value};

use super::Scene;
use crate::camera::CameraSpec;
use crate::material::{Light, Material};
use crate::math::DVec3;
use crate::settings::{Protocol, RenderSettings};

/// Why a scene cannot be written as TOML.
#[derive(Debug, thiserror::Error)]
pub enum SaveError {
    #[error(
        "{path} is an NFF scene: glint saves TOML scenes only (export a PNG to keep these edits; `glint render --from-png` renders it again)"
    )]
    NotToml { path: PathBuf },
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
    /// Edited materials a mesh's MTL file defines: a TOML scene takes those
    /// from the MTL file, so the edits are not in `text`.
    pub left_out_materials: Vec<String>,
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
    let left_out_materials = write_materials(&mut doc, &loaded.materials, request.materials);
    write_mesh_paths(&mut doc, path, destination, request.mesh_paths);
    Ok(SavedText {
        text: doc.to_string(),
        left_out_materials,
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

/// Writes the file's own materials; returns the names of edited ones that
/// come from a mesh's MTL file.
fn write_materials(
    doc: &mut DocumentMut,
    loaded: &[Material],
    materials: &[Material],
) -> Vec<String> {
    let mut left_out = Vec::new();
    for (old, new) in loaded.iter().zip(materials) {
        if old == new {
            continue;
        }
        let entry = doc
            .get_mut("materials")
            .and_then(Item::as_table_like_mut)
            .and_then(|t| t.get_mut(&old.name))
            .and_then(Item::as_table_like_mut);
        let Some(t) = entry else {
            left_out.push(old.name.clone());
            continue;
        };
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
    left_out
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
mod tests {
    use super::*;
    use crate::scene::{MeshSource, load_str};

    struct NoMeshes;
    impl MeshSource for NoMeshes {
        fn read(&self, _: &Path) -> std::io::Result<Vec<u8>> {
            Err(std::io::ErrorKind::NotFound.into())
        }
    }

    const TEXT: &str = "# A test scene.\n[camera]\neye = [0, 1, 5] # over the floor\nlookat = [0, 0, 0]\n\
        up = [0, 1, 0]\nfov = 40\n\n[image]\nwidth = 64\nheight = 48\n\n\
        [materials.red]\ncolor = [0.8, 0.1, 0.1] # brick\nkd = 0.7\n\n\
        [[lights]]\nposition = [1, 5, 1]\n\n\
        [[objects]]\nkind = \"sphere\"\nmaterial = \"red\"\ncenter = [0, 0, 0]\nradius = 1\n";

    fn scene(text: &str) -> Scene {
        load_str(text, Path::new("dir/scene.toml"), &NoMeshes).unwrap()
    }

    fn request<'a>(
        loaded: &'a Scene,
        camera: &'a CameraSpec,
        settings: &'a RenderSettings,
    ) -> SaveRequest<'a> {
        SaveRequest {
            loaded,
            loaded_path: Path::new("dir/scene.toml"),
            camera,
            lights: &loaded.lights,
            materials: &loaded.materials,
            settings,
            mesh_paths: MeshPaths::Anchored,
        }
    }

    #[test]
    fn an_unedited_scene_is_saved_byte_for_byte() {
        let loaded = scene(TEXT);
        let settings = loaded.render_settings();
        let saved = scene_toml(
            &request(&loaded, &loaded.camera, &settings),
            Path::new("dir/scene.toml"),
        )
        .unwrap();
        assert_eq!(saved.text, TEXT);
        assert!(saved.left_out_materials.is_empty());
    }

    #[test]
    fn edits_are_written_and_comments_and_untouched_numbers_kept() {
        let loaded = scene(TEXT);
        let mut camera = loaded.camera;
        camera.eye = DVec3::new(1e100, -2.5e-300, 0.1);
        camera.fov = 12.5;
        let mut settings = loaded.render_settings();
        settings.width = 640;
        settings.samples = 16;
        settings.adaptive = true;
        settings.use_octree = false;
        let mut lights = loaded.lights.clone();
        lights[0].color = DVec3::new(0.5, 0.25, 1.0);
        let mut materials = loaded.materials.clone();
        materials[0].kd = 0.123456789;
        let req = SaveRequest {
            lights: &lights,
            materials: &materials,
            ..request(&loaded, &camera, &settings)
        };
        let saved = scene_toml(&req, Path::new("dir/scene.toml")).unwrap();
        let text = &saved.text;
        for kept in [
            "# A test scene.\n",
            "# over the floor\n",
            "color = [0.8, 0.1, 0.1] # brick\n",
            "lookat = [0, 0, 0]\n",
            "height = 48\n",
            "position = [1, 5, 1]\n",
        ] {
            assert!(text.contains(kept), "lost {kept:?} in\n{text}");
        }
        let again = scene(text);
        assert_eq!(again.camera, camera);
        assert_eq!(again.lights, lights);
        assert_eq!(again.materials, materials);
        assert_eq!(again.render_settings(), settings);
        assert!(!again.octree_enabled);
        assert_eq!((again.image.samples, again.image.adaptive), (16, true));
    }

    #[test]
    fn nff_scenes_are_refused_with_the_way_to_keep_the_edits() {
        let loaded = scene(TEXT);
        let settings = loaded.render_settings();
        let req = SaveRequest {
            loaded_path: Path::new("balls.nff"),
            ..request(&loaded, &loaded.camera, &settings)
        };
        let e = scene_toml(&req, Path::new("balls.toml")).unwrap_err();
        assert!(matches!(e, SaveError::NotToml { .. }), "{e}");
        assert!(e.to_string().contains("export a PNG"), "{e}");
    }

    #[test]
    fn mesh_paths_follow_the_file_to_another_folder() {
        let text = "[camera]\neye = [0, 0, 5]\nlookat = [0, 0, 0]\nup = [0, 1, 0]\nfov = 40\n\
                    [[objects]]\nkind = \"mesh\"\npath = \"../models/m.obj\"\n";
        let doc = |how, dest: &str| {
            let mut d: DocumentMut = text.parse().unwrap();
            write_mesh_paths(
                &mut d,
                Path::new("/nonexistent/a/scene.toml"),
                Path::new(dest),
                how,
            );
            d["objects"][0]["path"].as_str().unwrap().to_owned()
        };
        assert_eq!(
            doc(MeshPaths::Anchored, "/nonexistent/a/copy.toml"),
            "../models/m.obj"
        );
        assert_eq!(
            doc(MeshPaths::Anchored, "/nonexistent/b/copy.toml"),
            "/nonexistent/a/../models/m.obj"
        );
        assert_eq!(doc(MeshPaths::Beside, "/nonexistent/a/copy.toml"), "m.obj");
    }
}
