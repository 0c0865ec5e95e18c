//! "Save scene": the viewer's edits written into the scene's file, TOML or
//! NFF (see [`crate::scene::save`]), atomically, then read back to prove it
//! loads.

use crate::settings::Accel;
use std::path::{Path, PathBuf};

use super::export::file_dialog_available;
use super::state::{EditState, SceneSource, Snapshot};
use crate::accel::OctreeParams;
use crate::scene::Scene;
use crate::scene::save::{MeshPaths, SaveRequest, scene_nff, scene_toml};
use crate::settings::RenderSettings;

/// Whether "Save scene" can write into the scene's own file: a TOML or an
/// NFF scene file can be edited in place (the built-in scene and an OBJ
/// opened on its own need a new file).
pub fn saves_in_place(source: &SceneSource) -> bool {
    is_nff(source)
        || source
            .path()
            .and_then(Path::extension)
            .is_some_and(|e| e.eq_ignore_ascii_case("toml"))
}

/// Whether the scene is an NFF file, which is saved as NFF (TOML has no
/// cones or polygon patches).
pub(super) fn is_nff(source: &SceneSource) -> bool {
    source
        .path()
        .and_then(Path::extension)
        .is_some_and(|e| e.eq_ignore_ascii_case("nff"))
}

/// Where "Save scene as" writes: chosen in a save dialog, or, without one,
/// a new name beside the scene file (`NAME-edited.toml`, then
/// `NAME-edited-2.toml`, ...); the built-in scene, which has no file, goes
/// where exports go ([`super::export::export_dir`]), never into the working
/// directory, often a checkout. `None` when the user
/// cancels.
pub fn choose_path(source: &SceneSource) -> Option<PathBuf> {
    let folder = match source.path().and_then(Path::parent) {
        Some(d) if !d.as_os_str().is_empty() => d.to_owned(),
        Some(_) => PathBuf::from("."),
        None => super::export::export_dir(),
    };
    // A copy of a copy is `NAME-edited-2`, not `NAME-edited-edited`.
    let stem = unedited_stem(&source.stem());
    let (extension, filter) = if is_nff(source) {
        ("nff", "NFF scene")
    } else {
        ("toml", "glint scene")
    };
    if file_dialog_available() {
        let name = if saves_in_place(source) {
            format!("{stem}-edited.{extension}")
        } else {
            format!("{stem}.{extension}")
        };
        return rfd::FileDialog::new()
            .set_directory(&folder)
            .set_file_name(&name)
            .add_filter(filter, &[extension])
            .save_file();
    }
    (1..)
        .map(|k| match k {
            1 => folder.join(format!("{stem}-edited.{extension}")),
            k => folder.join(format!("{stem}-edited-{k}.{extension}")),
        })
        .find(|p| !p.exists())
}

/// `stem` without the `-edited` or `-edited-K` that "save as" added.
fn unedited_stem(stem: &str) -> String {
    let base = match stem.rsplit_once("-edited-") {
        Some((base, k)) if !k.is_empty() && k.bytes().all(|b| b.is_ascii_digit()) => base,
        _ => stem.strip_suffix("-edited").unwrap_or(stem),
    };
    if base.is_empty() { stem } else { base }.to_owned()
}

/// What a save did.
pub struct Saved {
    /// The saved file, loaded back: the new "as loaded" scene.
    pub scene: Scene,
    /// Edits the file's format could not hold.
    pub left_out: Vec<crate::scene::save::LeftOut>,
}

/// Writes `edit` to `destination` (TOML, or NFF for an NFF scene) and
/// loads the file back. Only edits are written: a value the same as in
/// `baseline` (the edits as last loaded or saved) is the file's own, so a
/// command-line `--size` or octree flag, a way of looking at the scene,
/// does not end up in it.
pub fn save(edit: &EditState, baseline: &Snapshot, destination: &Path) -> anyhow::Result<Saved> {
    let extension = if is_nff(&edit.source) { "nff" } else { "toml" };
    let named_right = destination
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case(extension));
    anyhow::ensure!(
        named_right,
        "name the scene file .{extension} (glint saves {} scenes as {})",
        if extension == "nff" { "NFF" } else { "its" },
        extension.to_uppercase()
    );
    let builtin = edit.source == SceneSource::BuiltIn;
    let loaded_path = match edit.source.path() {
        Some(p) => p.to_owned(),
        None => PathBuf::from("scenes/default.toml"),
    };
    let (settings, octree) = edited_only(edit, baseline);
    let request = SaveRequest {
        loaded: &edit.loaded,
        loaded_path: &loaded_path,
        camera: &edit.camera,
        camera_path: edit.camera_path.as_ref(),
        lights: &edit.scene.lights,
        materials: &edit.scene.materials,
        settings: &settings,
        octree: &octree,
        mesh_paths: if builtin {
            MeshPaths::Beside
        } else {
            MeshPaths::Anchored
        },
    };
    let saved = if extension == "nff" {
        scene_nff(&request)?
    } else {
        scene_toml(&request, destination)?
    };
    if builtin {
        write_builtin_mesh(destination)?;
    }
    // The text must load before it replaces a file (the reload below then
    // only confirms what was written).
    crate::scene::load_str(&saved.text, destination, &crate::scene::FileSystem)?;
    crate::export::write_file_atomically(destination, saved.text.as_bytes())?;
    let scene = crate::scene::load(destination)?;
    Ok(Saved {
        scene,
        left_out: saved.left_out,
    })
}

/// The settings and octree parameters to save: each value the user has
/// not changed since `baseline` is put back to the file's.
fn edited_only(edit: &EditState, baseline: &Snapshot) -> (RenderSettings, OctreeParams) {
    let file = edit.loaded.render_settings();
    let (was, now) = (&baseline.settings, &edit.settings);
    let mut s = *now;
    if (now.width, now.height) == (was.width, was.height) {
        (s.width, s.height) = (file.width, file.height);
    }
    if (now.samples, now.adaptive) == (was.samples, was.adaptive) {
        (s.samples, s.adaptive) = (file.samples, file.adaptive);
    }
    if now.max_depth == was.max_depth {
        s.max_depth = file.max_depth;
    }
    if now.colors == was.colors {
        s.colors = file.colors;
    }
    if now.sides == was.sides {
        s.sides = file.sides;
    }
    // A scene file says the octree is on or off; the BVH is the viewer's
    // (and a PNG record's) to choose, so choosing it keeps the file's switch.
    if now.accel == was.accel || now.accel == Accel::Bvh {
        s.accel = file.accel;
    }
    let (file, was, now) = (
        &edit.loaded.octree_params,
        &baseline.octree,
        &edit.scene.octree_params,
    );
    let keep = |a: u32, b: u32, f: u32| if a == b { f } else { a };
    let octree = OctreeParams {
        max_depth: keep(now.max_depth, was.max_depth, file.max_depth),
        leaf_size: keep(now.leaf_size, was.leaf_size, file.leaf_size),
        max_duplication: keep(
            now.max_duplication,
            was.max_duplication,
            file.max_duplication,
        ),
        memory_budget_mib: keep(
            now.memory_budget_mib,
            was.memory_budget_mib,
            file.memory_budget_mib,
        ),
        cost_driven: if now.cost_driven == was.cost_driven {
            file.cost_driven
        } else {
            now.cost_driven
        },
    };
    (s, octree)
}

/// The built-in scene's mesh, written beside a copy of the scene (a file
/// of that name already there must be the same mesh).
fn write_builtin_mesh(destination: &Path) -> anyhow::Result<()> {
    let folder = match destination.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    let mesh = folder.join(crate::scene::builtin::MESH_NAME);
    match std::fs::read(&mesh) {
        Ok(bytes) if bytes == crate::scene::builtin::MESH => Ok(()),
        Ok(_) => anyhow::bail!(
            "{} exists and is not the built-in scene's bunny; save the scene in another folder",
            mesh.display()
        ),
        Err(_) => Ok(crate::export::write_file_atomically(
            &mesh,
            crate::scene::builtin::MESH,
        )?),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_copy_of_a_copy_is_numbered_not_edited_twice() {
        assert_eq!(unedited_stem("default-edited"), "default");
        assert_eq!(unedited_stem("default-edited-12"), "default");
        assert_eq!(unedited_stem("default"), "default");
        assert_eq!(unedited_stem("my-edited-scene"), "my-edited-scene");
        assert_eq!(unedited_stem("-edited"), "-edited");
        assert_eq!(unedited_stem("a-edited-x"), "a-edited-x");
    }

    #[test]
    fn the_built_in_scene_is_never_saved_into_the_working_directory() {
        if file_dialog_available() {
            return; // a dialog would ask; nothing to check headless
        }
        let path = choose_path(&SceneSource::BuiltIn).unwrap();
        let folder = path.parent().unwrap();
        assert_ne!(
            std::fs::canonicalize(folder).unwrap(),
            std::fs::canonicalize(std::env::current_dir().unwrap()).unwrap(),
            "{}",
            path.display()
        );
        assert!(
            path.ends_with("default-edited.toml")
                || path.to_string_lossy().contains("default-edited-")
        );
    }
}
