//! The record an exported PNG carries: how the image was made, enough to
//! make it again. Its keywords and JSON field names are part of the file
//! format: add, never rename.

use serde::{Deserialize, Serialize};

use crate::accel::OctreeParams;
use crate::camera::CameraSpec;
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
/// Largest scene text a record embeds: every bundled scene (tetra_s8,
/// 5 MB, the largest) and anything a person writes by hand fits; past it
/// (generated scenes of tens of megabytes, which made an 8x6 render's PNG
/// 7.6 MB and took seconds to compress) the record keeps the scene's path
/// and SHA-256 only, and `--from-png` reads the file there, checked.
pub const MAX_EMBEDDED_SCENE: usize = 16 << 20;

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
    /// Whether diagnostic views and the overlay have their legend strip
    /// under the image (`glint render --legend off` leaves it out). Absent
    /// in records from before the flag: they all have it.
    #[serde(default = "legend_default", skip_serializing_if = "is_true")]
    pub legend: bool,

    /// The files besides the scene text it was built from (meshes, MTL
    /// libraries: not embedded) with their SHA-256, so a re-render can say
    /// when one has changed. Absent in records from before it.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub files: Vec<RecordedFile>,
    /// The scene text was past [`MAX_EMBEDDED_SCENE`] and is not in the
    /// PNG: the record holds its path and SHA-256 only.
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    pub scene_not_embedded: bool,
    /// The image is one frame of a sequence (a turntable or a camera
    /// path); `camera` is that frame's. Absent for single images.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub frame: Option<RecordedFrame>,
}

/// Where a frame sits in its sequence.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct RecordedFrame {
    /// Its number, from 0.
    pub index: u32,
    /// Frames in the sequence.
    pub count: u32,
    /// Seconds along the scene's camera path (absent for a turntable).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub time: Option<f64>,
}

/// A file a recorded scene read, as [`RecordedSettings::files`] lists it.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct RecordedFile {
    pub path: String,
    pub sha256: String,
}

fn legend_default() -> bool {
    true
}

fn is_true(b: &bool) -> bool {
    *b
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
            // Past the limit, the path and hash stand for the text.
            scene_text: if scene.source_text.len() > MAX_EMBEDDED_SCENE {
                String::new()
            } else {
                scene.source_text.to_string()
            },
            settings: RecordedSettings {
                camera: camera.into(),
                render: settings,
                octree_params: scene.octree_params,
                overlay_depth: None,
                edits: None,
                partial: false,
                legend: true,
                files: scene
                    .files_read
                    .iter()
                    .map(|f| RecordedFile {
                        path: absolute_name(&f.path),
                        sha256: f.sha256.clone(),
                    })
                    .collect(),
                scene_not_embedded: scene.source_text.len() > MAX_EMBEDDED_SCENE,
                frame: None,
            },
        }
    }
}

/// The limits scene files and the command line enforce
/// ([`crate::limits`]), applied to a record (a PNG is user input like any
/// other).
pub(super) fn validate(s: &RecordedSettings) -> Result<(), String> {
    let name = |e: crate::limits::LimitError| e.to_string();
    s.render.check().map_err(name)?;
    s.octree_params.check().map_err(name)?;
    if let Some(d) = s.overlay_depth
        && d > crate::limits::MAX_OCTREE_DEPTH
    {
        return Err(name(crate::limits::LimitError::OverlayDepth(d)));
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

/// A file's name as a record keeps it: absolute where it exists (a
/// re-render from another folder resolves it the same), else as given.
pub fn absolute_name(path: &std::path::Path) -> String {
    std::fs::canonicalize(path)
        .unwrap_or_else(|_| path.to_owned())
        .display()
        .to_string()
}

/// SHA-256 of `bytes` as 64 lowercase hex digits (FIPS 180-4, `sha2`).
pub fn sha256_hex(bytes: &[u8]) -> String {
    use sha2::Digest;
    format!("{:x}", sha2::Sha256::digest(bytes))
}
