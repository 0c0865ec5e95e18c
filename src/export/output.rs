//! Where an output's bytes go: standard output, a FIFO or device written
//! directly, or a file written through a temporary file renamed into place
//! (following symbolic links to their target).

use std::path::{Path, PathBuf};
use std::sync::Mutex;

use super::error::ExportError;
use super::png_file::{Animation, write_animated_png, write_png};
use super::record::RenderRecord;

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
            // Through a link, the name is not what decides: say where it leads.
            return Err(if file.file_name() == path.file_name() {
                ExportError::NotPng {
                    path: path.to_owned(),
                }
            } else {
                ExportError::LinkNotPng {
                    path: path.to_owned(),
                    target: file.to_owned(),
                }
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
        // The folder must exist and take a new file now, not after a render
        // of minutes: try the temporary file the write will use.
        let folder = folder_of(file);
        temporary_in(&folder).map_err(|source| ExportError::Write {
            path: path.to_owned(),
            // tempfile reports some refusals (a folder such as /proc that
            // takes no new files) without the system's word for them.
            source: if source.raw_os_error().is_none() && folder.is_dir() {
                std::io::Error::other(format!(
                    "the folder {} does not take new files ({source})",
                    folder.display()
                ))
            } else {
                source
            },
        })?;
    }
    Ok(target)
}

/// What an output file about to be replaced holds when it is not a PNG
/// image (a name ending `.png` does not make one): e.g. "1,234 bytes of
/// text", for a note before it is replaced. `None` for a PNG, a file not
/// yet there, or one that cannot be read.
pub fn replaced_non_png(target: &OutputTarget) -> Option<String> {
    use std::io::Read;
    let file = target.file()?;
    let mut head = [0u8; 8];
    let mut f = std::fs::File::open(file).ok()?;
    let size = f.metadata().ok()?.len();
    let n = f.read(&mut head).ok()?;
    if size == 0 || head[..n] == *b"\x89PNG\r\n\x1a\n" {
        return None;
    }
    let text = std::str::from_utf8(&head[..n]).is_ok_and(|t| !t.contains('\0'));
    let what = if text {
        "text"
    } else {
        "data that is not a PNG image"
    };
    Some(format!("{} bytes of {what}", group_thousands(size)))
}

/// `1234567` as "1,234,567".
fn group_thousands(n: u64) -> String {
    let digits = n.to_string();
    let mut out = String::new();
    for (k, c) in digits.chars().enumerate() {
        if k > 0 && (digits.len() - k).is_multiple_of(3) {
            out.push(',');
        }
        out.push(c);
    }
    out
}

/// Temporary files being written: an interrupted process (Ctrl+C runs no
/// destructors) removes them with [`remove_unfinished_outputs`].
static UNFINISHED: Mutex<Vec<PathBuf>> = Mutex::new(Vec::new());

/// Keeps a temporary file's name in [`UNFINISHED`] while it is written.
struct Unfinished(PathBuf);

impl Unfinished {
    fn register(path: &Path) -> Self {
        let mut list = UNFINISHED.lock().unwrap_or_else(|e| e.into_inner());
        list.push(path.to_owned());
        Unfinished(path.to_owned())
    }
}

impl Drop for Unfinished {
    fn drop(&mut self) {
        let mut list = UNFINISHED.lock().unwrap_or_else(|e| e.into_inner());
        list.retain(|p| *p != self.0);
    }
}

/// Removes the temporary files of outputs still being written: for a
/// signal handler, before the process exits without running destructors.
/// Returns how many it removed.
pub fn remove_unfinished_outputs() -> usize {
    let list = UNFINISHED.lock().unwrap_or_else(|e| e.into_inner());
    list.iter()
        .filter(|p| std::fs::remove_file(p).is_ok())
        .count()
}

/// The folder a file named `file` goes in (`.` for a bare name).
fn folder_of(file: &Path) -> PathBuf {
    match file.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_owned(),
        _ => PathBuf::from("."),
    }
}

/// A new hidden temporary file in `dir` with `permissions`, removed when
/// dropped. Errors keep their kind but not the temporary name: messages
/// name the user's path.
fn temporary_with(
    dir: &Path,
    permissions: std::fs::Permissions,
    suffix: &str,
) -> std::io::Result<tempfile::NamedTempFile> {
    // The folder first, for the system's own words ("No such file or
    // directory", "Not a directory").
    let folder = std::fs::metadata(dir)?;
    if !folder.is_dir() {
        return Err(std::io::Error::from_raw_os_error(20)); // ENOTDIR
    }
    tempfile::Builder::new()
        .prefix(".glint-")
        .suffix(suffix)
        .permissions(permissions)
        .tempfile_in(dir)
        .map_err(|e| without_path(&e))
}

/// `e` without the temporary file's name tempfile adds (its kind only).
fn without_path(e: &std::io::Error) -> std::io::Error {
    e.raw_os_error().map_or_else(
        || std::io::Error::from(e.kind()),
        std::io::Error::from_raw_os_error,
    )
}

fn temporary_in(dir: &Path) -> std::io::Result<tempfile::NamedTempFile> {
    use std::os::unix::fs::PermissionsExt;
    temporary_with(dir, std::fs::Permissions::from_mode(0o600), ".png.tmp")
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
    write_output(path, &mut |out| {
        write_png(out, path, width, height, rgb, record)
    })
}

/// Writes an animated PNG (APNG) of `count` frames of `size` shown at
/// `fps` frames a second, looping, as [`save_rgb_png`] writes a still one;
/// `frames` yields each frame's RGB8 pixels in order. It carries `record`
/// (the first frame's) for `glint info`.
pub fn save_animation(
    path: &Path,
    size: (u32, u32),
    count: u32,
    fps: f64,
    frames: &mut dyn Iterator<Item = Result<Vec<u8>, ExportError>>,
    record: Option<&RenderRecord>,
) -> Result<(), ExportError> {
    let animation = Animation {
        frames: count,
        delay: frame_delay(fps),
    };
    write_output(path, &mut |out| {
        write_animated_png(out, path, size, animation, frames, record)
    })
}

/// An APNG frame's display time for `fps`: the fraction with 16-bit parts
/// nearest 1/fps seconds (the smallest denominator among equals, so 24 fps
/// is 1/24 and 0.4 fps 5/2).
fn frame_delay(fps: f64) -> (u16, u16) {
    let seconds = 1.0 / fps;
    let mut best = (1u16, 1u16);
    let mut best_error = f64::INFINITY;
    for den in 1..=u16::MAX {
        let num = (seconds * f64::from(den))
            .round()
            .clamp(1.0, f64::from(u16::MAX));
        let error = (num / f64::from(den) - seconds).abs();
        if error < best_error {
            (best, best_error) = ((num as u16, den), error);
            if error == 0.0 {
                break;
            }
        }
    }
    best
}

/// Runs `write` on where `path` leads: standard output for `-`, FIFOs and
/// devices directly, files through a temporary file renamed into place.
fn write_output(
    path: &Path,
    write: &mut dyn FnMut(&mut dyn std::io::Write) -> Result<(), ExportError>,
) -> Result<(), ExportError> {
    let write_error = |source| ExportError::Write {
        path: path.to_owned(),
        source,
    };
    match OutputTarget::resolve(path)? {
        OutputTarget::Stdout => {
            use std::io::Write;
            let mut bytes = Vec::new();
            write(&mut bytes)?;
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
            write(&mut w)?;
            use std::io::Write;
            w.flush().map_err(write_error)
        }
        OutputTarget::File(target) => {
            let dir = folder_of(&target);
            // A replaced file keeps its permissions; a new one gets the
            // usual 0666 less the umask (tempfile's own default is 0600).
            let tmp =
                temporary_with(&dir, kept_permissions(&target), ".png.tmp").map_err(write_error)?;
            let _unfinished = Unfinished::register(tmp.path());
            {
                let mut w = std::io::BufWriter::new(tmp.as_file());
                write(&mut w)?;
                use std::io::Write;
                w.flush().map_err(write_error)?;
            }
            // Dropped (and deleted) on any error above.
            tmp.persist(&target)
                .map_err(|e| write_error(without_path(&e.error)))?;
            Ok(())
        }
    }
}

/// The permissions a file written over `target` gets: the old file's, or
/// for a new one the usual 0666 less the umask (tempfile's own default is
/// 0600).
fn kept_permissions(target: &Path) -> std::fs::Permissions {
    use std::os::unix::fs::PermissionsExt;
    std::fs::metadata(target)
        .map(|m| m.permissions())
        .unwrap_or_else(|_| std::fs::Permissions::from_mode(0o666))
}

/// Writes `bytes` to the regular file `path` (following symbolic links)
/// through a temporary file renamed into place: a failed write leaves the
/// old file whole. Used for saved scenes.
pub fn write_file_atomically(path: &Path, bytes: &[u8]) -> Result<(), ExportError> {
    let write_error = |source| ExportError::Write {
        path: path.to_owned(),
        source,
    };
    let target = match OutputTarget::resolve(path)? {
        OutputTarget::File(target) => target,
        _ => {
            return Err(write_error(std::io::Error::other(
                "it is not a regular file",
            )));
        }
    };
    let tmp = temporary_with(&folder_of(&target), kept_permissions(&target), ".tmp")
        .map_err(write_error)?;
    let _unfinished = Unfinished::register(tmp.path());
    {
        use std::io::Write;
        let mut file = tmp.as_file();
        file.write_all(bytes)
            .and_then(|()| file.sync_all())
            .map_err(write_error)?;
    }
    tmp.persist(&target)
        .map_err(|e| write_error(without_path(&e.error)))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn listed(path: &Path) -> bool {
        let list = UNFINISHED.lock().unwrap_or_else(|e| e.into_inner());
        list.iter().any(|p| p == path)
    }

    #[test]
    fn frame_delays_are_the_nearest_16_bit_fractions() {
        assert_eq!(frame_delay(24.0), (1, 24));
        assert_eq!(frame_delay(12.0), (1, 12));
        assert_eq!(frame_delay(0.4), (5, 2));
        assert_eq!(frame_delay(0.001), (1000, 1));
        // 7 frames over 9 s: 1.5 s each.
        assert_eq!(frame_delay(6.0 / 9.0), (3, 2));
        // Past what 16 bits hold: the nearest they can.
        assert_eq!(frame_delay(1e-6), (u16::MAX, 1));
        let (n, d) = frame_delay(29.97);
        assert!((f64::from(n) / f64::from(d) - 1.0 / 29.97).abs() < 1e-8);
    }

    // Removal itself is `tests/integration/cli_output.rs`'s: calling it here would
    // remove other tests' files being written in parallel.
    #[test]
    fn a_file_about_to_be_replaced_that_is_not_a_png_is_described() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("notes.png");
        let target = |p: &Path| OutputTarget::resolve(p).unwrap();
        assert_eq!(replaced_non_png(&target(&path)), None, "not there yet");
        std::fs::write(&path, "my notes\n".repeat(200)).unwrap();
        assert_eq!(
            replaced_non_png(&target(&path)).as_deref(),
            Some("1,800 bytes of text")
        );
        std::fs::write(&path, [0xffu8, 0xd8, 0xff, 0xe0, 0, 0x10]).unwrap();
        assert_eq!(
            replaced_non_png(&target(&path)).as_deref(),
            Some("6 bytes of data that is not a PNG image")
        );
        std::fs::write(&path, b"\x89PNG\r\n\x1a\n\0\0\0\rIHDR").unwrap();
        assert_eq!(replaced_non_png(&target(&path)), None, "a PNG");
        assert_eq!(replaced_non_png(&OutputTarget::Stdout), None);
    }

    #[test]
    fn temporary_files_are_listed_while_written_and_forgotten_after() {
        let dir = tempfile::tempdir().unwrap();
        let tmp = temporary_in(dir.path()).unwrap();
        let guard = Unfinished::register(tmp.path());
        assert!(listed(tmp.path()));
        drop(guard);
        assert!(!listed(tmp.path()));
        let done = dir.path().join("done.png");
        write_file_atomically(&done, b"png").unwrap();
        let left: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(std::fs::read(&done).unwrap(), b"png");
        assert_eq!(
            left.len(),
            2,
            "the file and the first temporary only: {left:?}"
        );
    }
}
