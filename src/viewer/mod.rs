//! The interactive viewer (cargo feature `gui`): a layer over the headless
//! renderer. [`app::GlintApp`] holds what the user edits; [`worker::Worker`]
//! renders in the background.

pub mod app;
mod orbit;
mod panels;
pub mod worker;

pub use app::{GlintApp, SceneSource, ViewerOptions};

/// The built-in default scene and the mesh it uses, embedded in the binary.
pub mod builtin {
    use std::path::Path;

    use crate::scene::{MeshSource, Scene, SceneError};

    pub const DEFAULT_SCENE: &str = include_str!("../../scenes/default.toml");
    const BUNNY_OBJ: &[u8] = include_bytes!("../../assets/bunny.obj");
    /// How the built-in scene is named in messages and exports.
    pub const NAME: &str = "scenes/default.toml (built in)";

    struct Embedded;

    impl MeshSource for Embedded {
        fn read(&self, path: &Path) -> std::io::Result<Vec<u8>> {
            if path.file_name().is_some_and(|n| n == "bunny.obj") {
                Ok(BUNNY_OBJ.to_vec())
            } else {
                Err(std::io::Error::new(
                    std::io::ErrorKind::NotFound,
                    "the built-in scene embeds only assets/bunny.obj",
                ))
            }
        }
    }

    pub fn default_scene() -> Result<Scene, SceneError> {
        let mut scene =
            crate::scene::load_str(DEFAULT_SCENE, Path::new("scenes/default.toml"), &Embedded)?;
        scene.name = NAME.into();
        Ok(scene)
    }
}
