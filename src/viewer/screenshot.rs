//! `glint view --screenshot`: once the final pass has been on screen for a
//! few frames, save the whole window as PNG and close it.

use std::path::PathBuf;
use std::sync::Arc;

use super::worker::PassRecord;

pub struct Screenshot {
    path: PathBuf,
    /// Frames to wait after the final pass (the panels settle).
    frames: u32,
    frames_since_final: u32,
    requested: bool,
}

impl Screenshot {
    pub fn new(path: PathBuf, frames: u32) -> Self {
        Self {
            path,
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
                eprintln!(
                    "glint: {} pass {}x{}: {:.3} s, {:.2} Mrays/s, octree {}",
                    r.kind.label(),
                    r.width,
                    r.height,
                    r.seconds,
                    r.rays.total() as f64 / r.seconds.max(1e-9) / 1e6,
                    if r.octree { "on" } else { "off" }
                );
            }
        }
        self.frames_since_final += 1;
        if self.frames_since_final >= self.frames {
            self.requested = true;
            let path = self.path.clone();
            let close = ctx.clone();
            ctx.request_screenshot(move |image: Arc<egui::ColorImage>| {
                match save(&path, &image) {
                    Ok(()) => eprintln!("glint: saved window screenshot {}", path.display()),
                    Err(e) => eprintln!("glint: screenshot failed: {e:#}"),
                }
                close.send_viewport_cmd(egui::ViewportCommand::Close);
            });
        }
        ctx.request_repaint();
    }
}

fn save(path: &std::path::Path, image: &egui::ColorImage) -> anyhow::Result<()> {
    let [w, h] = image.size;
    let rgba: Vec<u8> = image.pixels.iter().flat_map(|c| c.to_array()).collect();
    let img = image::RgbaImage::from_raw(w as u32, h as u32, rgba)
        .ok_or_else(|| anyhow::anyhow!("bad screenshot size {w}x{h}"))?;
    img.save(path)?;
    Ok(())
}
