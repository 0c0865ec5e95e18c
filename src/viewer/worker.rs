//! The render worker: a thread that refines the image progressively (a
//! 1-sample pass, then the 16-sample pass) tile by tile into a shared
//! display buffer, and abandons stale work within one tile.
//!
//! The UI never waits on it: it publishes a job and bumps the generation
//! counter; tiles of an older generation are dropped. The buffer's lock is
//! held only to copy one finished tile in or the display image out.
//!
//! Previews while the user drags are the exception: a preview in flight
//! runs to completion and is shown, and the newest camera waits (one job,
//! replaced by each newer one) until it is; then it starts at once. A
//! preview cancelled by every pointer event is never seen when events come
//! faster than previews finish.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc::{Receiver, Sender, channel};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use super::pass_cache::{self, PassCache};
pub use super::preview::{Preview, Reduced, Reflections};

mod display;
mod job;
mod light_buffers;
mod pass_record;
mod reuse;

use crate::image::frame::{Frame, rgb_to_rgba};
use crate::render::{PassOptions, Renderer};
use display::Display;
pub use display::{DisplayBuffer, FrameSource};
pub use job::Job;
use light_buffers::LightBufferCache;
pub use pass_record::{PassRecord, ShownPass};
use reuse::ReuseState;

/// The worker's record of finished passes. Previews come at up to 60 a
/// second while the user drags, so only the newest [`Self::MAX_PREVIEWS`]
/// are kept (the frame budget reads the last few of each kind, the orbit
/// benchmark those of its drag); full passes are all kept. Readers share
/// the list ([`Arc`]); a push copies it only while one holds it.
#[derive(Default)]
pub(super) struct History {
    records: Arc<Vec<PassRecord>>,
    previews: usize,
}

impl History {
    pub const MAX_PREVIEWS: usize = 4096;

    pub(super) fn push(&mut self, record: PassRecord) {
        let records = Arc::make_mut(&mut self.records);
        if record.kind.preview.is_some() {
            self.previews += 1;
            if self.previews > Self::MAX_PREVIEWS {
                // Past the cap, drop the oldest preview: one scan of a few
                // thousand records, a few times a second.
                if let Some(k) = records.iter().position(|r| r.kind.preview.is_some()) {
                    records.remove(k);
                    self.previews -= 1;
                }
            }
        }
        records.push(record);
    }

    /// The record just pushed.
    pub(super) fn last(&self) -> Option<&PassRecord> {
        self.records.last()
    }
}

struct Shared {
    generation: AtomicU64,
    buffer: Mutex<DisplayBuffer>,
    history: Mutex<History>,
    repaint: Box<dyn Fn() + Send + Sync>,
    started: Instant,
    /// Tiles started per generation (for the cancellation test and stats).
    tiles_started: Mutex<Vec<(u64, u64)>>,
    /// When the UI was last asked to repaint for new tiles.
    last_repaint: Mutex<Instant>,
    /// What went wrong in the worker, for the status bar (taken by the UI).
    failure: Mutex<Option<String>>,
    /// Recent finished passes, shown again without rendering.
    cache: Mutex<PassCache<PassRecord>>,
    /// The preview in flight and the one waiting for it.
    previews: Mutex<PreviewQueue>,
    previews_sent: AtomicU64,
    previews_started: AtomicU64,
    previews_completed: AtomicU64,
    previews_dropped: AtomicU64,
    /// The newest full job's generation ([`Worker::full_generation`]).
    full_generation: AtomicU64,
    /// The octree switch of the last full job rendered: a job that flips
    /// it always renders, its time being what the user toggled to see.
    last_octree_switch: Mutex<Option<crate::settings::Accel>>,
    /// What the last job's light buffer holds and its build's seconds
    /// (`None`: the job asked none), for the Timing panel.
    light_buffer: Mutex<Option<(crate::accel::LightBufferStats, f64)>>,
}

/// While the user drags: the generation of the preview in flight (sent or
/// rendering), and the newest preview asked for since, which starts when
/// that one is done.
#[derive(Default)]
struct PreviewQueue {
    in_flight: Option<u64>,
    waiting: Option<Job>,
}

/// How the previews of a worker's life went (the orbit benchmark's counts).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PreviewCounts {
    /// Previews given a generation to render (sent to the worker, or
    /// taken from the queue when the one before was done).
    pub sent: u64,
    /// Previews the worker began rendering.
    pub started: u64,
    /// Previews that finished and went into the display buffer.
    pub completed: u64,
    /// Previews sent that a newer job replaced before they started: a full
    /// render (the drag ended, or a frame near the press was not yet a
    /// drag) or a cancel. A newer preview never replaces one: it waits.
    pub dropped: u64,
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
    /// Render threads (0 asked for: one per core).
    threads: usize,
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
            history: Mutex::new(History::default()),
            repaint: Box::new(repaint),
            started: Instant::now(),
            tiles_started: Mutex::new(Vec::new()),
            last_repaint: Mutex::new(Instant::now()),
            failure: Mutex::new(None),
            cache: Mutex::new(PassCache::default()),
            previews: Mutex::new(PreviewQueue::default()),
            previews_sent: AtomicU64::new(0),
            previews_started: AtomicU64::new(0),
            previews_completed: AtomicU64::new(0),
            previews_dropped: AtomicU64::new(0),
            full_generation: AtomicU64::new(0),
            last_octree_switch: Mutex::new(None),
            light_buffer: Mutex::new(None),
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
        let threads = if threads == 0 {
            std::thread::available_parallelism().map_or(1, |n| n.get())
        } else {
            threads
        };
        Self {
            threads,
            shared,
            jobs: Some(tx),
            thread,
        }
    }

    /// What the newest job's light buffer holds and its build's seconds
    /// (`None` when the job asked none).
    pub fn light_buffer(&self) -> Option<(crate::accel::LightBufferStats, f64)> {
        *self
            .shared
            .light_buffer
            .lock()
            .unwrap_or_else(|e| e.into_inner())
    }

    /// How many threads render.
    pub fn threads(&self) -> usize {
        self.threads
    }

    /// Starts rendering `job`, abandoning whatever was in flight (a
    /// preview too, and the one waiting for it). Returns the job's
    /// generation.
    pub fn submit(&self, job: Job) -> u64 {
        let mut previews = self.previews();
        *previews = PreviewQueue::default();
        let generation = self.send(job);
        self.shared
            .full_generation
            .store(generation, Ordering::SeqCst);
        generation
    }

    /// The generation of the newest full (not preview) job submitted: the
    /// image whose figures the timing panel shows, or "rendering…" for.
    pub fn full_generation(&self) -> u64 {
        self.shared.full_generation.load(Ordering::SeqCst)
    }

    /// Renders the preview `job` (a job with [`Job::preview`]) without
    /// cancelling a preview in flight: if one is, `job` waits, replacing
    /// any job waiting before it, and starts as soon as the one in flight
    /// is in the display buffer. Latest wins, after completion.
    pub fn submit_preview(&self, job: Job) {
        debug_assert!(job.preview.is_some());
        let mut previews = self.previews();
        if previews.in_flight.is_some() {
            previews.waiting = Some(job);
        } else {
            self.shared.previews_sent.fetch_add(1, Ordering::SeqCst);
            previews.in_flight = Some(self.send(job));
        }
    }

    /// How many previews were started and completed so far.
    pub fn preview_counts(&self) -> PreviewCounts {
        PreviewCounts {
            sent: self.shared.previews_sent.load(Ordering::SeqCst),
            started: self.shared.previews_started.load(Ordering::SeqCst),
            completed: self.shared.previews_completed.load(Ordering::SeqCst),
            dropped: self.shared.previews_dropped.load(Ordering::SeqCst),
        }
    }

    fn previews(&self) -> std::sync::MutexGuard<'_, PreviewQueue> {
        self.shared
            .previews
            .lock()
            .unwrap_or_else(|e| e.into_inner())
    }

    fn send(&self, job: Job) -> u64 {
        let generation = self.shared.generation.fetch_add(1, Ordering::SeqCst) + 1;
        if let Some(tx) = &self.jobs {
            let _ = tx.send((generation, job));
        }
        generation
    }

    pub fn generation(&self) -> u64 {
        self.shared.generation.load(Ordering::SeqCst)
    }

    /// Stops the passes in flight (within a tile per thread), keeping the
    /// image as far as it got; the next submitted job renders as usual.
    pub fn stop(&self) {
        *self.previews() = PreviewQueue::default();
        let mut b = self.shared.buffer.lock().unwrap_or_else(|e| e.into_inner());
        if b.finished {
            return;
        }
        self.shared.generation.fetch_add(1, Ordering::SeqCst);
        b.stopped = true;
        b.version += 1;
        drop(b);
        (self.shared.repaint)();
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

    /// The finished passes, oldest first (the last
    /// 4,096 previews among them). Shared, not copied:
    /// the UI reads it several times a frame.
    pub fn history(&self) -> Arc<Vec<PassRecord>> {
        self.shared
            .history
            .lock()
            .map(|h| Arc::clone(&h.records))
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
        // Cancel the work in flight (and the preview waiting for it),
        // close the channel, then join.
        *self.previews() = PreviewQueue::default();
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
    let mut light_buffers = LightBufferCache::default();
    let mut reuse = ReuseState::default();
    while let Ok(mut next) = rx.recv() {
        // Only the newest job matters.
        let dropped = |job: &Job| {
            if job.preview.is_some() {
                shared.previews_dropped.fetch_add(1, Ordering::SeqCst);
            }
        };
        while let Ok(newer) = rx.try_recv() {
            dropped(&next.1);
            next = newer;
        }
        let (mut generation, mut job) = next;
        loop {
            if shared.generation.load(Ordering::SeqCst) != generation {
                dropped(&job);
                break;
            }
            let started = shared.previews_started.load(Ordering::SeqCst);
            pool.install(|| {
                if job.preview == Some(Preview::Reuse) {
                    reuse_preview(&shared, generation, &job, &mut reuse, &mut light_buffers);
                } else {
                    render_job(&shared, generation, &job, &mut light_buffers);
                }
            });
            if job.preview.is_some() && shared.previews_started.load(Ordering::SeqCst) == started {
                // Cancelled before it began (or shown from the cache).
                dropped(&job);
            }
            if job.preview.is_none() {
                break;
            }
            // The preview is on screen (or was cancelled by a full job,
            // which emptied the queue): the camera that waited starts now.
            let mut previews = shared.previews.lock().unwrap_or_else(|e| e.into_inner());
            if previews.in_flight != Some(generation) {
                break;
            }
            match previews.waiting.take() {
                Some(waiting) => {
                    shared.previews_sent.fetch_add(1, Ordering::SeqCst);
                    generation = shared.generation.fetch_add(1, Ordering::SeqCst) + 1;
                    previews.in_flight = Some(generation);
                    job = waiting;
                }
                None => {
                    previews.in_flight = None;
                    break;
                }
            }
        }
    }
}

/// A render-cache preview of `job`: the cache's points moved into the
/// job's view, fresh rays for what its time allows
/// ([`super::preview::reuse_seconds`] of the frame budget), shown
/// complete (enlarged to the image's size when the cache keeps a point for
/// a block of pixels). The cache is seeded first from the display's last
/// finished full pass when that is newer than its points, or from the
/// picture on screen when its scale changes.
fn reuse_preview(
    shared: &Shared,
    generation: u64,
    job: &Job,
    state: &mut ReuseState,
    light_buffers: &mut LightBufferCache,
) {
    use crate::render::render_cache::{PreviewBudget, enlarge, shrink};
    let start = Instant::now();
    let scale = state.scale;
    let full = (job.settings.width, job.settings.height);
    let mut settings = job.settings;
    settings.set_anti_aliasing(crate::settings::AntiAliasing::Off);
    settings.width = full.0.div_ceil(scale);
    settings.height = full.1.div_ceil(scale);
    // A buffer is built for a new scene, but not again while a light is
    // dragged: its build would take a preview's time every frame.
    let built = job.accelerator(&job.scene, &settings, light_buffers.kept(&job.scene));
    let accel = match built {
        Ok(a) => a,
        Err(e) => {
            shared.fail(format!("cannot render: {e}"));
            return;
        }
    };
    let renderer = match Renderer::with_camera(&job.scene, &accel, settings, &job.camera) {
        Ok(r) => r,
        Err(e) => {
            shared.fail(format!("cannot render: {e}"));
            return;
        }
    };
    shared.previews_started.fetch_add(1, Ordering::SeqCst);
    // The seed: the last finished full pass on screen if newer than the
    // points, or the picture on screen if the cache cannot serve this
    // scale; shrunk to the cache's size.
    let seed = {
        let b = shared.buffer.lock().unwrap_or_else(|e| e.into_inner());
        let newer_final =
            b.pass.is_some_and(|p| p.preview.is_none()) && b.generation > state.generation;
        let rescaled = !state.cache.can_serve(&renderer);
        match (&b.last_frame, &b.source) {
            (Some(frame), Some(source))
                if newer_final
                    && frame.view == crate::settings::ViewMode::Shaded
                    && (frame.width, frame.height) == full =>
            {
                Some((
                    shrink(&rgb_to_rgba(&frame.to_rgb8()), full, scale),
                    source.clone(),
                ))
            }
            (_, Some(source))
                if rescaled
                    && (b.width, b.height) == full
                    && b.rgba.len() == 4 * (full.0 * full.1) as usize =>
            {
                Some((shrink(&b.rgba, full, scale), source.clone()))
            }
            _ => None,
        }
    };
    // The seed's scene may have its lights elsewhere: the kept buffer
    // serves it only if it is of those lights.
    let seed_accel = seed.as_ref().and_then(|(_, source)| {
        job.accelerator(&source.scene, &settings, light_buffers.kept(&source.scene))
            .ok()
    });
    let seed_renderer = seed
        .as_ref()
        .zip(seed_accel.as_ref())
        .and_then(|((_, source), accel)| {
            Renderer::with_camera(&source.scene, accel, settings, &source.camera).ok()
        });
    if seed_renderer.is_some() {
        state.cache.clear();
    }
    // The rays get what the rest of the preview leaves of its time, and
    // never less than a third of it: without fresh rays the points thin
    // out frame by frame.
    let target = super::preview::reuse_seconds(job.frame_budget_ms);
    let budget = PreviewBudget {
        rays: Duration::from_secs_f64((target - state.overhead).max(target / 3.0)),
    };
    let seed_pair = seed_renderer
        .as_ref()
        .zip(seed.as_ref())
        .map(|(r, (rgba, _))| (r, rgba.as_slice()));
    let mut summary = state.cache.preview(&renderer, seed_pair, budget);
    summary.scale = scale;
    state.generation = generation;
    let (image, width, height) = state.cache.image();
    if job.show_sources {
        let mut sources = Vec::new();
        state.cache.source_colors(&mut sources);
        enlarge(&sources, (width, height), full, false, &mut state.shown);
    } else {
        enlarge(image, (width, height), full, true, &mut state.shown);
    }
    {
        let mut b = shared.buffer.lock().unwrap_or_else(|e| e.into_inner());
        // Swapped with the buffer's own allocation: a new one of a frame's
        // size costs a millisecond or more of page faults.
        std::mem::swap(&mut b.rgba, &mut state.shown);
        b.generation = generation;
        b.pass = Some(ShownPass::drag_preview(Preview::Reuse));
        b.stopped = false;
        b.width = full.0;
        b.height = full.1;
        b.serial = job.serial;
        shared.previews_completed.fetch_add(1, Ordering::SeqCst);
        b.source = Some(FrameSource {
            scene: Arc::clone(&job.scene),
            camera: job.camera,
            settings,
            frame_settings: job.settings,
        });
        b.finished = true;
        b.tiles_done = 0;
        b.tiles_total = 0;
        b.pass_started = None;
        // No linear frame: a preview is an approximation, exported only
        // as shown (and recorded as partial).
        b.last_frame = None;
        b.version += 1;
    }
    let seconds = start.elapsed().as_secs_f64();
    // What the preview spent besides rays, smoothed over a few frames.
    let overhead = (seconds - summary.trace_seconds - summary.seed_seconds).max(0.0);
    state.overhead = if state.overhead == 0.0 {
        overhead
    } else {
        0.7 * state.overhead + 0.3 * overhead
    };
    let next = state.adapt(seconds - summary.seed_seconds, target, &summary);
    if next != state.scale {
        state.scale = next;
        state.overhead = 0.0;
    }
    if let Ok(mut history) = shared.history.lock() {
        history.push(PassRecord {
            generation,
            kind: ShownPass::drag_preview(Preview::Reuse),
            seconds,
            rays: summary.rays,
            accel: settings.accel,
            anti_aliasing: false,
            width: full.0,
            height: full.1,
            finished_at: shared.started.elapsed().as_secs_f64(),
            one_sample_error: None,
            refined_pixels: None,
            view: settings.view,
            max_depth: settings.max_depth,
            protocol: settings.protocol,
            from_cache: false,
            reuse: Some(summary),
        });
    }
    (shared.repaint)();
}

fn render_job(shared: &Shared, generation: u64, job: &Job, light_buffers: &mut LightBufferCache) {
    let mut settings = job.settings;
    if let Some(p) = job.preview.and_then(|p| p.reduced()) {
        settings.set_anti_aliasing(crate::settings::AntiAliasing::Off);
        settings.width = (settings.width / p.divisor).max(1);
        settings.height = (settings.height / p.divisor).max(1);
        match p.reflections {
            Reflections::All => {}
            Reflections::OneBounce => settings.max_depth = settings.max_depth.min(2),
            Reflections::Off => settings.max_depth = 1,
        }
        settings.shadows = p.shadows;
    }
    let accel = match job.accelerator(&job.scene, &settings, light_buffers.current(&job.scene)) {
        Ok(a) => a,
        Err(e) => {
            shared.fail(format!("cannot render: {e}"));
            return;
        }
    };
    let seconds = light_buffers.keep(&job.scene, &accel);
    *shared
        .light_buffer
        .lock()
        .unwrap_or_else(|e| e.into_inner()) = accel.light_buffer().map(|b| (b.stats(), seconds));
    let renderer = match Renderer::with_camera(&job.scene, &accel, settings, &job.camera) {
        Ok(r) => r,
        Err(e) => {
            shared.fail(format!("cannot render: {e}"));
            return;
        }
    };
    if job.preview.is_none() {
        let switched = {
            let mut last = shared
                .last_octree_switch
                .lock()
                .unwrap_or_else(|e| e.into_inner());
            let switched = last.is_some_and(|accel| accel != job.settings.accel);
            *last = Some(job.settings.accel);
            switched
        };
        if !switched && show_cached(shared, generation, job, &renderer.plan(true)) {
            return;
        }
    }
    if job.preview.is_some() {
        shared.previews_started.fetch_add(1, Ordering::SeqCst);
    }
    let watch = Display {
        shared,
        generation,
        job,
        settings,
        done: AtomicU64::new(0),
    };
    let options = PassOptions {
        count_work: false,
        progressive: job.preview.is_none(),
    };
    renderer.render_frame(options, &watch);
}

/// Shows the job's image from the pass cache when every pass it needs is
/// there (the last pass; for aa-need the 1-sample pass too), with their
/// records marked as from the cache. `false`: it must be rendered.
fn show_cached(
    shared: &Shared,
    generation: u64,
    job: &Job,
    plan: &[crate::render::PassKind],
) -> bool {
    use crate::render::PassKind as Engine;
    use crate::settings::ViewMode;
    let Some(&last) = plan.last() else {
        return false;
    };
    let aa_need = job.settings.view == ViewMode::AaNeed;
    let (frame, records) = {
        let cache = shared.cache.lock().unwrap_or_else(|e| e.into_inner());
        let Some(final_pass) = cache.find(&job.pass_key(last)) else {
            return false;
        };
        let mut records = vec![final_pass.record];
        let one = (last != Engine::OneSample)
            .then(|| cache.find(&job.pass_key(Engine::OneSample)))
            .flatten();
        if let Some(one) = one {
            // The timing panel shows the 1-sample pass beside the last.
            records.insert(0, one.record);
        }
        let frame = if aa_need && last != Engine::OneSample {
            let Some(one) = one else {
                return false;
            };
            Frame::aa_need(&one.frame, &final_pass.frame)
        } else {
            final_pass.frame.clone()
        };
        (frame, records)
    };
    if shared.generation.load(Ordering::SeqCst) != generation {
        return true;
    }
    if let Ok(mut history) = shared.history.lock() {
        // `finished_at` stays the pass's own: the frame budget compares it
        // with the last preview's.
        for r in records {
            history.push(PassRecord {
                generation,
                anti_aliasing: job.settings.samples > 1,
                accel: job.settings.accel,
                view: job.settings.view,
                from_cache: true,
                ..r
            });
        }
    }
    // What the last pass traced, as the engine says ([`Display`]'s records
    // of rendered passes read the same).
    let mut settings = crate::render::pass_settings(job.settings, last);
    settings.view = frame.view;
    {
        let mut b = shared.buffer.lock().unwrap_or_else(|e| e.into_inner());
        b.generation = generation;
        b.rgba = rgb_to_rgba(&frame.to_rgb8());
        b.width = frame.width;
        b.height = frame.height;
        b.pass = Some(ShownPass::full(last));
        b.tiles_done = 0;
        b.tiles_total = 0;
        b.finished = true;
        b.pass_started = None;
        b.stopped = false;
        b.source = Some(FrameSource {
            scene: Arc::clone(&job.scene),
            camera: job.camera,
            settings,
            frame_settings: job.settings,
        });
        b.serial = job.serial;
        b.last_frame = Some(frame);
        b.version += 1;
    }
    (shared.repaint)();
    true
}

#[cfg(test)]
mod tests;
