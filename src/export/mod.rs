//! Reproducible PNG exports: every PNG glint writes carries the glint
//! version, the scene file's SHA-256 and full text, and every setting that
//! shaped the image, so `glint render --from-png` can render it again and
//! `glint info` can say how it was made.
//!
//! The small parts are standard iTXt text chunks, which any PNG tool shows.
//! The scene text can be megabytes (gears.nff is 1.3 MB), and common readers
//! refuse text chunks that decompress past 1 MB (Pillow's
//! `MAX_TEXT_CHUNK`), so it goes in a private ancillary chunk, `glSc`, that
//! readers skip: zlib-compressed UTF-8, written before the image data.
//!
//! Files: `record.rs` (what a record holds), `png_file.rs` (its chunks),
//! `output.rs` (where the bytes go), `error.rs`.

mod error;
mod output;
mod png_file;
mod record;

use std::path::Path;

pub use error::ExportError;
pub use output::{
    OutputTarget, check_output, remove_unfinished_outputs, replaced_non_png, save_animation,
    save_rgb_png, write_file_atomically,
};
pub use png_file::{read_record, read_record_bytes};
pub use record::{
    KEY_SCENE, KEY_SCENE_PATH, KEY_SCENE_SHA256, KEY_SETTINGS, KEY_VERSION, MAX_EMBEDDED_SCENE,
    MAX_SCENE_TEXT, RecordedCamera, RecordedFrame, RecordedSettings, RenderRecord, SCENE_CHUNK,
    SceneEdits, absolute_name, sha256_hex,
};

use crate::accel::Octree;
use crate::camera::{Camera, CameraSpec};
use crate::image::frame::Frame;
use crate::scene::Scene;
use crate::settings::RenderSettings;

/// Writes `frame` as PNG (with the legend strip of diagnostic views) and,
/// when given, its record; see [`save_rgb_png`] for where the bytes go.
pub fn save_png(
    frame: &Frame,
    path: &Path,
    record: Option<&RenderRecord>,
) -> Result<(), ExportError> {
    let (rgb, height) = frame.to_annotated_rgb8();
    save_rgb_png(path, frame.width, height, &rgb, record)
}

/// The PNG file `save_rgb_png` would write, as bytes in memory; `path`
/// names it in errors.
pub fn png_bytes(
    path: &Path,
    width: u32,
    height: u32,
    rgb: &[u8],
    record: Option<&RenderRecord>,
) -> Result<Vec<u8>, ExportError> {
    let mut out = Vec::new();
    png_file::write_png(&mut out, path, width, height, rgb, record)?;
    Ok(out)
}

/// The octree overlay to draw into an export: its cells down to `depth`,
/// projected through `camera`.
pub struct OverlayRequest<'a> {
    pub octree: &'a Octree,
    pub camera: &'a Camera,
    pub depth: u32,
}

/// Writes `frame` as `glint render` does, with `record`: the legend strip
/// of diagnostic views, and the octree overlay drawn in (and recorded) when
/// asked for.
pub fn save_frame(
    frame: &Frame,
    path: &Path,
    record: &mut RenderRecord,
    overlay: Option<OverlayRequest>,
) -> Result<(), ExportError> {
    let legend = record.settings.legend;
    match overlay {
        Some(o) => {
            record.settings.overlay_depth = Some(o.depth);
            let cells = o.octree.cells(o.depth);
            let (rgb, height) =
                crate::image::overlay::annotate(frame, o.camera, &cells, o.depth, legend);
            save_rgb_png(path, frame.width, height, &rgb, Some(record))
        }
        None if legend => save_png(frame, path, Some(record)),
        None => save_rgb_png(
            path,
            frame.width,
            frame.height,
            &frame.to_rgb8(),
            Some(record),
        ),
    }
}

/// The record `glint render` writes for `scene` (named `scene_name` as the
/// user gave it) seen from `camera` with `settings`. The record names the
/// scene file by its absolute path, as the viewer's exports do, so
/// `--from-png` finds it and its meshes from any folder (the built-in
/// scene keeps its name; `--stats` keeps the path as given).
pub fn render_record(
    scene: &Scene,
    scene_name: &str,
    camera: &CameraSpec,
    settings: RenderSettings,
) -> RenderRecord {
    let recorded_path = if scene_name == crate::scene::builtin::NAME {
        scene_name.to_owned()
    } else {
        absolute_name(Path::new(scene_name))
    };
    RenderRecord::new(scene, &recorded_path, camera, settings)
}

/// A render restored from the record of a PNG: its scene (with the
/// recorded octree parameters and viewer edits), settings, camera and
/// overlay, and what the user should know about it.
pub struct Restored {
    pub scene: Scene,
    /// The scene file as the record names it.
    pub scene_path: String,
    pub settings: RenderSettings,
    pub camera: CameraSpec,
    pub overlay_depth: Option<u32>,
    /// Whether the legend strip is drawn (diagnostic views, the overlay).
    pub legend: bool,
    /// The frame of a sequence the PNG is, if it is one.
    pub frame: Option<RecordedFrame>,
    /// Notes for the user: another glint version, a partial export.
    pub notes: Vec<String>,
}

/// Reads `png`'s record and loads what it recorded, to render it again.
pub fn restore(png: &Path) -> Result<Restored, ExportError> {
    let record = read_record(png)?;
    let scene = load_recorded_scene(&record)?;
    let mut notes = Vec::new();
    if record.glint_version != env!("CARGO_PKG_VERSION") {
        notes.push(format!(
            "{} was made by glint {}, this is {}: pixels may differ",
            png.display(),
            record.glint_version,
            env!("CARGO_PKG_VERSION")
        ));
    }
    // Meshes, material libraries and textures are not embedded: a changed
    // texture recolours the picture, so it is refused; for the others, say
    // which changed since the export (the picture may then differ).
    for file in &record.settings.files {
        let now = scene
            .files_read
            .iter()
            .find(|f| absolute_name(&f.path) == file.path);
        let changed = now.is_none_or(|f| f.sha256 != file.sha256);
        if changed && is_texture(&scene, &file.path) {
            return Err(ExportError::TextureChanged {
                texture: file.path.clone(),
                png: png.to_owned(),
                found: now.is_some(),
            });
        }
        if changed {
            notes.push(format!(
                "{} has changed since {} was made (its SHA-256 differs from the recorded one): \
                 pixels may differ",
                file.path,
                png.display()
            ));
        }
    }
    if record.settings.partial {
        notes.push(format!(
            "{} was exported while a pass was still rendering; this renders the whole pass",
            png.display()
        ));
    }
    Ok(Restored {
        scene,
        scene_path: record.scene_path,
        settings: record.settings.render,
        camera: record.settings.camera.into(),
        overlay_depth: record.settings.overlay_depth,
        legend: record.settings.legend,
        frame: record.settings.frame,
        notes,
    })
}

/// Whether the recorded file `path` is one of `scene`'s textures, or an
/// image that can be nothing else (a texture no longer found).
fn is_texture(scene: &Scene, path: &str) -> bool {
    let image = std::path::Path::new(path)
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| {
            ["png", "jpg", "jpeg", "tga", "bmp"].contains(&e.to_ascii_lowercase().as_str())
        });
    image
        || scene
            .textures
            .iter()
            .any(|t| absolute_name(&t.path) == path)
}

/// The scene a record was made from: parsed from its embedded text, with
/// meshes read relative to the recorded path (or from the binary for the
/// built-in scene).
pub fn load_recorded_scene(record: &RenderRecord) -> Result<Scene, ExportError> {
    load_recorded_scene_with(record, &crate::scene::FileSystem)
}

/// Like [`load_recorded_scene`], reading meshes from `files`.
pub fn load_recorded_scene_with(
    record: &RenderRecord,
    files: &dyn crate::scene::FileSource,
) -> Result<Scene, ExportError> {
    let mut scene = if record.scene_path == crate::scene::builtin::NAME {
        crate::scene::builtin::load_text(&record.scene_text)?
    } else if record.settings.scene_not_embedded {
        // Too large to embed: the file itself, as long as it is the same.
        let path = Path::new(&record.scene_path);
        let bytes = files.read(path).ok();
        if bytes.as_deref().map(sha256_hex).as_ref() != Some(&record.scene_sha256) {
            return Err(ExportError::SceneNotEmbedded {
                path: record.scene_path.clone(),
                sha256: record.scene_sha256.clone(),
                found: bytes.is_some(),
            });
        }
        crate::scene::load_with(path, files)?
    } else {
        crate::scene::load_str(&record.scene_text, Path::new(&record.scene_path), files)?
    };
    scene.octree_params = record.settings.octree_params;
    if let Some(edits) = &record.settings.edits {
        // Edits made in the viewer keep the file's counts; anything else
        // means the record does not belong to this scene text.
        if edits.lights.len() != scene.lights.len()
            || edits.materials.len() != scene.materials.len()
        {
            return Err(ExportError::EditsMismatch {
                scene: record.scene_path.clone(),
            });
        }
        scene.lights = edits.lights.clone();
        scene.materials = edits.materials.clone();
    }
    Ok(scene)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sha256_matches_the_fips_180_examples() {
        assert_eq!(
            sha256_hex(b"abc"),
            "ba7816bf8f01cfea414140de5dae2223b00361a396177a9cb410ff61f20015ad"
        );
        assert_eq!(
            sha256_hex(b""),
            "e3b0c44298fc1c149afbf4c8996fb92427ae41e4649b934ca495991b7852b855"
        );
    }

    fn record() -> RenderRecord {
        let scene = crate::scene::builtin::default_scene().unwrap();
        let mut settings = scene.render_settings();
        settings.width = 4;
        settings.height = 2;
        RenderRecord::new(&scene, crate::scene::builtin::NAME, &scene.camera, settings)
    }

    /// A 4x2 image with a different colour in every pixel.
    fn pixels() -> Vec<u8> {
        (0..24u8).map(|k| k * 10).collect()
    }

    #[test]
    fn a_record_and_the_pixels_read_back_as_written() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("round.png");
        let written = record();
        save_rgb_png(&path, 4, 2, &pixels(), Some(&written)).unwrap();
        assert_eq!(read_record(&path).unwrap(), written);
        let image = image::open(&path).unwrap().to_rgb8();
        assert_eq!(image.dimensions(), (4, 2));
        assert_eq!(image.into_raw(), pixels());
        // The scene it names loads again from the embedded text.
        let scene = load_recorded_scene(&written).unwrap();
        assert_eq!(scene.source_text.as_ref(), written.scene_text);
    }

    #[test]
    fn a_tampered_or_damaged_record_is_refused() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("tampered.png");
        let mut wrong = record();
        wrong.scene_sha256 = sha256_hex(b"another scene");
        save_rgb_png(&path, 4, 2, &pixels(), Some(&wrong)).unwrap();
        assert!(matches!(
            read_record(&path),
            Err(ExportError::Checksum { .. })
        ));

        // One flipped bit inside the scene chunk: its CRC no longer matches.
        save_rgb_png(&path, 4, 2, &pixels(), Some(&record())).unwrap();
        let mut bytes = std::fs::read(&path).unwrap();
        let at = bytes.windows(4).position(|w| w == SCENE_CHUNK).unwrap();
        bytes[at + 10] ^= 1;
        std::fs::write(&path, &bytes).unwrap();
        assert!(matches!(
            read_record(&path),
            Err(ExportError::Decode { .. })
        ));

        // Settings outside the limits scene files are held to.
        let mut deep = record();
        deep.settings.render.max_depth = 0;
        save_rgb_png(&path, 4, 2, &pixels(), Some(&deep)).unwrap();
        assert!(matches!(
            read_record(&path),
            Err(ExportError::Malformed {
                key: KEY_SETTINGS,
                ..
            })
        ));

        // A PNG without a record.
        save_rgb_png(&path, 4, 2, &pixels(), None).unwrap();
        assert!(matches!(
            read_record(&path),
            Err(ExportError::Missing { .. })
        ));
    }

    #[test]
    fn outputs_must_be_png_files_other_than_the_input() {
        let dir = tempfile::tempdir().unwrap();
        let scene = dir.path().join("scene.toml");
        std::fs::write(&scene, "").unwrap();
        let out = dir.path().join("out.png");
        assert_eq!(
            check_output(&out, Some(&scene)).unwrap(),
            OutputTarget::File(out.clone())
        );
        assert!(matches!(
            check_output(&dir.path().join("out.jpg"), None),
            Err(ExportError::NotPng { .. })
        ));
        // The scene itself, even named .png or reached through a link.
        let png_scene = dir.path().join("scene.png");
        std::fs::write(&png_scene, "").unwrap();
        let link = dir.path().join("link.png");
        std::os::unix::fs::symlink(&png_scene, &link).unwrap();
        assert!(matches!(
            check_output(&link, Some(&png_scene)),
            Err(ExportError::IsInput { .. })
        ));
        // A .png link to a file of another kind is named by where it leads.
        let toml_link = dir.path().join("toml-link.png");
        std::os::unix::fs::symlink(&scene, &toml_link).unwrap();
        let e = check_output(&toml_link, None).unwrap_err();
        assert!(matches!(e, ExportError::LinkNotPng { .. }), "{e}");
        assert!(e.to_string().contains("leads to"), "{e}");
        assert_eq!(
            check_output(Path::new("-"), None).unwrap(),
            OutputTarget::Stdout
        );
        assert!(matches!(
            check_output(Path::new("/dev/null"), None).unwrap(),
            OutputTarget::Special(_)
        ));
    }

    #[test]
    fn a_link_to_a_file_not_yet_there_writes_the_file_it_names() {
        let dir = tempfile::tempdir().unwrap();
        let link = dir.path().join("latest.png");
        std::os::unix::fs::symlink("renders/frame.png", &link).unwrap();
        assert_eq!(
            OutputTarget::resolve(&link).unwrap(),
            OutputTarget::File(dir.path().join("renders/frame.png"))
        );
    }
}
