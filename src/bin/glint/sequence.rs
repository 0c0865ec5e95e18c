//! `glint render --turntable N` and `--path`: a sequence of numbered PNGs
//! (Blender's `#` padding), each with its record, frame number and camera;
//! frames already written with the same record are kept, so an interrupted
//! run picks up where it stopped; `--animation` adds an animated PNG.

use std::path::{Path, PathBuf};
use std::time::Instant;

use anyhow::{Context, Result};
use glint::camera::CameraSpec;
use glint::camera_path::{FrameTiming, MAX_FRAMES, turntable};
use glint::export::{ExportError, RecordedFrame};
use glint::render::PassOptions;

use crate::render_cmd::{Prepared, RenderArgs, record_of, save_from};

#[derive(clap::Args, Clone, Debug, Default)]
pub struct SequenceArgs {
    /// Render a turntable: N frames around the lookat point, about the
    /// camera's up axis, at its distance and height (frame 0 is the
    /// scene's camera). -o names the frames: its last run of `#` becomes the
    /// frame number, zero-padded (turn_####.png: turn_0000.png, ...);
    /// without one, `_####` goes before `.png`. Frames already there with
    /// the same record are kept, not rendered again.
    #[arg(long, value_name = "N", value_parser = parse_frame_count,
          conflicts_with_all = ["path", "from_png", "trace_pixel", "stats"])]
    pub turntable: Option<u32>,
    /// Render the scene's camera path (its `[[camera.keyframes]]`) as a
    /// sequence: frame k at k / fps seconds from the first key, up to the
    /// last (or --seconds), or --frames spread over it. -o names the frames
    /// as for --turntable.
    #[arg(long, conflicts_with_all = ["from_png", "trace_pixel", "stats"])]
    pub path: bool,
    /// Render the camera path in this TOML file of `[[keyframes]]` (time,
    /// eye, lookat; up and fov default to the scene's camera) instead of
    /// the scene's own: for NFF and OBJ scenes, which cannot hold one.
    /// Implies --path.
    #[arg(long, value_name = "KEYFRAMES.toml",
          conflicts_with_all = ["from_png", "trace_pixel", "stats", "turntable"])]
    pub path_file: Option<PathBuf>,
    /// Frames per second of --path's frames and of --animation
    /// (default 24).
    #[arg(long)]
    pub fps: Option<f64>,
    /// How many seconds of the camera path --path renders (default: all
    /// of it).
    #[arg(long)]
    pub seconds: Option<f64>,
    /// How many frames --path renders (default: --seconds times --fps,
    /// plus the frame at the end).
    #[arg(long, value_parser = parse_frame_count)]
    pub frames: Option<u32>,
    /// Also write the whole sequence as one animated PNG (APNG, looping,
    /// at --fps), which browsers and most image viewers play.
    #[arg(long, value_name = "OUT.png")]
    pub animation: Option<PathBuf>,
}

fn parse_frame_count(s: &str) -> std::result::Result<u32, String> {
    match s.parse::<u32>() {
        Ok(n) if (1..=MAX_FRAMES).contains(&n) => Ok(n),
        _ => Err(format!(
            "expected a whole number of frames from 1 to 1,000,000, got `{s}`"
        )),
    }
}

impl SequenceArgs {
    pub fn is_sequence(&self) -> bool {
        self.turntable.is_some() || self.path || self.path_file.is_some()
    }

    /// Flags that only mean something in a sequence are refused alone.
    pub fn check(&self, args: &RenderArgs) -> Result<()> {
        if !self.is_sequence() {
            anyhow::ensure!(
                self.fps.is_none() && self.animation.is_none(),
                "--fps and --animation belong to a sequence: add --turntable N or --path"
            );
        }
        anyhow::ensure!(
            (self.seconds.is_none() && self.frames.is_none())
                || self.path
                || self.path_file.is_some(),
            "--seconds and --frames time a camera path: add --path (or --path-file); a \
             turntable's frame count is --turntable N"
        );
        if !self.is_sequence() {
            return Ok(());
        }
        let Some(output) = &args.output else {
            anyhow::bail!(
                "a sequence needs -o naming its frames, e.g. -o frames/turn_####.png \
                 (the #s become the frame number)"
            );
        };
        anyhow::ensure!(
            output.as_os_str() != "-",
            "a sequence writes one file per frame: -o - (standard output) cannot hold them; \
             name the frames, e.g. -o frames/turn_####.png"
        );
        Ok(())
    }
}

/// The file of frame `index`: the last run of `#` in the file name of
/// `pattern` replaced by the number, zero-padded to the run's length (more
/// digits when it needs them); without `#`, `_####` before the extension.
pub fn frame_file(pattern: &Path, index: u32) -> PathBuf {
    let name = pattern
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let (head, width, tail) = match name.rfind('#') {
        Some(end) => {
            let start = name[..end].trim_end_matches('#').len();
            (&name[..start], end + 1 - start, &name[end + 1..])
        }
        None => match name.rfind('.') {
            Some(dot) => (&name[..dot], 0, &name[dot..]),
            None => (name.as_str(), 0, ""),
        },
    };
    let number = if width == 0 {
        format!("_{index:04}")
    } else {
        format!("{index:0width$}")
    };
    pattern.with_file_name(format!("{head}{number}{tail}"))
}

/// The cameras of a sequence, each with its time along the path (none
/// for a turntable).
type TimedCameras = Vec<(Option<f64>, CameraSpec)>;

/// One frame to make: its camera and place in the sequence.
struct SequenceFrame {
    camera: CameraSpec,
    recorded: RecordedFrame,
    file: PathBuf,
}

pub fn run(args: &RenderArgs, job: &Prepared) -> Result<()> {
    let seq = &args.sequence;
    let pattern = args
        .output
        .as_deref()
        .context("a sequence needs -o naming its frames")?;
    let (cameras, fps) = cameras(seq, job)?;
    let count = u32::try_from(cameras.len()).context("too many frames")?;
    let frames: Vec<SequenceFrame> = cameras
        .into_iter()
        .enumerate()
        .map(|(k, (time, camera))| SequenceFrame {
            camera,
            recorded: RecordedFrame {
                index: k as u32,
                count,
                time,
            },
            file: frame_file(pattern, k as u32),
        })
        .collect();
    // Every camera and name is checked before the first frame.
    for f in &frames {
        glint::camera::Camera::new(&f.camera, 1, 1).with_context(|| {
            format!(
                "frame {} of the sequence has no valid camera",
                f.recorded.index
            )
        })?;
    }
    let first = &frames[0].file;
    for file in std::iter::once(first).chain(&seq.animation) {
        if let Some(dir) = file.parent().filter(|d| !d.as_os_str().is_empty()) {
            std::fs::create_dir_all(dir)
                .with_context(|| format!("cannot create the folder {}", dir.display()))?;
        }
        glint::export::check_output(file, args.scene.as_deref())?;
    }
    // Checked once the folders exist, so that links and `..` resolve.
    if let Some(animation) = &seq.animation
        && let Some(f) = frames.iter().find(|f| same_path(&f.file, animation))
    {
        anyhow::bail!(
            "--animation {} is also the name of frame {}: give the animation a name of its own",
            animation.display(),
            f.recorded.index
        );
    }

    let todo: Vec<&SequenceFrame> = frames.iter().filter(|f| !already_written(job, f)).collect();
    let kept = frames.len() - todo.len();
    if kept > 0 && !args.quiet {
        say!(
            "{kept} of {} frames are already there with the same record: rendering the other {}",
            frames.len(),
            todo.len()
        );
    }
    let bar = if todo.is_empty() {
        None
    } else {
        crate::common::terminal_bar(
            todo.len() as u64,
            "{spinner} frame {msg} [{bar:30}] {pos}/{len} frames, {elapsed} (eta {eta})",
        )
    };
    let start = Instant::now();
    for f in &todo {
        if let Some(b) = &bar {
            b.set_message(format!("{}", f.recorded.index));
        }
        let renderer = job
            .renderer_from(job.settings, &f.camera)
            .with_context(|| format!("cannot render {}", job.scene_name))?;
        let options = PassOptions {
            count_work: false,
            progressive: false,
        };
        let rendered = job
            .pool
            .install(|| renderer.render_frame(options, &()))
            .context("the render was abandoned")?;
        save_from(job, &rendered.frame, &f.file, &f.camera, Some(f.recorded))?;
        if let Some(b) = &bar {
            b.inc(1);
        }
    }
    if let Some(b) = &bar {
        b.finish_and_clear();
    }
    let render_s = start.elapsed().as_secs_f64();
    if !args.quiet {
        let per_frame = if todo.is_empty() {
            String::new()
        } else {
            format!(", {:.3} s a frame", render_s / todo.len() as f64)
        };
        say!(
            "wrote {} frames, {} to {} ({} rendered in {render_s:.2} s{per_frame}; load {:.2} s, \
             build {:.2} s)",
            frames.len(),
            frames[0].file.display(),
            frames[frames.len() - 1]
                .file
                .file_name()
                .unwrap_or_default()
                .to_string_lossy(),
            todo.len(),
            job.load_s,
            job.build_s
        );
    }
    if let Some(animation) = &seq.animation {
        write_animation(animation, &frames, fps, job)?;
        if !args.quiet {
            let size = std::fs::metadata(animation).map_or(0, |m| m.len());
            say!(
                "wrote {} ({} frames at {fps} fps, {} KiB)",
                animation.display(),
                frames.len(),
                size.div_ceil(1024)
            );
        }
    }
    for note in job.scene.notes() {
        say!("note: {note}");
    }
    Ok(())
}

/// Whether `a` and `b` name the same file: their folders (which exist)
/// resolved through links and `..`, then their names.
fn same_path(a: &Path, b: &Path) -> bool {
    let resolve = |p: &Path| -> Option<PathBuf> {
        let folder = match p.parent() {
            Some(d) if !d.as_os_str().is_empty() => d,
            _ => Path::new("."),
        };
        Some(std::fs::canonicalize(folder).ok()?.join(p.file_name()?))
    };
    matches!((resolve(a), resolve(b)), (Some(x), Some(y)) if x == y)
}

/// The sequence's cameras (with their time along the path) and its frame
/// rate.
fn cameras(seq: &SequenceArgs, job: &Prepared) -> Result<(TimedCameras, f64)> {
    let timing = FrameTiming {
        fps: seq.fps,
        seconds: seq.seconds,
        frames: seq.frames,
    };
    if let Some(n) = seq.turntable {
        let (fps, _) = timing.resolve(0.0)?;
        let cameras = turntable(&job.camera, n).into_iter().map(|c| (None, c));
        return Ok((cameras.collect(), fps));
    }
    let from_file = match &seq.path_file {
        Some(file) => {
            let text = std::fs::read_to_string(file)
                .with_context(|| format!("cannot read the camera path file {}", file.display()))?;
            Some(glint::scene::camera_path_from_str(
                &text,
                file,
                &job.camera,
            )?)
        }
        None => None,
    };
    let Some(path) = from_file.as_ref().or(job.scene.camera_path.as_ref()) else {
        anyhow::bail!(
            "{} has no camera path: give it [[camera.keyframes]] (time, eye, lookat; \
             scenes/README.md; --path-file KEYFRAMES.toml for NFF and OBJ scenes), record \
             one in the viewer, or render --turntable N",
            job.scene_name
        );
    };
    let frames = path.frames(&timing)?;
    let (fps, _) = timing.resolve(path.duration())?;
    Ok((frames.into_iter().map(|(t, c)| (Some(t), c)).collect(), fps))
}

/// Whether `f`'s file is a whole PNG whose record is the one this run
/// would write: then it is kept.
fn already_written(job: &Prepared, f: &SequenceFrame) -> bool {
    let Ok(record) = glint::export::read_record(&f.file) else {
        return false;
    };
    record == record_of(job, &f.camera, Some(f.recorded)) && decode_rgb(&f.file).is_ok()
}

/// A PNG file's RGB8 pixels and size.
fn decode_rgb(path: &Path) -> Result<(Vec<u8>, u32, u32), ExportError> {
    let decode = |message: String| ExportError::Decode {
        path: path.to_owned(),
        message,
    };
    let file = std::fs::File::open(path).map_err(|source| ExportError::Read {
        path: path.to_owned(),
        source,
    })?;
    let mut reader = png::Decoder::new(std::io::BufReader::new(file))
        .read_info()
        .map_err(|e| decode(e.to_string()))?;
    let size = reader
        .output_buffer_size()
        .ok_or_else(|| decode("the image is too large".into()))?;
    let mut buf = vec![0; size];
    let info = reader
        .next_frame(&mut buf)
        .map_err(|e| decode(e.to_string()))?;
    if info.color_type != png::ColorType::Rgb || info.bit_depth != png::BitDepth::Eight {
        return Err(decode("not an 8-bit RGB image".into()));
    }
    buf.truncate(info.buffer_size());
    Ok((buf, info.width, info.height))
}

/// The frames, read back from their files, as one animated PNG carrying
/// the first frame's record.
fn write_animation(path: &Path, frames: &[SequenceFrame], fps: f64, job: &Prepared) -> Result<()> {
    let (_, width, height) = decode_rgb(&frames[0].file)?;
    let mut pixels = frames.iter().map(|f| {
        let (rgb, w, h) = decode_rgb(&f.file)?;
        if (w, h) != (width, height) {
            return Err(ExportError::Decode {
                path: f.file.clone(),
                message: format!("it is {w}x{h}, the first frame {width}x{height}"),
            });
        }
        Ok(rgb)
    });
    let record = record_of(job, &frames[0].camera, Some(frames[0].recorded));
    glint::export::save_animation(
        path,
        (width, height),
        frames.len() as u32,
        fps,
        &mut pixels,
        Some(&record),
    )
    .with_context(|| format!("cannot write the animation {}", path.display()))?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_files_follow_blenders_hash_padding() {
        let f = |p: &str, k| frame_file(Path::new(p), k).display().to_string();
        assert_eq!(f("frames/turn_####.png", 7), "frames/turn_0007.png");
        assert_eq!(f("a#b_##.png", 3), "a#b_03.png");
        assert_eq!(f("f_#.png", 123), "f_123.png");
        assert_eq!(f("out/fly.png", 12), "out/fly_0012.png");
        assert_eq!(f("dir#/x#.png", 5), "dir#/x5.png");
    }
}
