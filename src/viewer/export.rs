//! Exporting the frame on screen to PNG: where it goes (a save dialog, or
//! the pictures directory where there is none) and what it records.

use std::path::{Path, PathBuf};

use super::state::SceneSource;
use super::worker::Worker;
use crate::accel::Octree;
use crate::export::{OverlayRequest, RenderRecord, SceneEdits, save_frame};
use crate::image::frame::rgba_to_rgb;

/// The path to export to: chosen in a save dialog, or, where no dialog is
/// available, a timestamped name in a place made for pictures. `None` when
/// the user cancels the dialog.
pub fn choose_path(source: &SceneSource) -> Option<PathBuf> {
    let default_name = format!("{}-{}.png", source.stem(), timestamp());
    if file_dialog_available() {
        rfd::FileDialog::new()
            .set_file_name(&default_name)
            .add_filter("PNG", &["png"])
            .save_file()
    } else {
        // No dialog (no desktop portal, e.g. under Xvfb): never the working
        // directory, which is often a checkout.
        Some(unused_path(&export_dir(), &default_name))
    }
}

/// `dir/name`, or where that exists (two exports within a second share a
/// timestamp) `NAME-2.png`, `NAME-3.png`, ...: an export never replaces
/// an earlier one.
fn unused_path(dir: &Path, name: &str) -> PathBuf {
    let stem = name.strip_suffix(".png").unwrap_or(name);
    (1..)
        .map(|k| match k {
            1 => dir.join(name),
            k => dir.join(format!("{stem}-{k}.png")),
        })
        .find(|p| !p.exists())
        .unwrap_or_else(|| dir.join(name))
}

/// Saves the display buffer with the record of how it was made (see
/// [`crate::export`]): the scene, camera and settings of the pass on
/// screen, not the panels' current values. A finished pass is written as
/// `glint render` writes it (diagnostic views with their legend strip, the
/// octree overlay drawn in when `overlay_depth` is set); a pass still
/// sweeping in is written as displayed and recorded as partial.
pub fn export_to(
    path: &Path,
    worker: &Worker,
    octree: &Octree,
    overlay_depth: Option<u32>,
) -> anyhow::Result<()> {
    let (w, h, rgba, frame, shown, finished) = worker.with_buffer(|b| {
        (
            b.width,
            b.height,
            b.rgba.clone(),
            b.last_frame.clone(),
            b.source.clone(),
            b.finished,
        )
    });
    let Some(shown) = shown.filter(|_| w > 0 && h > 0) else {
        anyhow::bail!("nothing has been rendered yet");
    };
    let mut record = record_of(&shown, shown.settings);
    match frame {
        Some(f) if finished && f.width == w && f.height == h => {
            let camera = crate::camera::Camera::new(&shown.camera, w, h)?;
            let overlay = overlay_depth.map(|depth| OverlayRequest {
                octree,
                camera: &camera,
                depth,
            });
            save_frame(&f, path, &mut record, overlay)?
        }
        _ => {
            record.settings.partial = true;
            let rgb = rgba_to_rgb(&rgba);
            crate::export::save_rgb_png(path, w, h, &rgb, Some(&record))?
        }
    }
    Ok(())
}

/// The record of an image of `shown` rendered with `settings`: the
/// rendered scene's own name and text, which belong together (a save since
/// may have renamed the file in the window), by its absolute path so that
/// `--from-png` finds it and its meshes from any folder, and the lights
/// and materials as rendered (the panels may have edited them).
pub(super) fn record_of(
    shown: &super::worker::FrameSource,
    settings: crate::settings::RenderSettings,
) -> RenderRecord {
    let scene_name = if shown.scene.name == crate::scene::builtin::NAME {
        shown.scene.name.clone()
    } else {
        let p = Path::new(&shown.scene.name);
        std::fs::canonicalize(p)
            .or_else(|_| std::path::absolute(p))
            .map_or_else(|_| shown.scene.name.clone(), |p| p.display().to_string())
    };
    let mut record = RenderRecord::new(&shown.scene, &scene_name, &shown.camera, settings);
    record.settings.edits = Some(SceneEdits {
        lights: shown.scene.lights.clone(),
        materials: shown.scene.materials.clone(),
    });
    record
}

/// rfd's dialogs go through the XDG desktop portal on D-Bus; without a
/// session bus (a bare X server such as Xvfb) there is no dialog to show.
pub fn file_dialog_available() -> bool {
    std::env::var_os("DBUS_SESSION_BUS_ADDRESS").is_some_and(|v| !v.is_empty())
}

/// A readable UTC timestamp for file names, e.g. `2026-11-23T14-05-09Z`.
pub(super) fn timestamp() -> String {
    let secs = std::time::SystemTime::now()
        .duration_since(std::time::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs());
    utc_timestamp(secs)
}

/// `secs` since the Unix epoch as `YYYY-MM-DDTHH-MM-SSZ` (dashes, not
/// colons, so the name is valid everywhere). The date from the day count
/// follows Hinnant's `civil_from_days` ("chrono-Compatible Low-Level Date
/// Algorithms").
fn utc_timestamp(secs: u64) -> String {
    let days = (secs / 86_400) as i64;
    let rem = secs % 86_400;
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1_460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let day = doy - (153 * mp + 2) / 5 + 1;
    let month = if mp < 10 { mp + 3 } else { mp - 9 };
    let year = yoe + era * 400 + (month <= 2) as i64;
    format!(
        "{year:04}-{month:02}-{day:02}T{:02}-{:02}-{:02}Z",
        rem / 3600,
        rem / 60 % 60,
        rem % 60
    )
}

/// Where exports go without a file dialog: the user's pictures directory
/// (`XDG_PICTURES_DIR`, from the environment or `~/.config/user-dirs.dirs`,
/// else `~/Pictures`) if it exists, else glint's folder in the user's data
/// directory (`$XDG_DATA_HOME/glint/exports`, else
/// `~/.local/share/glint/exports`, made if need be), else the temporary
/// directory. Never the working directory nor the scene's folder: either
/// is often a checkout, where an export would lie about as an untracked
/// file.
pub(super) fn export_dir() -> PathBuf {
    export_dir_with(|name| std::env::var_os(name))
}

/// [`export_dir`] with the environment read through `var`.
fn export_dir_with(var: impl Fn(&str) -> Option<std::ffi::OsString>) -> PathBuf {
    let home = var("HOME").map(PathBuf::from);
    let from_user_dirs = || {
        let home = home.as_ref()?;
        let text = std::fs::read_to_string(home.join(".config/user-dirs.dirs")).ok()?;
        let line = text
            .lines()
            .find(|l| l.trim_start().starts_with("XDG_PICTURES_DIR="))?;
        let value = line.split_once('=')?.1.trim().trim_matches('"');
        Some(PathBuf::from(
            value.replace("$HOME", &home.to_string_lossy()),
        ))
    };
    let pictures = var("XDG_PICTURES_DIR")
        .map(PathBuf::from)
        .or_else(from_user_dirs)
        .or_else(|| home.as_ref().map(|h| h.join("Pictures")));
    if let Some(dir) = pictures.filter(|d| d.is_dir()) {
        return dir;
    }
    let data = var("XDG_DATA_HOME")
        .map(PathBuf::from)
        .filter(|d| d.is_absolute())
        .or_else(|| home.as_ref().map(|h| h.join(".local/share")));
    if let Some(dir) = data.map(|d| d.join("glint").join("exports"))
        && std::fs::create_dir_all(&dir).is_ok()
    {
        return dir;
    }
    std::env::temp_dir()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn timestamps_are_readable_utc() {
        assert_eq!(utc_timestamp(0), "1970-01-01T00-00-00Z");
        // 2000-02-29 (a leap day) 12:34:56 and 2026-11-23 14:05:09.
        assert_eq!(utc_timestamp(951_827_696), "2000-02-29T12-34-56Z");
        assert_eq!(utc_timestamp(1_795_442_709), "2026-11-23T14-05-09Z");
    }

    #[test]
    fn without_a_pictures_folder_exports_go_to_glints_data_folder() {
        // Never the scene's folder or the working one (often a checkout).
        let home = tempfile::tempdir().unwrap();
        let env = |name: &str| (name == "HOME").then(|| home.path().as_os_str().to_owned());
        let dir = export_dir_with(env);
        assert_eq!(dir, home.path().join(".local/share/glint/exports"));
        assert!(dir.is_dir());
        // A pictures folder, where there is one.
        std::fs::create_dir(home.path().join("Pictures")).unwrap();
        assert_eq!(export_dir_with(env), home.path().join("Pictures"));
    }

    #[test]
    fn an_export_never_takes_an_earlier_ones_name() {
        let dir = tempfile::tempdir().unwrap();
        let name = "sphere-2026-11-25T14-17-38Z.png";
        assert_eq!(unused_path(dir.path(), name), dir.path().join(name));
        std::fs::write(dir.path().join(name), b"first").unwrap();
        let second = unused_path(dir.path(), name);
        assert_eq!(second, dir.path().join("sphere-2026-11-25T14-17-38Z-2.png"));
        std::fs::write(&second, b"second").unwrap();
        assert_eq!(
            unused_path(dir.path(), name),
            dir.path().join("sphere-2026-11-25T14-17-38Z-3.png")
        );
    }
}
