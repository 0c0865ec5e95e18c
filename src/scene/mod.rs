//! A scene as the renderer sees it, and the two file formats that describe it:
//! glint's own TOML ([`toml_format`]) and Eric Haines's NFF ([`nff`]).

pub mod builtin;
mod mesh;
mod model;
pub mod nff;
pub mod polygon;
pub mod toml_format;

use std::path::Path;
use std::sync::Arc;

pub use mesh::{FileSystem, MeshSource};
pub use model::{ImageSettings, Location, Scene, SceneError};
pub use polygon::DroppedPolygons;

/// Loads a `.toml` or `.nff` scene file.
pub fn load(path: &Path) -> Result<Scene, SceneError> {
    let bytes = std::fs::read(path).map_err(|source| SceneError::Io {
        path: path.to_owned(),
        source,
    })?;
    let text = String::from_utf8(bytes).map_err(|e| SceneError::NotUtf8 {
        path: path.to_owned(),
        offset: e.utf8_error().valid_up_to(),
    })?;
    load_str(&text, path, &mesh::FileSystem)
}

/// Parses scene text; `path` names it in errors, chooses the format by its
/// extension and anchors relative mesh paths.
pub fn load_str(text: &str, path: &Path, files: &dyn MeshSource) -> Result<Scene, SceneError> {
    let mut scene = match path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("toml") => toml_format::parse(text, path, files),
        Some("nff") => nff::parse(text, path),
        _ => Err(SceneError::UnknownFormat {
            path: path.to_owned(),
        }),
    }?;
    scene.source_text = Arc::from(text);
    Ok(scene)
}
