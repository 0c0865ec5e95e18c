//! The display buffer the UI shows, and the pass watcher that sweeps a
//! job's tiles and finished passes into it.

use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use super::pass_cache::CachedPass;
use super::{Job, PassRecord, Shared, ShownPass};
use crate::camera::CameraSpec;
use crate::image::frame::{Frame, resample_rgba, rgb_to_rgba};
use crate::render::{FinishedPass, FinishedTile, PassInfo, PassWatch};
use crate::scene::Scene;
use crate::settings::RenderSettings;

/// The display buffer: RGBA8, exactly what the viewer shows and exports.
#[derive(Clone, Debug, Default)]
pub struct DisplayBuffer {
    pub generation: u64,
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<u8>,
    /// Bumped on every change, so the UI uploads the texture only when new
    /// tiles arrived.
    pub version: u64,
    pub pass: Option<ShownPass>,
    /// The pass currently being rendered and its progress in tiles.
    pub tiles_done: u64,
    pub tiles_total: u64,
    /// True when the last pass of the generation is complete.
    pub finished: bool,
    /// When the pass on screen started (for the time left).
    pub pass_started: Option<Instant>,
    /// The user stopped the pass on screen ([`super::Worker::stop`]): the image
    /// stays as far as it got until the next change.
    pub stopped: bool,
    /// The linear-light frame of the last completed pass (for exact comparisons).
    pub last_frame: Option<Frame>,
    /// What the pass on screen renders: scene, camera and settings (its
    /// size, samples and the view its frame holds), for export records.
    pub source: Option<FrameSource>,
    /// The [`Job::serial`] of the job on screen.
    pub serial: u64,
}

/// The inputs of a pass, exactly as rendered.
#[derive(Clone)]
pub struct FrameSource {
    pub scene: Arc<Scene>,
    pub camera: CameraSpec,
    pub settings: RenderSettings,
    /// The settings of the frame the pass belongs to: `settings` itself
    /// for a full pass, the frame a drag preview stands for (its size,
    /// samples and depth) for a preview.
    pub frame_settings: RenderSettings,
}

impl std::fmt::Debug for FrameSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FrameSource")
            .field("camera", &self.camera)
            .field("settings", &self.settings)
            .finish_non_exhaustive()
    }
}

/// Shows a job's passes: tiles sweep into the display buffer as they
/// finish (a preview only once complete: a half-swept preview is a torn
/// frame), each finished pass replaces them with its exact frame.
pub(super) struct Display<'a> {
    pub shared: &'a Shared,
    pub generation: u64,
    pub job: &'a Job,
    pub settings: RenderSettings,
    /// Tiles of the current pass on screen.
    pub done: AtomicU64,
}

impl Display<'_> {
    fn stale(&self) -> bool {
        self.shared.generation.load(Ordering::SeqCst) != self.generation
    }

    fn buffer(&self) -> std::sync::MutexGuard<'_, DisplayBuffer> {
        self.shared.buffer.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The inputs of a pass, as an export records them: the settings the
    /// pass traced with ([`PassInfo::settings`]) and the view its frame
    /// holds.
    fn source(&self, pass: &PassInfo, frame_view: crate::settings::ViewMode) -> FrameSource {
        let mut settings = pass.settings;
        settings.view = frame_view;
        FrameSource {
            scene: Arc::clone(&self.job.scene),
            camera: self.job.camera,
            settings,
            frame_settings: self.job.settings,
        }
    }
}

impl PassWatch for Display<'_> {
    fn start_tile(&self, _pass: &PassInfo) -> bool {
        // The cancellation point: at most one tile per thread is wasted.
        if self.stale() {
            return false;
        }
        count_tile(self.shared, self.generation);
        true
    }

    fn shows_tiles(&self) -> bool {
        self.job.preview.is_none()
    }

    fn pass_started(&self, pass: &PassInfo) {
        self.done.store(0, Ordering::Relaxed);
        if self.job.preview.is_some() {
            // The buffer goes on describing the preview on screen until
            // this one is complete: the UI counts what it shows by it.
            return;
        }
        let (w, h) = (pass.width, pass.height);
        let mut b = self.buffer();
        // A full pass sweeps in over the previous image, first scaled to
        // the new size if it differs (after a preview).
        if b.width != w || b.height != h || b.rgba.len() != (w * h * 4) as usize {
            b.rgba = resample_rgba(&b.rgba, b.width, b.height, w, h);
            b.width = w;
            b.height = h;
        }
        b.generation = self.generation;
        b.serial = self.job.serial;
        b.pass = Some(ShownPass::full(pass.kind));
        b.source = Some(self.source(pass, pass.view));
        b.tiles_done = 0;
        b.tiles_total = pass.tiles;
        b.finished = false;
        b.pass_started = Some(Instant::now());
        b.stopped = false;
        b.version += 1;
    }

    fn tile_done(&self, pass: &PassInfo, tile: &FinishedTile) {
        {
            let mut b = self.buffer();
            if b.generation == self.generation
                && b.width == pass.width
                && tile.paint_rgba(&mut b.rgba, pass.width)
            {
                b.tiles_done = self.done.fetch_add(1, Ordering::Relaxed) + 1;
                b.version += 1;
            }
        }
        self.shared.repaint_soon();
    }

    fn pass_done(&self, pass: &FinishedPass) {
        if self.stale() {
            return;
        }
        // The record goes in before the buffer says finished, so whoever
        // waits for the finished buffer also finds its pass in the history.
        let summary = pass.summary;
        if let Ok(mut history) = self.shared.history.lock() {
            history.push(PassRecord {
                generation: self.generation,
                kind: ShownPass {
                    pass: pass.info.kind,
                    preview: self.job.preview,
                },
                seconds: summary.seconds,
                rays: summary.counts.rays,
                accel: self.settings.accel,
                anti_aliasing: self.job.settings.samples > 1,
                width: pass.frame.width,
                height: pass.frame.height,
                finished_at: self.shared.started.elapsed().as_secs_f64(),
                one_sample_error: summary.one_sample_error,
                refined_pixels: summary.refined_pixels,
                view: self.job.settings.view,
                max_depth: self.settings.max_depth,
                protocol: self.settings.protocol,
                from_cache: false,
                reuse: None,
            });
            if self.job.preview.is_none()
                && let Some(&record) = history.last()
            {
                self.shared
                    .cache
                    .lock()
                    .unwrap_or_else(|e| e.into_inner())
                    .insert(CachedPass {
                        key: self.job.pass_key(pass.info.kind),
                        frame: pass.traced.clone(),
                        record,
                    });
            }
        }
        let frame = pass.frame;
        let rgba = rgb_to_rgba(&frame.to_rgb8());
        {
            let mut b = self.buffer();
            // Checked under the lock: a newer job's first write waits for it.
            if self.stale() {
                return;
            }
            b.generation = self.generation;
            b.pass = Some(ShownPass {
                pass: pass.info.kind,
                preview: self.job.preview,
            });
            b.stopped = false;
            b.rgba = rgba;
            b.width = frame.width;
            b.height = frame.height;
            b.serial = self.job.serial;
            if self.job.preview.is_some() {
                self.shared
                    .previews_completed
                    .fetch_add(1, Ordering::SeqCst);
            }
            b.source = Some(self.source(&pass.info, frame.view));
            b.finished = pass.info.is_last();
            b.last_frame = Some(frame.clone());
            b.version += 1;
        }
        (self.shared.repaint)();
    }
}

pub(super) fn count_tile(shared: &Shared, generation: u64) {
    let mut list = shared
        .tiles_started
        .lock()
        .unwrap_or_else(|e| e.into_inner());
    match list.iter_mut().find(|(g, _)| *g == generation) {
        Some((_, n)) => *n += 1,
        None => {
            list.push((generation, 1));
            // Keep the record short: only recent generations matter.
            if list.len() > 64 {
                list.remove(0);
            }
        }
    }
}
