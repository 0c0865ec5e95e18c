//! `glint view --screenshot`: once the final pass has been on screen for a
//! few frames, save the whole window as PNG and close it. The path is
//! checked before the window opens (`glint view`), and the file is written
//! like every output of glint: through a temporary file renamed into place,
//! so a failure never leaves an existing file emptied or a new one half
//! written.

use std::io::Write as _;
use std::path::PathBuf;
use std::sync::{Arc, Mutex};

use super::worker::PassRecord;

/// How the screenshot went: `None` until it was saved or failed; the
/// caller reads it once the window has closed.
pub type ScreenshotOutcome = Arc<Mutex<Option<Result<PathBuf, String>>>>;

pub struct Screenshot {
    path: PathBuf,
    outcome: ScreenshotOutcome,
    /// Frames to wait after the final pass (the panels settle).
    frames: u32,
    frames_since_final: u32,
    requested: bool,
}

impl Screenshot {
    pub fn new(path: PathBuf, frames: u32, outcome: ScreenshotOutcome) -> Self {
        Self {
            path,
            outcome,
            frames: frames.max(1),
            frames_since_final: 0,
            requested: false,
        }
    }

    /// Called once per frame. `shown` holds the passes of the image on
    /// screen when its final pass is complete (`None` until then); they are
    /// reported on stderr when the wait starts.
    pub fn update(&mut self, ctx: &egui::Context, shown: Option<Vec<PassRecord>>) {
        if self.requested {
            // Keep frames coming until the screenshot callback has run.
            ctx.request_repaint();
            return;
        }
        let Some(passes) = shown else {
            return;
        };
        if self.frames_since_final == 0 {
            for r in &passes {
                let _ = writeln!(
                    std::io::stderr().lock(),
                    "glint: {} pass {}x{}: {:.3} s, {:.2} Mrays/s, {}",
                    r.kind.label(),
                    r.width,
                    r.height,
                    r.seconds,
                    r.rays.total() as f64 / r.seconds.max(1e-9) / 1e6,
                    match r.accel {
                        crate::settings::Accel::Octree => "octree on",
                        crate::settings::Accel::Bvh => "octree off, BVH",
                        crate::settings::Accel::BruteForce => "octree off",
                    }
                );
            }
        }
        self.frames_since_final += 1;
        if self.frames_since_final >= self.frames {
            self.requested = true;
            let path = self.path.clone();
            let outcome = Arc::clone(&self.outcome);
            let close = ctx.clone();
            ctx.request_screenshot(move |image: Arc<egui::ColorImage>| {
                let result = save(&path, &image)
                    .map(|()| path.clone())
                    .map_err(|e| format!("{e:#}"));
                *outcome.lock().unwrap_or_else(|e| e.into_inner()) = Some(result);
                close.send_viewport_cmd(egui::ViewportCommand::Close);
            });
        }
        ctx.request_repaint();
    }
}

/// The window's pixels as an opaque PNG, written as `glint render -o`
/// writes (standard output for `-`, FIFOs directly, files atomically).
fn save(path: &std::path::Path, image: &egui::ColorImage) -> anyhow::Result<()> {
    let [w, h] = image.size;
    let rgb: Vec<u8> = image
        .pixels
        .iter()
        .flat_map(|c| {
            let [r, g, b, _] = c.to_array();
            [r, g, b]
        })
        .collect();
    crate::export::save_rgb_png(path, w as u32, h as u32, &rgb, None)?;
    Ok(())
}
