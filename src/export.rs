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

use std::path::{Path, PathBuf};

use serde::{Deserialize, Serialize};

use crate::accel::OctreeParams;
use crate::camera::CameraSpec;
use crate::frame::Frame;
use crate::math::DVec3;
use crate::scene::Scene;
use crate::settings::RenderSettings;

/// Text-chunk keywords. Part of the file format: never rename them.
pub const KEY_VERSION: &str = "glint:version";
pub const KEY_SCENE_PATH: &str = "glint:scene-path";
pub const KEY_SCENE_SHA256: &str = "glint:scene-sha256";
pub const KEY_SCENE: &str = "glint:scene";
pub const KEY_SETTINGS: &str = "glint:settings";
/// The private chunk holding the scene text (ancillary, private,
/// safe to copy: lower, lower, upper, lower).
pub const SCENE_CHUNK: [u8; 4] = *b"glSc";
/// Largest scene text a record may hold once decompressed: far above any
/// scene file (the largest SPD size, tetra_s8, is 5 MB), and a bound on
/// what a crafted PNG can make glint allocate.
pub const MAX_SCENE_TEXT: usize = 256 << 20;

/// How an image was made: enough to make it again.
#[derive(Clone, Debug, PartialEq)]
pub struct RenderRecord {
    pub glint_version: String,
    /// The scene file as it was named when loaded (anchors relative mesh paths).
    pub scene_path: String,
    pub scene_sha256: String,
    pub scene_text: String,
    pub settings: RecordedSettings,
}

/// The settings part of a record, stored as JSON.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RecordedSettings {
    pub camera: RecordedCamera,
    #[serde(flatten)]
    pub render: RenderSettings,
    pub octree_params: OctreeParams,
    /// Octree overlay drawn down to this level, if any.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub overlay_depth: Option<u32>,
    /// Lights and materials as edited in the viewer, replacing the scene
    /// file's (absent when they are the file's own).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub edits: Option<SceneEdits>,
    /// Exported from the viewer while a pass was still sweeping in: the
    /// pixels are part old, part new, and a re-render gives the whole pass.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub partial: bool,
}

/// Lights and materials that replace a scene file's own.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SceneEdits {
    pub lights: Vec<crate::material::Light>,
    pub materials: Vec<crate::material::Material>,
}

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RecordedCamera {
    pub eye: [f64; 3],
    pub lookat: [f64; 3],
    pub up: [f64; 3],
    pub fov: f64,
}

impl From<&CameraSpec> for RecordedCamera {
    fn from(c: &CameraSpec) -> Self {
        Self {
            eye: c.eye.to_array(),
            lookat: c.lookat.to_array(),
            up: c.up.to_array(),
            fov: c.fov,
        }
    }
}

impl From<RecordedCamera> for CameraSpec {
    fn from(c: RecordedCamera) -> Self {
        Self {
            eye: DVec3::from_array(c.eye),
            lookat: DVec3::from_array(c.lookat),
            up: DVec3::from_array(c.up),
            fov: c.fov,
        }
    }
}

impl RenderRecord {
    /// The record of rendering `scene` (named `scene_path`) from `camera`
    /// with `settings`.
    pub fn new(
        scene: &Scene,
        scene_path: &str,
        camera: &CameraSpec,
        settings: RenderSettings,
    ) -> Self {
        Self {
            glint_version: env!("CARGO_PKG_VERSION").to_string(),
            scene_path: scene_path.to_string(),
            scene_sha256: sha256_hex(scene.source_text.as_bytes()),
            scene_text: scene.source_text.to_string(),
            settings: RecordedSettings {
                camera: camera.into(),
                render: settings,
                octree_params: scene.octree_params,
                overlay_depth: None,
                edits: None,
                partial: false,
            },
        }
    }
}

#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    #[error("cannot write {path}")]
    Write {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error(
        "{path}: glint writes PNG images; name the output .png (or give - for standard output)"
    )]
    NotPng { path: PathBuf },
    #[error("{path} is the scene being rendered; choose another output file")]
    IsInput { path: PathBuf },
    #[error("cannot encode {path} as PNG: {message}")]
    Encode { path: PathBuf, message: String },
    #[error("cannot read {path}")]
    Read {
        path: PathBuf,
        source: std::io::Error,
    },
    #[error("{path} is not a readable PNG: {message}")]
    Decode { path: PathBuf, message: String },
    #[error(
        "{path} carries no glint metadata (text chunk `{key}` is missing): it was not written by glint, or was re-saved by a program that dropped it"
    )]
    Missing { path: PathBuf, key: &'static str },
    #[error("{path}: text chunk `{key}` is malformed: {message}")]
    Malformed {
        path: PathBuf,
        key: &'static str,
        message: String,
    },
    #[error(transparent)]
    Scene(#[from] crate::scene::SceneError),
    #[error("the recorded light and material edits do not fit the recorded scene {scene}")]
    EditsMismatch { scene: String },
    #[error(
        "{path}: the embedded scene text does not match its SHA-256 (recorded {recorded}, computed {computed})"
    )]
    Checksum {
        path: PathBuf,
        recorded: String,
        computed: String,
    },
}

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

/// Where an output path's bytes go.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum OutputTarget {
    /// `-`: standard output.
    Stdout,
    /// A FIFO, a character or block device or a socket: written directly,
    /// never replaced.
    Special(PathBuf),
    /// A regular file (or a name not yet taken), after following symbolic
    /// links: written to a temporary file next to it, renamed into place,
    /// so a failed write never leaves a truncated image and a symbolic link
    /// keeps pointing at its (updated) target.
    File(PathBuf),
}

impl OutputTarget {
    /// Resolves `path` (`-` for standard output).
    pub fn resolve(path: &Path) -> Result<Self, ExportError> {
        if path.as_os_str() == "-" {
            return Ok(OutputTarget::Stdout);
        }
        use std::os::unix::fs::FileTypeExt;
        match std::fs::metadata(path) {
            Ok(m) => {
                let t = m.file_type();
                if t.is_fifo() || t.is_char_device() || t.is_block_device() || t.is_socket() {
                    return Ok(OutputTarget::Special(path.to_owned()));
                }
                if t.is_dir() {
                    return Err(ExportError::Write {
                        path: path.to_owned(),
                        source: std::io::Error::other("it is a directory"),
                    });
                }
                // An existing file, possibly behind symbolic links.
                let target = std::fs::canonicalize(path).map_err(|source| ExportError::Write {
                    path: path.to_owned(),
                    source,
                })?;
                Ok(OutputTarget::File(target))
            }
            Err(_) => Ok(OutputTarget::File(dangling_link_target(path))),
        }
    }

    /// The regular file the output ends up in, if any.
    pub fn file(&self) -> Option<&Path> {
        match self {
            OutputTarget::File(p) => Some(p),
            _ => None,
        }
    }
}

/// Checks an output path before any work is done: a file must be named
/// `.png` (glint writes PNG, and a PNG under another name misleads), and
/// must not be the scene being rendered (`input`). Standard output, FIFOs
/// and devices take PNG bytes whatever their name.
pub fn check_output(path: &Path, input: Option<&Path>) -> Result<OutputTarget, ExportError> {
    let target = OutputTarget::resolve(path)?;
    if let Some(file) = target.file() {
        let is_png = file
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| e.eq_ignore_ascii_case("png"));
        if !is_png {
            return Err(ExportError::NotPng {
                path: path.to_owned(),
            });
        }
        if let Some(input) = input
            && let Ok(input) = std::fs::canonicalize(input)
            && input == file
        {
            return Err(ExportError::IsInput {
                path: path.to_owned(),
            });
        }
    }
    Ok(target)
}

/// The file a new output named `path` creates: `path` itself, or the
/// target of a symbolic link that points at a file not yet there.
fn dangling_link_target(path: &Path) -> PathBuf {
    let mut current = path.to_owned();
    // Follow a bounded chain of links, as the kernel does.
    for _ in 0..40 {
        match std::fs::read_link(&current) {
            Ok(target) => {
                current = match current.parent() {
                    Some(dir) if target.is_relative() => dir.join(target),
                    _ => target,
                };
            }
            Err(_) => return current,
        }
    }
    current
}

/// Writes an RGB8 picture (already annotated) as PNG with its record:
/// to standard output for `-`, straight into FIFOs and devices, and for
/// files through a temporary file next to the target (following symbolic
/// links) renamed into place.
pub fn save_rgb_png(
    path: &Path,
    width: u32,
    height: u32,
    rgb: &[u8],
    record: Option<&RenderRecord>,
) -> Result<(), ExportError> {
    let write_error = |source| ExportError::Write {
        path: path.to_owned(),
        source,
    };
    match OutputTarget::resolve(path)? {
        OutputTarget::Stdout => {
            use std::io::Write;
            let mut bytes = Vec::new();
            write_png(&mut bytes, path, width, height, rgb, record)?;
            let mut out = std::io::stdout().lock();
            out.write_all(&bytes)
                .and_then(|()| out.flush())
                .map_err(write_error)
        }
        OutputTarget::Special(p) => {
            let file = std::fs::OpenOptions::new()
                .write(true)
                .open(&p)
                .map_err(write_error)?;
            let mut w = std::io::BufWriter::new(file);
            write_png(&mut w, path, width, height, rgb, record)?;
            use std::io::Write;
            w.flush().map_err(write_error)
        }
        OutputTarget::File(target) => {
            let dir = match target.parent() {
                Some(d) if !d.as_os_str().is_empty() => d.to_owned(),
                _ => PathBuf::from("."),
            };
            // A replaced file keeps its permissions; a new one gets the
            // usual 0666 less the umask (tempfile's own default is 0600).
            use std::os::unix::fs::PermissionsExt;
            let permissions = std::fs::metadata(&target)
                .map(|m| m.permissions())
                .unwrap_or_else(|_| std::fs::Permissions::from_mode(0o666));
            let tmp = tempfile::Builder::new()
                .prefix(".glint-")
                .suffix(".png.tmp")
                .permissions(permissions)
                .tempfile_in(&dir)
                .map_err(write_error)?;
            {
                let mut w = std::io::BufWriter::new(tmp.as_file());
                write_png(&mut w, path, width, height, rgb, record)?;
                use std::io::Write;
                w.flush().map_err(write_error)?;
            }
            // Dropped (and deleted) on any error above.
            tmp.persist(&target).map_err(|e| write_error(e.error))?;
            Ok(())
        }
    }
}

/// Encodes the PNG into `out`; errors name `path`, the file the user asked for.
fn write_png(
    out: impl std::io::Write,
    path: &Path,
    width: u32,
    height: u32,
    rgb: &[u8],
    record: Option<&RenderRecord>,
) -> Result<(), ExportError> {
    let encode = |e: png::EncodingError| ExportError::Encode {
        path: path.to_owned(),
        message: e.to_string(),
    };
    let mut encoder = png::Encoder::new(out, width, height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder
        .add_text_chunk(
            "Software".into(),
            format!("glint {}", env!("CARGO_PKG_VERSION")),
        )
        .map_err(encode)?;
    let mut writer = encoder.write_header().map_err(encode)?;
    if let Some(r) = record {
        let settings = serde_json::to_string(&r.settings).map_err(|e| ExportError::Encode {
            path: path.to_owned(),
            message: e.to_string(),
        })?;
        for (key, text) in [
            (KEY_VERSION, r.glint_version.as_str()),
            (KEY_SCENE_PATH, r.scene_path.as_str()),
            (KEY_SCENE_SHA256, r.scene_sha256.as_str()),
            (KEY_SETTINGS, settings.as_str()),
        ] {
            let mut chunk = png::text_metadata::ITXtChunk::new(key, text);
            // Settings with many edited materials can grow; compressed they
            // stay far below what readers accept.
            chunk.compressed = text.len() > 1024;
            writer.write_text_chunk(&chunk).map_err(encode)?;
        }
        let scene = compress(r.scene_text.as_bytes()).map_err(|e| ExportError::Encode {
            path: path.to_owned(),
            message: e.to_string(),
        })?;
        writer
            .write_chunk(png::chunk::ChunkType(SCENE_CHUNK), &scene)
            .map_err(encode)?;
    }
    writer.write_image_data(rgb).map_err(encode)?;
    writer.finish().map_err(encode)
}

/// Reads the record glint wrote into a PNG.
pub fn read_record(path: &Path) -> Result<RenderRecord, ExportError> {
    let file = std::fs::File::open(path).map_err(|source| ExportError::Read {
        path: path.to_owned(),
        source,
    })?;
    let decode = |message: String| ExportError::Decode {
        path: path.to_owned(),
        message,
    };
    // glint writes its text chunks before the image data, so reading the
    // header chunks is enough: the pixels are never decoded (a crafted
    // header cannot make this allocate).
    let reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .map_err(|e| decode(e.to_string()))?;
    let info = reader.info();
    let text = |key: &'static str| -> Result<String, ExportError> {
        let chunk = info
            .utf8_text
            .iter()
            .find(|c| c.keyword == key)
            .ok_or_else(|| ExportError::Missing {
                path: path.to_owned(),
                key,
            })?;
        chunk.get_text().map_err(|e| ExportError::Malformed {
            path: path.to_owned(),
            key,
            message: e.to_string(),
        })
    };
    let settings_json = text(KEY_SETTINGS)?;
    let settings: RecordedSettings =
        serde_json::from_str(&settings_json).map_err(|e| ExportError::Malformed {
            path: path.to_owned(),
            key: KEY_SETTINGS,
            message: e.to_string(),
        })?;
    // Records written before the private chunk existed keep the scene in
    // an iTXt chunk.
    let scene_text = match private_chunk(path, SCENE_CHUNK)? {
        Some(data) => decompress(&data).map_err(|message| ExportError::Malformed {
            path: path.to_owned(),
            key: KEY_SCENE,
            message,
        })?,
        None => text(KEY_SCENE)?,
    };
    let record = RenderRecord {
        glint_version: text(KEY_VERSION)?,
        scene_path: text(KEY_SCENE_PATH)?,
        scene_sha256: text(KEY_SCENE_SHA256)?,
        scene_text,
        settings,
    };
    validate(&record.settings).map_err(|message| ExportError::Malformed {
        path: path.to_owned(),
        key: KEY_SETTINGS,
        message,
    })?;
    let computed = sha256_hex(record.scene_text.as_bytes());
    if computed != record.scene_sha256 {
        return Err(ExportError::Checksum {
            path: path.to_owned(),
            recorded: record.scene_sha256,
            computed,
        });
    }
    Ok(record)
}

/// SHA-256 of `bytes` as 64 lowercase hex digits (FIPS 180-4, `sha2`).
pub fn sha256_hex(bytes: &[u8]) -> String {
    use sha2::Digest;
    format!("{:x}", sha2::Sha256::digest(bytes))
}

fn compress(data: &[u8]) -> std::io::Result<Vec<u8>> {
    use std::io::Write;
    let mut encoder = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
    encoder.write_all(data)?;
    encoder.finish()
}

/// Inflates a zlib stream into UTF-8 text of at most [`MAX_SCENE_TEXT`] bytes.
fn decompress(data: &[u8]) -> Result<String, String> {
    use std::io::Read;
    let mut out = Vec::new();
    flate2::read::ZlibDecoder::new(data)
        .take(MAX_SCENE_TEXT as u64 + 1)
        .read_to_end(&mut out)
        .map_err(|e| format!("cannot decompress: {e}"))?;
    if out.len() > MAX_SCENE_TEXT {
        return Err(format!("scene text exceeds {MAX_SCENE_TEXT} bytes"));
    }
    String::from_utf8(out).map_err(|e| format!("not UTF-8 text: {e}"))
}

/// The data of the first chunk of type `kind` before the image data, if
/// any. The png crate skips chunks it does not know, so glint walks the
/// chunk list itself (PNG spec, section 5.3: length, type, data, CRC).
fn private_chunk(path: &Path, kind: [u8; 4]) -> Result<Option<Vec<u8>>, ExportError> {
    use std::io::Read;
    let decode = |message: &str| ExportError::Decode {
        path: path.to_owned(),
        message: message.to_owned(),
    };
    let mut file =
        std::io::BufReader::new(
            std::fs::File::open(path).map_err(|source| ExportError::Read {
                path: path.to_owned(),
                source,
            })?,
        );
    let read_error = |source| ExportError::Read {
        path: path.to_owned(),
        source,
    };
    let mut signature = [0u8; 8];
    file.read_exact(&mut signature).map_err(read_error)?;
    if signature != *b"\x89PNG\r\n\x1a\n" {
        return Err(decode("not a PNG file"));
    }
    loop {
        let mut header = [0u8; 8];
        if file.read_exact(&mut header).is_err() {
            return Ok(None);
        }
        let length = u32::from_be_bytes([header[0], header[1], header[2], header[3]]);
        let chunk_type = [header[4], header[5], header[6], header[7]];
        if &chunk_type == b"IDAT" || &chunk_type == b"IEND" {
            return Ok(None);
        }
        if chunk_type != kind {
            // Skip the data and the CRC.
            std::io::copy(
                &mut (&mut file).take(length as u64 + 4),
                &mut std::io::sink(),
            )
            .map_err(read_error)?;
            continue;
        }
        let mut data = Vec::new();
        (&mut file)
            .take(length as u64)
            .read_to_end(&mut data)
            .map_err(read_error)?;
        let mut crc = [0u8; 4];
        file.read_exact(&mut crc).map_err(read_error)?;
        if data.len() != length as usize {
            return Err(decode("the file ends inside a chunk"));
        }
        let mut hasher = crc32fast::Hasher::new();
        hasher.update(&chunk_type);
        hasher.update(&data);
        if hasher.finalize() != u32::from_be_bytes(crc) {
            return Err(decode("the scene chunk is corrupt (CRC mismatch)"));
        }
        return Ok(Some(data));
    }
}

/// The limits scene files and the command line enforce, applied to a
/// record (a PNG is user input like any other).
fn validate(s: &RecordedSettings) -> Result<(), String> {
    let r = &s.render;
    if !(1..=crate::scene::MAX_RAY_DEPTH).contains(&r.max_depth) {
        return Err(format!(
            "max_depth {} is outside 1..={}",
            r.max_depth,
            crate::scene::MAX_RAY_DEPTH
        ));
    }
    if s.octree_params.max_depth > crate::accel::MAX_OCTREE_DEPTH {
        return Err(format!(
            "octree max_depth {} is above {}",
            s.octree_params.max_depth,
            crate::accel::MAX_OCTREE_DEPTH
        ));
    }
    if s.octree_params.leaf_size == 0 {
        return Err("octree leaf_size must be at least 1".into());
    }
    if !(1..=8).contains(&s.octree_params.max_duplication) {
        return Err("octree max_duplication must lie in 1..=8".into());
    }
    if !(1..=crate::accel::MAX_MEMORY_BUDGET_MIB).contains(&s.octree_params.memory_budget_mib) {
        return Err(format!(
            "octree memory budget must lie in 1..={} MiB",
            crate::accel::MAX_MEMORY_BUDGET_MIB
        ));
    }
    if r.width == 0
        || r.height == 0
        || r.width.max(r.height) > crate::scene::MAX_IMAGE_SIDE
        || r.width as u64 * r.height as u64 > crate::scene::MAX_PIXELS
    {
        return Err(format!(
            "image size {}x{} is not allowed",
            r.width, r.height
        ));
    }
    if s.overlay_depth
        .is_some_and(|d| d > crate::accel::MAX_OCTREE_DEPTH)
    {
        return Err("overlay depth is above the octree's limit".into());
    }
    if let Some(e) = &s.edits {
        // The ranges scene files are held to (scenes/README.md).
        for (i, l) in e.lights.iter().enumerate() {
            l.validate().map_err(|m| format!("light {i}: {m}"))?;
        }
        for m in &e.materials {
            m.validate()
                .map_err(|e| format!("material `{}`: {e}", m.name))?;
        }
    }
    Ok(())
}

/// The scene a record was made from: parsed from its embedded text, with
/// meshes read relative to the recorded path (or from the binary for the
/// built-in scene).
pub fn load_recorded_scene(record: &RenderRecord) -> Result<Scene, ExportError> {
    let mut scene = if record.scene_path == crate::scene::builtin::NAME {
        crate::scene::builtin::load_text(&record.scene_text)?
    } else {
        crate::scene::load_str(
            &record.scene_text,
            Path::new(&record.scene_path),
            &crate::scene::FileSystem,
        )?
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
        let mut settings = RenderSettings::from_scene(&scene);
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
    fn scene_text_compresses_losslessly_and_garbage_is_refused() {
        let text = "[camera]\neye = [0, 1, 2]\n# ünïcödé\n".repeat(100);
        let packed = compress(text.as_bytes()).unwrap();
        assert!(packed.len() < text.len() / 10);
        assert_eq!(decompress(&packed).unwrap(), text);
        assert!(decompress(b"not zlib").is_err());
        let not_utf8 = compress(&[0xff, 0xfe, 0x00]).unwrap();
        assert!(decompress(&not_utf8).unwrap_err().contains("UTF-8"));
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
