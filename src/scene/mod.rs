//! A scene as the renderer sees it, and the two file formats that describe it:
//! glint's own TOML ([`toml_format`]) and Eric Haines's NFF ([`nff`]); an
//! OBJ model also opens on its own, in a scene written around it.

pub mod builtin;
pub mod edit;
mod file_source;
mod interior_view;
mod keyhole;
mod mesh;
mod mesh_materials;
mod model;
mod model_axes;
mod model_probe;
mod mtl;
pub mod nff;
mod obj;
mod obj_scene;
pub mod polygon;
pub mod save;
mod text;
mod textures;
pub mod toml_format;

use std::path::Path;
use std::sync::Arc;

pub use edit::{EditError, KeyValue};
pub use file_source::{FileRead, FileSource, FileSystem};
pub use model::{ImageSettings, Location, MeshCounts, MeshMaterialOrigin, Scene, SceneError};
pub use obj::SkippedElements;
pub use polygon::DroppedPolygons;

/// Loads a `.toml` or `.nff` scene file, or an `.obj` model in a scene
/// glint writes around it.
pub fn load(path: &Path) -> Result<Scene, SceneError> {
    load_with(path, &FileSystem)
}

/// A camera path from the text of a TOML file of `[[keyframes]]` (for
/// scenes whose format has no place for one: NFF, OBJ); `path` names it
/// in errors; `up` and `fov` default to `camera`'s.
pub fn camera_path_from_str(
    text: &str,
    path: &Path,
    camera: &crate::camera::CameraSpec,
) -> Result<crate::camera_path::CameraPath, SceneError> {
    toml_format::parse_camera_path(text, path, camera)
}

/// Like [`load`], reading the scene file and its meshes from `files`.
pub fn load_with(path: &Path, files: &dyn FileSource) -> Result<Scene, SceneError> {
    if extension(path).as_deref() == Some("obj") {
        return obj_scene::load(path, files);
    }
    let bytes = files.read(path).map_err(|source| SceneError::Io {
        path: path.to_owned(),
        source,
    })?;
    if bytes.starts_with(PNG_SIGNATURE) {
        return Err(SceneError::Png {
            path: path.to_owned(),
        });
    }
    let text = String::from_utf8(bytes).map_err(|e| SceneError::NotUtf8 {
        path: path.to_owned(),
        offset: e.utf8_error().valid_up_to(),
    })?;
    load_str(&text, path, files)
}

/// The eight bytes every PNG file begins with (PNG specification, 5.2).
const PNG_SIGNATURE: &[u8] = b"\x89PNG\r\n\x1a\n";

fn extension(path: &Path) -> Option<String> {
    path.extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
}

/// Parses scene text; `path` names it in errors, chooses the format by its
/// extension and anchors relative mesh paths. For an `.obj` path the text
/// is the TOML scene [`load`] wrote around it.
pub fn load_str(text: &str, path: &Path, files: &dyn FileSource) -> Result<Scene, SceneError> {
    let recording = file_source::Recording {
        inner: files,
        read: Default::default(),
    };
    let files = &recording;
    let mut scene = match extension(path).as_deref() {
        Some("toml") => toml_format::parse(text, path, files),
        // A byte-order mark (Windows editors) is not the first entity.
        Some("nff") => nff::parse(text.strip_prefix('\u{feff}').unwrap_or(text), path),
        Some("obj") => obj_scene::reload(text, path, files),
        _ => Err(SceneError::UnknownFormat {
            path: path.to_owned(),
        }),
    }?;
    scene.source_text = Arc::from(text);
    scene.files_read = recording.read.into_inner();
    Ok(scene)
}
