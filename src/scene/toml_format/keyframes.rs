//! Camera paths in TOML: a scene's `[[camera.keyframes]]`, or a file of
//! `[[keyframes]]` on its own for scenes whose format has none.

use std::path::Path;

use serde::Deserialize;
use toml::Spanned;

use super::context::{Context, Vec3, deserialize};
use crate::camera::CameraSpec;
use crate::camera_path::{CameraPath, Keyframe, PathError};
use crate::scene::model::SceneError;

/// One key of the camera path: `up` and `fov` default to the camera's.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
pub(super) struct KeyframeFile {
    time: Spanned<f64>,
    eye: Vec3,
    lookat: Vec3,
    up: Option<Vec3>,
    fov: Option<Spanned<f64>>,
}

/// A camera path on its own: a TOML file of `[[keyframes]]` (time, eye,
/// lookat, and up and fov defaulting to `camera`'s), for scenes whose
/// format has no place for one (NFF, OBJ). Errors name `path`, the line,
/// the column and the key.
pub fn parse_camera_path(
    text: &str,
    path: &Path,
    camera: &CameraSpec,
) -> Result<CameraPath, SceneError> {
    #[derive(Deserialize)]
    #[serde(deny_unknown_fields)]
    struct PathFile {
        keyframes: Vec<Spanned<KeyframeFile>>,
    }
    let cx = Context {
        text,
        path,
        defined_materials: 0,
    };
    let file: PathFile = deserialize(&cx)?;
    camera_path(&cx, &file.keyframes, camera, "keyframes")?.ok_or_else(|| {
        cx.error(
            0..0,
            "keyframes",
            "a camera path needs at least one keyframe",
        )
    })
}
/// The scene's camera path from its keyframes (none without any), each
/// error pointing at the key at fault.
pub(super) fn camera_path(
    cx: &Context,
    keys: &[Spanned<KeyframeFile>],
    camera: &CameraSpec,
    table: &str,
) -> Result<Option<CameraPath>, SceneError> {
    if keys.is_empty() {
        return Ok(None);
    }
    let mut keyframes = Vec::with_capacity(keys.len());
    for (i, k) in keys.iter().enumerate() {
        let key = |name: &str| format!("{table}[{i}].{name}");
        let f = k.get_ref();
        let spec = CameraSpec {
            eye: cx.vec3(&f.eye, &key("eye"))?,
            lookat: cx.vec3(&f.lookat, &key("lookat"))?,
            up: match &f.up {
                Some(up) => cx.vec3(up, &key("up"))?,
                None => camera.up,
            },
            fov: match &f.fov {
                Some(fov) => cx.finite(fov, &key("fov"))?,
                None => camera.fov,
            },
        };
        keyframes.push(Keyframe {
            time: cx.finite(&f.time, &key("time"))?,
            camera: spec,
        });
    }
    CameraPath::new(keyframes)
        .map_err(|e| {
            let (index, name) = match &e {
                PathError::TimeOrder { index, .. } | PathError::TimeNotFinite { index } => {
                    (*index, "time")
                }
                PathError::Camera { index, .. } => (*index, "eye"),
                _ => (0, "time"),
            };
            let f = keys[index].get_ref();
            let span = if name == "time" {
                f.time.span()
            } else {
                f.eye.span()
            };
            cx.error(span, &format!("{table}[{index}].{name}"), e.to_string())
        })
        .map(Some)
}
