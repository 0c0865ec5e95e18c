//! The built-in default scene and the mesh it uses, embedded in the binary.

use std::path::Path;

use crate::scene::{FileSource, Scene, SceneError};

pub const DEFAULT_SCENE: &str = include_str!("../../scenes/default.toml");
/// The mesh the built-in scene uses, and its file name.
pub const MESH: &[u8] = include_bytes!("../../assets/bunny.obj");
pub const MESH_NAME: &str = "bunny.obj";
/// How the built-in scene is named in messages and exports.
pub const NAME: &str = "scenes/default.toml (built in)";

struct Embedded;

impl FileSource for Embedded {
    fn read(&self, path: &Path) -> std::io::Result<Vec<u8>> {
        if path.file_name().is_some_and(|n| n == MESH_NAME) {
            Ok(MESH.to_vec())
        } else {
            Err(std::io::Error::new(
                std::io::ErrorKind::NotFound,
                "the built-in scene embeds only assets/bunny.obj",
            ))
        }
    }
}

pub fn default_scene() -> Result<Scene, SceneError> {
    load_text(DEFAULT_SCENE)
}

/// Parses `text` as the built-in scene would be (its mesh from the binary):
/// used to re-render exports made from an edited copy of it.
pub fn load_text(text: &str) -> Result<Scene, SceneError> {
    let mut scene = crate::scene::load_str(text, Path::new("scenes/default.toml"), &Embedded)?;
    scene.name = NAME.into();
    Ok(scene)
}
