//! The image files materials name, found beside the file that names them
//! and decoded once each however many materials use them.
//!
//! A material file written on another machine names its textures as that
//! machine saw them: `\` separators, absolute paths, names whose case the
//! files on disk do not share. glint looks for the path as written (with
//! `\` read as `/`) inside the naming file's folder, then for its file name
//! alone there, each also without regard to case. A path that climbs out
//! of the folder is not followed, as for material libraries.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use super::file_source::{FileSource, inside_folder};
use super::model::Scene;
use crate::texture::Texture;

/// Where the file naming a texture comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Namer {
    /// A model's material file, shared with the model: its textures are
    /// looked for inside its folder only.
    Model,
    /// A scene file the user wrote: its paths go where they say, as its
    /// mesh paths do.
    Scene,
}

/// Index in `scene.textures` of the image `written` names, from a file in
/// `folder`: read and decoded the first time any material names it.
pub(super) fn texture_index(
    scene: &mut Scene,
    folder: &Path,
    written: &str,
    namer: Namer,
    files: &dyn FileSource,
) -> Result<u32, String> {
    let mut looked_at = Vec::new();
    for relative in candidates(written, namer) {
        let path = folder.join(&relative);
        if let Some(i) = scene.textures.iter().position(|t| t.path == path) {
            return Ok(i as u32);
        }
        let found = match files.read(&path) {
            Ok(bytes) => Some((path.clone(), bytes)),
            Err(_) => same_path_any_case(folder, &relative, files),
        };
        if let Some((path, bytes)) = found {
            if let Some(i) = scene.textures.iter().position(|t| t.path == path) {
                return Ok(i as u32);
            }
            let texture =
                Texture::decode(&path, &bytes).map_err(|e| format!("{}: {e}", path.display()))?;
            scene.textures.push(Arc::new(texture));
            return Ok(scene.textures.len() as u32 - 1);
        }
        looked_at.push(path.display().to_string());
    }
    Err(if looked_at.is_empty() {
        "it has no file name".into()
    } else {
        format!("no such file (looked for {})", looked_at.join(" and "))
    })
}

/// Where `written` may be, relative to the naming file's folder, in the
/// order tried: the path as written (if it stays inside the folder), then
/// its file name alone, then that name in a `textures` folder.
fn candidates(written: &str, namer: Namer) -> Vec<PathBuf> {
    let normalized = written.trim().replace('\\', "/");
    let mut out = Vec::new();
    if namer == Namer::Scene || inside_folder(Path::new(""), &normalized).is_some() {
        out.push(PathBuf::from(&normalized));
    }
    // Then the file name alone, beside the naming file and in a
    // `textures` folder there (where exporters and asset packs put them).
    if let Some(name) = Path::new(&normalized).file_name() {
        for p in [PathBuf::from(name), Path::new("textures").join(name)] {
            if !out.contains(&p) {
                out.push(p);
            }
        }
    }
    out
}

/// The file at `relative` under `folder` whose every folder and file name
/// equals the written one but for case, with its bytes: the exact name
/// where the folder has it, else the first that differs only in case.
fn same_path_any_case(
    folder: &Path,
    relative: &Path,
    files: &dyn FileSource,
) -> Option<(PathBuf, Vec<u8>)> {
    use std::path::Component;
    let mut at = folder.to_path_buf();
    for component in relative.components() {
        let Component::Normal(name) = component else {
            at.push(component);
            continue;
        };
        let names = files.file_names(&at);
        let wanted = name.to_str()?;
        let found = names.iter().find(|n| n.as_os_str() == name).or_else(|| {
            names
                .iter()
                .find(|n| n.to_str().is_some_and(|n| n.eq_ignore_ascii_case(wanted)))
        })?;
        at.push(found);
    }
    files.read(&at).ok().map(|bytes| (at, bytes))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::camera::CameraSpec;
    use std::collections::BTreeMap;

    struct Files(BTreeMap<PathBuf, Vec<u8>>);

    impl FileSource for Files {
        fn read(&self, path: &Path) -> std::io::Result<Vec<u8>> {
            self.0
                .get(path)
                .cloned()
                .ok_or_else(|| std::io::Error::from(std::io::ErrorKind::NotFound))
        }
        /// Every file and folder directly in `folder`.
        fn file_names(&self, folder: &Path) -> Vec<std::ffi::OsString> {
            let mut names: Vec<std::ffi::OsString> = self
                .0
                .keys()
                .flat_map(|p| p.ancestors().collect::<Vec<_>>())
                .filter(|p| p.parent() == Some(folder))
                .filter_map(|p| p.file_name().map(|n| n.to_owned()))
                .collect();
            names.sort();
            names.dedup();
            names
        }
    }

    fn png() -> Vec<u8> {
        let mut bytes = Vec::new();
        image::RgbImage::from_raw(1, 1, vec![200, 100, 50])
            .unwrap()
            .write_to(
                &mut std::io::Cursor::new(&mut bytes),
                image::ImageFormat::Png,
            )
            .unwrap();
        bytes
    }

    fn scene() -> Scene {
        let camera = CameraSpec {
            eye: glam::DVec3::Z,
            lookat: glam::DVec3::ZERO,
            up: glam::DVec3::Y,
            fov: 45.0,
        };
        Scene::empty("t".into(), camera, Default::default())
    }

    #[test]
    fn windows_paths_any_case_and_absolute_paths_find_the_file_beside_it() {
        let files = Files(BTreeMap::from([
            (PathBuf::from("m/tex/Wood.PNG"), png()),
            (PathBuf::from("m/leaf.png"), png()),
        ]));
        let mut s = scene();
        let folder = Path::new("m");
        assert_eq!(
            texture_index(&mut s, folder, "tex\\wood.png", Namer::Model, &files),
            Ok(0)
        );
        // The same file by another spelling is decoded once.
        assert_eq!(
            texture_index(&mut s, folder, "TEX/wood.png", Namer::Model, &files),
            Ok(0)
        );
        assert_eq!(
            texture_index(
                &mut s,
                folder,
                "C:\\Users\\me\\Desktop\\leaf.png",
                Namer::Model,
                &files
            ),
            Ok(1)
        );
        assert_eq!(s.textures.len(), 2);
        assert_eq!(s.textures[0].path, Path::new("m/tex/Wood.PNG"));
        let e = texture_index(&mut s, folder, "../outside/leaf2.png", Namer::Model, &files)
            .unwrap_err();
        assert!(
            e.contains("no such file (looked for m/leaf2.png and m/textures/leaf2.png)"),
            "{e}"
        );
        // A scene file's own path goes where it says.
        let e = texture_index(&mut s, folder, "../outside/leaf2.png", Namer::Scene, &files)
            .unwrap_err();
        assert!(
            e.contains("looked for m/../outside/leaf2.png and m/leaf2.png"),
            "{e}"
        );
        let e = texture_index(&mut s, folder, "gone.png", Namer::Model, &files).unwrap_err();
        assert!(e.contains("m/gone.png"), "{e}");
    }

    #[test]
    fn a_file_that_is_no_image_is_named_with_the_reason() {
        let files = Files(BTreeMap::from([(
            PathBuf::from("m/t.png"),
            b"text".to_vec(),
        )]));
        let e =
            texture_index(&mut scene(), Path::new("m"), "t.png", Namer::Model, &files).unwrap_err();
        assert!(e.starts_with("m/t.png: not an image glint reads"), "{e}");
    }
}
