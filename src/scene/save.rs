//! Writing a scene back to its file: the viewer's "Save scene". A TOML
//! scene's own text is edited in place (`toml_edit`), so its comments, its
//! order and every number nobody changed stay as they were; only values
//! that differ from the scene as loaded are written. An NFF scene keeps its
//! text too, with the numbers the viewer edits rewritten; what NFF cannot
//! say is listed in [`SavedText::left_out`], not lost silently.

use std::path::{Path, PathBuf};

use toml_edit::{Item, TableLike, Value};

use super::Scene;
use crate::accel::OctreeParams;
use crate::camera::CameraSpec;
use crate::material::{Light, Material};
use crate::settings::RenderSettings;

mod mesh_paths;
mod nff;
mod toml;

pub use nff::scene_nff;
pub use toml::scene_toml;

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
    /// The camera path to save (TOML's `[[camera.keyframes]]`; none
    /// removes them).
    pub camera_path: Option<&'a crate::camera_path::CameraPath>,
    /// Lights as edited (as many as the scene has).
    pub lights: &'a [Light],
    /// Materials as edited (the scene's, in its order).
    pub materials: &'a [Material],
    /// Image size, samples, depth, colours, sides and the octree switch.
    /// Under the SPD protocol the image settings are the protocol's, not
    /// the scene's, so only the octree switch is written.
    pub settings: &'a RenderSettings,
    /// The octree's parameters as edited (TOML's `[octree]` table).
    pub octree: &'a OctreeParams,
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
    /// The octree's depth, leaf size and other parameters (NFF).
    OctreeParams,
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
    /// The camera path's keyframes (NFF has no camera path).
    CameraPath,
}

impl std::fmt::Display for LeftOut {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            LeftOut::Samples => f.write_str("samples"),
            LeftOut::MaxDepth => f.write_str("max depth"),
            LeftOut::Colors => f.write_str("colours"),
            LeftOut::Sides => f.write_str("sides"),
            LeftOut::OctreeSwitch => f.write_str("the octree switch"),
            LeftOut::OctreeParams => f.write_str("the octree parameters"),
            LeftOut::Reflectivity { material } => {
                write!(f, "the reflectivity of {material} (NFF uses Ks)")
            }
            LeftOut::EqualMaterial { material, equal_to } => write!(
                f,
                "{material} apart from {equal_to} (equal materials are one in NFF)"
            ),
            LeftOut::Material { name } => write!(f, "material {name}"),
            LeftOut::CameraPath => f.write_str("the camera path (save as TOML to keep it)"),
        }
    }
}

// TOML helpers the TOML writer and the mesh paths share.

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

#[cfg(test)]
mod tests;
