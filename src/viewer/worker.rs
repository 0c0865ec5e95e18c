//! The render worker: a thread that refines the image progressively (a
//! 1-sample pass, then the 16-sample pass) tile by tile into a shared
//! display buffer, and abandons stale work within one tile.
//!
//! The UI never waits on it: it publishes a job and bumps the generation
//! counter; tiles of an older generation are dropped. The buffer's lock is
//! held only to copy one finished tile in or the display image out.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, Sender, channel};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use rayon::prelude::*;

use crate::accel::Octree;
use crate::camera::CameraSpec;
use crate::frame::Frame;
use crate::math::DVec3;
use crate::render::Renderer;
use crate::scene::Scene;
use crate::settings::{RenderSettings, ViewMode};
use crate::stats::RayCounts;
use crate::tiles::{TileCounts, tiles};

/// What to render. `settings.samples` is ignored: the worker runs the
/// 1-sample pass, then the 16-sample pass if `anti_aliasing`.
#[derive(Clone)]
pub struct Job {
    pub scene: Arc<Scene>,
    pub octree: Arc<Octree>,
    pub camera: CameraSpec,
    pub settings: RenderSettings,
    pub anti_aliasing: bool,
    /// Render only a quick 1-sample pass (while the user drags), at
    /// 1/`divisor` of the resolution and as simplified as the frame budget
    /// chose; `None`: the full progressive sequence.
    pub preview: Option<Preview>,
}

/// Which pass produced a buffer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PassKind {
    Preview(Preview),
    OneSample,
    SixteenSamples,
    /// The SPD protocol's one pass: rays through the pixel corners.
    Corners,
}

impl PassKind {
    pub fn label(self) -> String {
        match self {
            PassKind::Preview(p) => format!("preview {}", p.describe()),
            PassKind::OneSample => "1 sample".into(),
            PassKind::SixteenSamples => "16 samples".into(),
            PassKind::Corners => "SPD corners".into(),
        }
    }
}

/// How a preview while moving simplifies the image to fit the frame budget.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Preview {
    /// 1/`divisor` of the resolution on each axis.
    pub divisor: u32,
    /// Reflection and refraction rays (off: the eye ray only).
    pub reflections: bool,
    pub shadows: bool,
}

impl Preview {
    /// E.g. "1/2, no reflections".
    pub fn describe(&self) -> String {
        let mut s = if self.divisor == 1 {
            "full resolution".to_string()
        } else {
            format!("1/{}", self.divisor)
        };
        if !self.reflections {
            s.push_str(", no reflections");
        }
        if !self.shadows {
            s.push_str(", no shadows");
        }
        s
    }
}

/// A finished pass, for the timing panel and plot.
#[derive(Clone, Copy, Debug)]
pub struct PassRecord {
    pub generation: u64,
    pub kind: PassKind,
    pub seconds: f64,
    pub rays: RayCounts,
    pub octree: bool,
    pub anti_aliasing: bool,
    pub width: u32,
    pub height: u32,
    /// Seconds since the worker started, when the pass finished.
    pub finished_at: f64,
    /// For a 16-sample pass: the error of the same generation's 1-sample
    /// pass against it (what anti-aliasing changed).
    pub one_sample_error: Option<crate::metrics::ImageError>,
    /// For an adaptive 16-sample pass: the pixels it refined (the rest kept
    /// their 1-sample value).
    pub refined_pixels: Option<u64>,
    /// What the pass showed, and the settings that decide its time apart
    /// from anti-aliasing (passes are compared only when these agree).
    pub view: crate::settings::ViewMode,
    pub max_depth: u32,
    pub protocol: crate::settings::Protocol,
}

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
    pub pass: Option<PassKind>,
    /// The pass currently being rendered and its progress in tiles.
    pub tiles_done: u64,
    pub tiles_total: u64,
    /// True when the last pass of the generation is complete.
    pub finished: bool,
    /// The linear-light frame of the last completed pass (for exact comparisons).
    pub last_frame: Option<Frame>,
    /// What the pass on screen renders: scene, camera and settings (its
    /// size, samples and the view its frame holds), for export records.
    pub source: Option<FrameSource>,
}

/// The inputs of a pass, exactly as rendered.
#[derive(Clone)]
pub struct FrameSource {
    pub scene: Arc<Scene>,
    pub camera: CameraSpec,
    pub settings: RenderSettings,
}

impl std::fmt::Debug for FrameSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FrameSource")
            .field("camera", &self.camera)
            .field("settings", &self.settings)
            .finish_non_exhaustive()
    }
}

/// The 1-sample frame of the generation being refined, kept by the worker
/// to measure what the 16-sample pass changes, with the signatures of what
/// each pixel's ray met (for adaptive anti-aliasing; empty otherwise).
type OneSampleFrame = Mutex<Option<(u64, Frame, Vec<u64>)>>;

struct Shared {
    generation: AtomicU64,
    buffer: Mutex<DisplayBuffer>,
    history: Mutex<Vec<PassRecord>>,
    repaint: Box<dyn Fn() + Send + Sync>,
    started: Instant,
    /// Tiles started per generation (for the cancellation test and stats).
    tiles_started: Mutex<Vec<(u64, u64)>>,
    /// When the UI was last asked to repaint for new tiles.
    last_repaint: Mutex<Instant>,
    one_sample: OneSampleFrame,
    /// What went wrong in the worker, for the status bar (taken by the UI).
    failure: Mutex<Option<String>>,
}

/// Tiles arrive far faster than a screen refreshes; asking for a repaint
/// per tile would make the UI thread (and a software OpenGL under Xvfb)
/// compete with the renderer for the cores: under Xvfb's software OpenGL a
/// repaint of the full window costs tens of milliseconds of CPU. Ten
/// repaints a second show the sweep and leave the cores to the renderer.
const REPAINT_INTERVAL: Duration = Duration::from_millis(100);

impl Shared {
    /// Records a failure for the status bar and wakes the UI to show it.
    fn fail(&self, message: String) {
        *self.failure.lock().unwrap_or_else(|e| e.into_inner()) = Some(message);
        (self.repaint)();
    }

    fn repaint_soon(&self) {
        let mut last = self.last_repaint.lock().unwrap_or_else(|e| e.into_inner());
        if last.elapsed() >= REPAINT_INTERVAL {
            *last = Instant::now();
            drop(last);
            (self.repaint)();
        }
    }
}

/// Handle owned by the UI. Dropping it stops and joins the thread.
pub struct Worker {
    shared: Arc<Shared>,
    jobs: Option<Sender<(u64, Job)>>,
    thread: Option<JoinHandle<()>>,
}

impl Worker {
    /// `repaint` is called whenever the display buffer changed (egui's
    /// `Context::request_repaint`, so an idle viewer does no work).
    pub fn spawn(threads: usize, repaint: impl Fn() + Send + Sync + 'static) -> Self {
        let shared = Arc::new(Shared {
            generation: AtomicU64::new(0),
            buffer: Mutex::new(DisplayBuffer::default()),
            history: Mutex::new(Vec::new()),
            repaint: Box::new(repaint),
            started: Instant::now(),
            tiles_started: Mutex::new(Vec::new()),
            last_repaint: Mutex::new(Instant::now()),
            one_sample: Mutex::new(None),
            failure: Mutex::new(None),
        });
        let (tx, rx) = channel();
        let thread_shared = Arc::clone(&shared);
        let thread = match std::thread::Builder::new()
            .name("glint-render".into())
            .spawn(move || run(thread_shared, rx, threads))
        {
            Ok(t) => Some(t),
            Err(e) => {
                shared.fail(format!("cannot start the render thread: {e}"));
                None
            }
        };
        Self {
            shared,
            jobs: Some(tx),
            thread,
        }
    }

    /// Starts rendering `job`, abandoning whatever was in flight. Returns
    /// the job's generation.
    pub fn submit(&self, job: Job) -> u64 {
        let generation = self.shared.generation.fetch_add(1, Ordering::SeqCst) + 1;
        if let Some(tx) = &self.jobs {
            let _ = tx.send((generation, job));
        }
        generation
    }

    pub fn generation(&self) -> u64 {
        self.shared.generation.load(Ordering::SeqCst)
    }

    /// What went wrong in the worker since the last call, if anything.
    pub fn take_failure(&self) -> Option<String> {
        self.shared
            .failure
            .lock()
            .unwrap_or_else(|e| e.into_inner())
            .take()
    }

    /// Calls `f` with the buffer if the lock is free; the UI never waits.
    pub fn try_with_buffer<R>(&self, f: impl FnOnce(&DisplayBuffer) -> R) -> Option<R> {
        self.shared.buffer.try_lock().ok().map(|b| f(&b))
    }

    /// Waits for the lock (tests and export only).
    pub fn with_buffer<R>(&self, f: impl FnOnce(&DisplayBuffer) -> R) -> R {
        let guard = self.shared.buffer.lock().unwrap_or_else(|e| e.into_inner());
        f(&guard)
    }

    /// How many tiles of generation `generation` were started, all passes.
    pub fn tiles_started(&self, generation: u64) -> u64 {
        let list = self
            .shared
            .tiles_started
            .lock()
            .unwrap_or_else(|e| e.into_inner());
        list.iter()
            .find(|(g, _)| *g == generation)
            .map_or(0, |(_, n)| *n)
    }

    pub fn history(&self) -> Vec<PassRecord> {
        self.shared
            .history
            .lock()
            .map(|h| h.clone())
            .unwrap_or_default()
    }

    /// Blocks until generation `generation` has finished its last pass
    /// (tests and `--screenshot`), or the timeout passes.
    pub fn wait_finished(&self, generation: u64, timeout: Duration) -> bool {
        let start = Instant::now();
        while start.elapsed() < timeout {
            if self.with_buffer(|b| b.generation == generation && b.finished) {
                return true;
            }
            std::thread::sleep(Duration::from_millis(2));
        }
        false
    }
}

impl Drop for Worker {
    fn drop(&mut self) {
        // Cancel the work in flight, close the channel, then join.
        self.shared.generation.fetch_add(1, Ordering::SeqCst);
        self.jobs.take();
        if let Some(t) = self.thread.take() {
            let _ = t.join();
        }
    }
}

fn run(shared: Arc<Shared>, rx: Receiver<(u64, Job)>, threads: usize) {
    let pool = match rayon::ThreadPoolBuilder::new()
        .num_threads(threads)
        .thread_name(|i| format!("glint-tile-{i}"))
        .build()
    {
        Ok(p) => p,
        Err(e) => {
            shared.fail(format!("cannot start the render threads: {e}"));
            return;
        }
    };
    while let Ok(mut next) = rx.recv() {
        // Only the newest job matters.
        while let Ok(newer) = rx.try_recv() {
            next = newer;
        }
        let (generation, job) = next;
        if shared.generation.load(Ordering::SeqCst) != generation {
            continue;
        }
        pool.install(|| render_job(&shared, generation, &job));
    }
}

fn render_job(shared: &Shared, generation: u64, job: &Job) {
    let passes: Vec<PassKind> = if let Some(preview) = job.preview {
        vec![PassKind::Preview(preview)]
    } else if job.settings.corner_rays() {
        // The SPD protocol has one way to sample: no refinement pass.
        vec![PassKind::Corners]
    } else if job.anti_aliasing {
        vec![PassKind::OneSample, PassKind::SixteenSamples]
    } else {
        vec![PassKind::OneSample]
    };
    let last = passes.len() - 1;
    for (index, &kind) in passes.iter().enumerate() {
        let mut settings = job.settings;
        settings.samples = if kind == PassKind::SixteenSamples {
            16
        } else {
            1
        };
        if let PassKind::Preview(p) = kind {
            settings.width = (settings.width / p.divisor).max(1);
            settings.height = (settings.height / p.divisor).max(1);
            if !p.reflections {
                settings.max_depth = 1;
            }
            settings.shadows = p.shadows;
        }
        if !render_pass(shared, generation, job, settings, kind, index == last) {
            return;
        }
    }
}

/// Renders one pass; `false` if it was cancelled.
fn render_pass(
    shared: &Shared,
    generation: u64,
    job: &Job,
    settings: RenderSettings,
    kind: PassKind,
    last: bool,
) -> bool {
    let stale = || shared.generation.load(Ordering::SeqCst) != generation;
    // The aa-need view renders shaded passes and shows their difference
    // once the 16-sample pass is done.
    let shown_view = settings.view;
    let mut settings = settings;
    if shown_view == ViewMode::AaNeed {
        settings.view = ViewMode::Shaded;
    }
    let renderer = match Renderer::with_camera(&job.scene, &job.octree, settings, &job.camera) {
        Ok(r) => r,
        Err(e) => {
            shared.fail(format!("cannot render: {e}"));
            return false;
        }
    };
    let (w, h) = (settings.width, settings.height);
    let all = tiles(w, h);
    // A preview is shown only once complete (a half-swept preview is a torn
    // frame), with its record; a full pass sweeps in over the previous
    // image, first scaled to the new size if it differs (after a preview).
    let preview = matches!(kind, PassKind::Preview(_));
    // The aa-need difference exists only after a 16-sample pass; before
    // it (and without anti-aliasing) the frame is the shaded picture.
    let frame_view = if shown_view == ViewMode::AaNeed && kind != PassKind::SixteenSamples {
        ViewMode::Shaded
    } else {
        shown_view
    };
    let source = FrameSource {
        scene: Arc::clone(&job.scene),
        camera: job.camera,
        settings: RenderSettings {
            view: frame_view,
            ..settings
        },
    };
    {
        let mut b = shared.buffer.lock().unwrap_or_else(|e| e.into_inner());
        if !preview && (b.width != w || b.height != h || b.rgba.len() != (w * h * 4) as usize) {
            b.rgba = resample_rgba(&b.rgba, b.width, b.height, w, h);
            b.width = w;
            b.height = h;
        }
        b.generation = generation;
        b.pass = Some(kind);
        if !preview {
            b.source = Some(source.clone());
        }
        b.tiles_done = 0;
        b.tiles_total = all.len() as u64;
        b.finished = false;
        b.version += 1;
    }
    // Adaptive anti-aliasing: the 1-sample pass keeps what each pixel's ray
    // met, the 16-sample pass refines where that or the picture has an edge.
    let adaptive = settings.anti_aliasing() == crate::settings::AntiAliasing::Adaptive
        || (kind == PassKind::OneSample && job.settings.adaptive && job.anti_aliasing);
    let first_pass = if kind == PassKind::SixteenSamples && adaptive {
        let one = shared.one_sample.lock().unwrap_or_else(|e| e.into_inner());
        one.as_ref()
            .filter(|(g, f, sig)| *g == generation && f.pixels.len() == sig.len() && f.width == w)
            .map(|(_, f, sig)| {
                let mask = crate::adaptive::refine_mask(&f.to_rgb8(), sig, w, h);
                (f.pixels.clone(), mask)
            })
    } else {
        None
    };
    let signatures = Mutex::new(if kind == PassKind::OneSample && adaptive {
        vec![0u64; (w * h) as usize]
    } else {
        Vec::new()
    });
    let start = Instant::now();
    let done = AtomicU64::new(0);
    let depth_range = Mutex::new((f64::INFINITY, f64::NEG_INFINITY));
    let results: Vec<Option<(Vec<DVec3>, TileCounts)>> = all
        .par_iter()
        .map(|&tile| {
            // The cancellation point: at most one tile per thread is wasted.
            if stale() {
                return None;
            }
            count_tile(shared, generation);
            let (values, counts) = match &first_pass {
                Some((pixels, mask)) => renderer.refine_tile(tile, pixels, mask, false),
                None if kind == PassKind::OneSample && adaptive => {
                    let (values, sig, counts) = renderer.first_pass_tile(tile, false);
                    let mut all_sig = signatures.lock().unwrap_or_else(|e| e.into_inner());
                    crate::tiles::place_tile(&mut all_sig, w, &tile, &sig);
                    (values, counts)
                }
                None => renderer.render_tile(tile, false),
            };
            let rgba = tile_rgba(&values, &settings, &depth_range);
            if !matches!(kind, PassKind::Preview(_)) {
                let mut b = shared.buffer.lock().unwrap_or_else(|e| e.into_inner());
                if b.generation == generation && b.width == w {
                    for row in 0..tile.height {
                        let dst = (((tile.y + row) * w + tile.x) * 4) as usize;
                        let src = (row * tile.width * 4) as usize;
                        let n = (tile.width * 4) as usize;
                        b.rgba[dst..dst + n].copy_from_slice(&rgba[src..src + n]);
                    }
                    b.tiles_done = done.fetch_add(1, Ordering::Relaxed) + 1;
                    b.version += 1;
                }
            }
            shared.repaint_soon();
            Some((values, counts))
        })
        .collect();
    if stale() || results.iter().any(Option::is_none) {
        return false;
    }
    let seconds = start.elapsed().as_secs_f64();
    // Assemble the exact frame, as `glint render` would, and publish it.
    let (frame, counts) =
        crate::tiles::assemble_tiles(&settings, &all, results.into_iter().flatten());
    let one_sample_error = {
        let mut one = shared.one_sample.lock().unwrap_or_else(|e| e.into_inner());
        match kind {
            PassKind::OneSample => {
                let sig =
                    std::mem::take(&mut *signatures.lock().unwrap_or_else(|e| e.into_inner()));
                *one = Some((generation, frame.clone(), sig));
                None
            }
            PassKind::SixteenSamples => one
                .as_ref()
                .filter(|(g, f, _)| *g == generation && f.pixels.len() == frame.pixels.len())
                .map(|(_, f, _)| {
                    crate::metrics::image_error(&f.pixels, &frame.pixels, frame.colors)
                }),
            PassKind::Preview(_) | PassKind::Corners => None,
        }
    };
    let frame = match (shown_view, kind) {
        (ViewMode::AaNeed, PassKind::SixteenSamples) => {
            let one = shared.one_sample.lock().unwrap_or_else(|e| e.into_inner());
            match one.as_ref() {
                Some((g, f, _)) if *g == generation && f.pixels.len() == frame.pixels.len() => {
                    Frame::aa_need(f, &frame)
                }
                _ => frame,
            }
        }
        _ => frame,
    };
    let rgba = rgb_to_rgba(&frame.to_rgb8());
    {
        let mut b = shared.buffer.lock().unwrap_or_else(|e| e.into_inner());
        if b.generation != generation {
            return false;
        }
        b.rgba = rgba;
        b.width = w;
        b.height = h;
        b.source = Some(source);
        b.finished = last;
        b.last_frame = Some(frame);
        b.version += 1;
    }
    if let Ok(mut history) = shared.history.lock() {
        history.push(PassRecord {
            generation,
            kind,
            seconds,
            rays: counts.rays,
            octree: settings.use_octree,
            anti_aliasing: job.anti_aliasing,
            width: w,
            height: h,
            finished_at: shared.started.elapsed().as_secs_f64(),
            one_sample_error,
            refined_pixels: first_pass.is_some().then_some(counts.refined_pixels),
            view: shown_view,
            max_depth: settings.max_depth,
            protocol: settings.protocol,
        });
    }
    (shared.repaint)();
    true
}

fn count_tile(shared: &Shared, generation: u64) {
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

/// Display bytes of one tile. Depth is normalised by the nearest distance
/// seen so far, cost by the range seen so far; the finished pass replaces
/// them with the exact full frame.
fn tile_rgba(
    values: &[DVec3],
    settings: &RenderSettings,
    depth_range: &Mutex<(f64, f64)>,
) -> Vec<u8> {
    let view = settings.view;
    let rgb = match view {
        ViewMode::Cost | ViewMode::CostSteps => {
            let range = {
                let mut r = depth_range.lock().unwrap_or_else(|e| e.into_inner());
                for v in values {
                    let c = crate::frame::cost_value(*v, view);
                    r.0 = r.0.min(c);
                    r.1 = r.1.max(c);
                }
                *r
            };
            values
                .iter()
                .flat_map(|v| {
                    crate::legend::viridis(crate::frame::cost_shade(
                        crate::frame::cost_value(*v, view),
                        range,
                    ))
                })
                .collect()
        }
        ViewMode::Depth => {
            let near = {
                let mut r = depth_range.lock().unwrap_or_else(|e| e.into_inner());
                if values.iter().any(|v| v.y > 0.0) {
                    r.0 = r.0.min(crate::frame::nearest_depth(values));
                }
                r.0
            };
            values
                .iter()
                .flat_map(|v| [(crate::frame::depth_shade(*v, near) * 255.0).round() as u8; 3])
                .collect()
        }
        _ => Frame {
            width: values.len() as u32,
            height: 1,
            view,
            colors: settings.colors,
            pixels: values.to_vec(),
        }
        .to_rgb8(),
    };
    rgb_to_rgba(&rgb)
}

/// An RGBA image scaled to `w x h` by nearest neighbour (opaque black when
/// there is nothing to scale).
fn resample_rgba(rgba: &[u8], from_w: u32, from_h: u32, w: u32, h: u32) -> Vec<u8> {
    let mut out = vec![0u8; (w * h * 4) as usize];
    let usable = from_w > 0 && from_h > 0 && rgba.len() == (from_w * from_h * 4) as usize;
    for y in 0..h {
        for x in 0..w {
            let dst = ((y * w + x) * 4) as usize;
            if usable {
                let sx = (x as u64 * from_w as u64 / w as u64) as u32;
                let sy = (y as u64 * from_h as u64 / h as u64) as u32;
                let src = ((sy * from_w + sx) * 4) as usize;
                out[dst..dst + 4].copy_from_slice(&rgba[src..src + 4]);
            } else {
                out[dst + 3] = 255;
            }
        }
    }
    out
}

pub fn rgb_to_rgba(rgb: &[u8]) -> Vec<u8> {
    let mut out = Vec::with_capacity(rgb.len() / 3 * 4);
    for p in rgb.chunks_exact(3) {
        out.extend_from_slice(&[p[0], p[1], p[2], 255]);
    }
    out
}

/// The display buffer's pixels without alpha, as a PNG stores them.
pub fn rgba_to_rgb(rgba: &[u8]) -> Vec<u8> {
    rgba.chunks_exact(4)
        .flat_map(|p| [p[0], p[1], p[2]])
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resampling_picks_the_nearest_source_pixel() {
        // A 2x2 image of four colours, doubled: each becomes a 2x2 block.
        let rgba: Vec<u8> = (0..4u8).flat_map(|k| [k, 10 * k, 20 * k, 255]).collect();
        let big = resample_rgba(&rgba, 2, 2, 4, 4);
        let at = |x: usize, y: usize| big[(y * 4 + x) * 4];
        let blocks: Vec<u8> = (0..4)
            .flat_map(|y| (0..4).map(move |x| (x, y)))
            .map(|(x, y)| at(x, y))
            .collect();
        assert_eq!(blocks, [0, 0, 1, 1, 0, 0, 1, 1, 2, 2, 3, 3, 2, 2, 3, 3]);
        // Halved back: the top-left pixel of each block.
        assert_eq!(resample_rgba(&big, 4, 4, 2, 2), rgba);
        // Nothing usable (a buffer of another size): opaque black.
        assert_eq!(resample_rgba(&rgba, 3, 3, 1, 1), [0, 0, 0, 255]);
    }

    #[test]
    fn a_tile_of_the_shaded_view_encodes_like_the_whole_frame() {
        let settings = RenderSettings {
            width: 3,
            height: 1,
            samples: 1,
            max_depth: 5,
            use_octree: true,
            view: ViewMode::Shaded,
            protocol: crate::settings::Protocol::Glint,
            colors: crate::color::ColorConvention::Linear,
            sides: crate::settings::Sides::Two,
            adaptive: false,
            shadows: true,
        };
        let values = [
            DVec3::new(0.0, 0.5, 1.0),
            DVec3::new(2.0, -1.0, 0.25),
            DVec3::splat(0.0031308),
        ];
        let range = Mutex::new((f64::INFINITY, f64::NEG_INFINITY));
        let tile = tile_rgba(&values, &settings, &range);
        // sRGB encoding (IEC 61966-2-1) of each channel, clamped to [0, 1].
        let srgb = |x: f64| {
            let x = x.clamp(0.0, 1.0);
            let e = if x <= 0.0031308 {
                12.92 * x
            } else {
                1.055 * x.powf(1.0 / 2.4) - 0.055
            };
            (e * 255.0).round() as u8
        };
        let expected: Vec<u8> = values
            .iter()
            .flat_map(|v| [srgb(v.x), srgb(v.y), srgb(v.z), 255])
            .collect();
        assert_eq!(tile, expected);
    }

    #[test]
    fn passes_describe_what_they_dropped() {
        let preview = Preview {
            divisor: 2,
            reflections: false,
            shadows: true,
        };
        assert_eq!(
            PassKind::Preview(preview).label(),
            "preview 1/2, no reflections"
        );
        let bare = Preview {
            divisor: 1,
            reflections: false,
            shadows: false,
        };
        assert_eq!(
            bare.describe(),
            "full resolution, no reflections, no shadows"
        );
    }
}
