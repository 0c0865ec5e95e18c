//! Mesh paths in a saved scene: a relative path names the same file from
//! the saved scene's folder as from the loaded one's.

use std::path::{Path, PathBuf};

use toml_edit::{DocumentMut, Item, Value};

use super::{set, tables_of};

use super::MeshPaths;

/// Rewrites relative mesh paths so the saved file finds the same meshes.
pub(super) fn write_mesh_paths(
    doc: &mut DocumentMut,
    loaded_path: &Path,
    destination: &Path,
    how: MeshPaths,
) {
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
