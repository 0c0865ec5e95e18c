//! `glint view --orbit-bench SECONDS`: the viewer orbits its own scene with
//! synthetic pointer events, sent through egui's input at a steady rate as
//! a mouse would send them, and reports how many previews a user saw, how
//! late, and how long the final image took after the drag.
//!
//! The drag starts once the scene's first image is complete (the frame
//! budget then has a full pass to estimate from, as it has for a user who
//! looks before dragging). The pointer moves steadily right along the
//! image's middle row, from near its left edge across 1.4 image widths
//! (past the image, still in the window), so the camera turns about the
//! up axis at a constant rate, its height unchanged: the last view shows
//! the scene from another side, as costly to render as the first.

use std::path::PathBuf;
use std::time::{Duration, Instant};

use egui::{Event, Modifiers, PointerButton, Pos2};

use super::worker::{DisplayBuffer, FrameSource, PassRecord, PreviewCounts, ShownPass};

/// What the benchmark drives.
#[derive(Clone, Debug, PartialEq)]
pub struct OrbitBenchOptions {
    /// How long the drag lasts.
    pub seconds: f64,
    /// Pointer events per second.
    pub event_hz: f64,
    /// Write each preview shown during the drag here, as shown, once the
    /// benchmark is over (so writing costs the drag nothing).
    pub save_previews: Option<PathBuf>,
}

/// A preview as it was shown, kept until the benchmark is over.
pub struct CapturedPreview {
    pub rgba: Vec<u8>,
    pub width: u32,
    pub height: u32,
    pub source: FrameSource,
}

impl CapturedPreview {
    /// The picture in `b` as shown, if it is a finished preview.
    pub fn of(b: &DisplayBuffer) -> Option<Self> {
        if !(b.finished && b.pass.is_some_and(|p| p.preview.is_some())) {
            return None;
        }
        b.source.clone().map(|source| Self {
            rgba: b.rgba.clone(),
            width: b.width,
            height: b.height,
            source,
        })
    }
}

/// A shown frame, as the UI uploaded it.
#[derive(Clone, Copy, Debug)]
pub struct ShownFrame {
    pub generation: u64,
    /// The input serial of the job it came from.
    pub serial: u64,
    pub pass: Option<ShownPass>,
    pub finished: bool,
}

impl ShownFrame {
    /// The frame `b` holds.
    pub fn of(b: &DisplayBuffer) -> Self {
        Self {
            generation: b.generation,
            serial: b.serial,
            pass: b.pass,
            finished: b.finished,
        }
    }
}

enum Phase {
    /// Waiting for the scene's first complete image.
    Waiting,
    /// Sending the drag's events on their schedule.
    Dragging(Drag),
    /// The button is up: waiting for the final pass.
    Settling(Drag),
    Done,
}

struct Drag {
    start: Instant,
    /// Where the drag starts and how far it goes, in points.
    from: Pos2,
    length: f32,
    /// Moves sent so far (the press goes with the first).
    sent: u64,
    /// Each move's scheduled time and the input serial it got.
    moves: Vec<(Instant, u64)>,
    released: Option<(Instant, u64)>,
    /// Moves up to this index have their latency.
    answered: usize,
    latencies_ms: Vec<f64>,
    previews_shown: u64,
    last_preview_generation: u64,
    newest_shown_serial: u64,
    older_than_shown: u64,
    first_generation: u64,
    counts_before: PreviewCounts,
    counts_at_release: PreviewCounts,
}

pub struct OrbitBench {
    options: OrbitBenchOptions,
    phase: Phase,
    /// The previews shown, when they are to be saved.
    captured: Vec<CapturedPreview>,
    /// When the next frame is needed (asked for during the frame: a
    /// request made before it begins is spent on the frame itself).
    wake: Option<Instant>,
}

/// Seconds the drag waits after the first image before its first event
/// (the window settles).
const LEAD_IN: Duration = Duration::from_millis(300);

/// The drag's length in image widths.
const DRAG_WIDTHS: f32 = 1.4;

impl OrbitBench {
    pub fn new(options: OrbitBenchOptions) -> Self {
        Self {
            options,
            phase: Phase::Waiting,
            captured: Vec::new(),
            wake: None,
        }
    }

    /// Whether shown previews are kept to be saved.
    pub fn saves_previews(&self) -> bool {
        self.options.save_previews.is_some()
    }

    /// Moves in the drag: one per event period, the press with the first.
    fn move_count(&self) -> u64 {
        (self.options.seconds * self.options.event_hz)
            .round()
            .max(1.0) as u64
    }

    /// Called before each frame with its raw input: starts the drag once
    /// `ready` (the first image is complete), appends the events now due,
    /// and notes when the next one is due ([`Self::request_wake`]). `serial` is the count of
    /// pointer events the viewer has had before this frame;
    /// `generation` the worker's generation; `counts` its preview counts.
    pub fn inject(
        &mut self,
        raw: &mut egui::RawInput,
        image_rect: Option<egui::Rect>,
        ready: bool,
        (serial, generation, counts): (u64, u64, PreviewCounts),
    ) {
        if let Phase::Waiting = self.phase {
            let Some(rect) = image_rect.filter(|_| ready) else {
                // Look again soon: the frame that shows the image comes
                // after this input.
                self.wake = Some(Instant::now() + Duration::from_millis(20));
                return;
            };
            self.phase = Phase::Dragging(Drag {
                start: Instant::now() + LEAD_IN,
                from: egui::pos2(rect.left() + 0.05 * rect.width(), rect.center().y),
                length: DRAG_WIDTHS * rect.width(),
                sent: 0,
                moves: Vec::new(),
                released: None,
                answered: 0,
                latencies_ms: Vec::new(),
                previews_shown: 0,
                last_preview_generation: 0,
                newest_shown_serial: 0,
                older_than_shown: 0,
                first_generation: generation,
                counts_before: counts,
                counts_at_release: counts,
            });
        }
        let moves = self.move_count();
        let period = 1.0 / self.options.event_hz;
        let Phase::Dragging(drag) = &mut self.phase else {
            return;
        };
        // Pointer events already in this frame's input come first.
        let mut serial = serial + raw.events.iter().filter(|e| is_pointer(e)).count() as u64;
        let now = Instant::now();
        let at = |k: u64| drag.start + Duration::from_secs_f64(k as f64 * period);
        let position = |k: u64| {
            let share = (k as f64 / (moves.max(2) - 1) as f64) as f32;
            drag.from + egui::vec2(share * drag.length, 0.0)
        };
        while drag.sent < moves && at(drag.sent) <= now {
            let k = drag.sent;
            let pos = position(k);
            raw.events.push(Event::PointerMoved(pos));
            serial += 1;
            if k == 0 {
                raw.events.push(Event::PointerButton {
                    pos,
                    button: PointerButton::Primary,
                    pressed: true,
                    modifiers: Modifiers::NONE,
                });
                serial += 1;
            }
            drag.moves.push((at(k), serial));
            drag.sent += 1;
        }
        if drag.sent < moves {
            self.wake = Some(at(drag.sent));
            return;
        }
        if at(moves) > now {
            self.wake = Some(at(moves));
            return;
        }
        raw.events.push(Event::PointerButton {
            pos: position(moves - 1),
            button: PointerButton::Primary,
            pressed: false,
            modifiers: Modifiers::NONE,
        });
        serial += 1;
        drag.released = Some((at(moves), serial));
        drag.counts_at_release = counts;
        if let Phase::Dragging(drag) = std::mem::replace(&mut self.phase, Phase::Done) {
            self.phase = Phase::Settling(drag);
        }
        self.wake = Some(now);
    }

    /// Called when the UI uploads a new image: counts shown previews and
    /// answers the moves it reflects. `capture` gives the image as shown,
    /// asked for only when it is a new preview and previews are saved.
    pub fn shown(&mut self, frame: ShownFrame, capture: impl FnOnce() -> Option<CapturedPreview>) {
        let (Phase::Dragging(drag) | Phase::Settling(drag)) = &mut self.phase else {
            return;
        };
        if frame.generation < drag.first_generation {
            return;
        }
        let now = Instant::now();
        if frame.serial < drag.newest_shown_serial {
            drag.older_than_shown += 1;
        }
        drag.newest_shown_serial = drag.newest_shown_serial.max(frame.serial);
        if frame.pass.is_some_and(|p| p.preview.is_some())
            && frame.finished
            && frame.generation != drag.last_preview_generation
        {
            drag.previews_shown += 1;
            drag.last_preview_generation = frame.generation;
            if self.options.save_previews.is_some()
                && let Some(c) = capture()
            {
                self.captured.push(c);
            }
        }
        while let Some(&(at, serial)) = drag.moves.get(drag.answered) {
            if serial > frame.serial {
                break;
            }
            drag.latencies_ms
                .push(now.saturating_duration_since(at).as_secs_f64() * 1000.0);
            drag.answered += 1;
        }
    }

    /// After the frame: once the final pass of the settings after the
    /// drag is on screen, the report (one JSON object), and the benchmark
    /// is over.
    pub fn finish(
        &mut self,
        final_shown: Option<u64>,
        history: &[PassRecord],
        counts: PreviewCounts,
        describe: serde_json::Value,
    ) -> Option<serde_json::Value> {
        let Phase::Settling(drag) = &self.phase else {
            return None;
        };
        let (released_at, release_serial) = drag.released?;
        if final_shown.is_none_or(|serial| serial < release_serial) {
            return None;
        }
        let final_ms = released_at.elapsed().as_secs_f64() * 1000.0;
        let mut report = report(drag, &self.options, final_ms, history, counts, describe);
        self.phase = Phase::Done;
        if let (Some(dir), Some(out)) = (&self.options.save_previews, report.as_object_mut()) {
            let captured = std::mem::take(&mut self.captured);
            match save_previews(dir, &captured) {
                Ok(n) => {
                    out.insert("previews_saved".into(), n.into());
                    out.insert("previews_dir".into(), dir.display().to_string().into());
                }
                Err(e) => {
                    out.insert("previews_saved".into(), 0.into());
                    out.insert("previews_save_error".into(), format!("{e:#}").into());
                }
            }
        }
        Some(report)
    }

    /// During a frame: asks for the next one when the benchmark needs it.
    pub fn request_wake(&mut self, ctx: &egui::Context) {
        if let Some(at) = self.wake.take() {
            ctx.request_repaint_after(at.saturating_duration_since(Instant::now()));
        }
    }

    pub fn is_done(&self) -> bool {
        matches!(self.phase, Phase::Done)
    }
}

/// Writes each captured preview to `dir/preview_NNNN.png` (from 0001, in
/// the order shown) at the size of the frame it stands for, as the viewer
/// drew it (a reduced preview scaled up to its nearest pixels), with the
/// record of that frame: `glint render --from-png` on it renders the final
/// image at the preview's camera. Returns how many were written.
fn save_previews(dir: &std::path::Path, captured: &[CapturedPreview]) -> anyhow::Result<usize> {
    use crate::image::frame::{resample_rgba, rgba_to_rgb};
    std::fs::create_dir_all(dir)?;
    for (k, c) in captured.iter().enumerate() {
        let settings = c.source.frame_settings;
        let (w, h) = (settings.width, settings.height);
        let rgba = if (c.width, c.height) == (w, h) {
            std::borrow::Cow::Borrowed(&c.rgba)
        } else {
            std::borrow::Cow::Owned(resample_rgba(&c.rgba, c.width, c.height, w, h))
        };
        let record = super::export::record_of(&c.source, settings);
        let path = dir.join(format!("preview_{:04}.png", k + 1));
        crate::export::save_rgb_png(&path, w, h, &rgba_to_rgb(&rgba), Some(&record))?;
    }
    Ok(captured.len())
}

/// The events that count towards the viewer's input serial.
pub fn is_pointer(event: &Event) -> bool {
    matches!(
        event,
        Event::PointerMoved(_) | Event::PointerButton { .. } | Event::PointerGone
    )
}

/// The value below which a share `q` of `values` lie (nearest rank).
fn percentile(values: &[f64], q: f64) -> Option<f64> {
    let mut sorted = values.to_vec();
    sorted.sort_by(f64::total_cmp);
    let rank = ((q * sorted.len() as f64).ceil() as usize).clamp(1, sorted.len().max(1));
    sorted.get(rank - 1).copied()
}

fn report(
    drag: &Drag,
    options: &OrbitBenchOptions,
    final_ms: f64,
    history: &[PassRecord],
    counts: PreviewCounts,
    describe: serde_json::Value,
) -> serde_json::Value {
    let during = PreviewCounts {
        sent: drag.counts_at_release.sent - drag.counts_before.sent,
        started: drag.counts_at_release.started - drag.counts_before.started,
        completed: drag.counts_at_release.completed - drag.counts_before.completed,
        dropped: drag.counts_at_release.dropped - drag.counts_before.dropped,
    };
    // Previews still in flight at the release end in the final passes'
    // cancellation: count them from the whole run.
    let started = counts.started - drag.counts_before.started;
    let completed = counts.completed - drag.counts_before.completed;
    let mut choices: Vec<(String, Vec<f64>)> = Vec::new();
    for r in history
        .iter()
        .filter(|r| r.generation > drag.first_generation)
    {
        let Some(p) = r.kind.preview else {
            continue;
        };
        let name = p.describe();
        match choices.iter_mut().find(|(n, _)| *n == name) {
            Some((_, times)) => times.push(r.seconds * 1000.0),
            None => choices.push((name, vec![r.seconds * 1000.0])),
        }
    }
    let round = |x: f64| (x * 10.0).round() / 10.0;
    // The passes of the image on screen at the end: what `final_ms` waited for.
    let last_generation = history.last().map(|r| r.generation);
    let final_passes: Vec<serde_json::Value> = history
        .iter()
        .filter(|r| Some(r.generation) == last_generation)
        .map(|r| {
            serde_json::json!({
                "pass": r.kind.label(),
                "ms": round(r.seconds * 1000.0),
                "from_cache": r.from_cache,
            })
        })
        .collect();
    let choices: Vec<serde_json::Value> = choices
        .into_iter()
        .map(|(name, times)| {
            serde_json::json!({
                "preview": name,
                "count": times.len(),
                "median_ms": percentile(&times, 0.5).map(round),
            })
        })
        .collect();
    let mut out = serde_json::json!({
        "seconds": options.seconds,
        "event_hz": options.event_hz,
        "events": drag.sent + 2,
        "previews_started": started,
        "previews_shown": drag.previews_shown,
        "previews_cancelled": started - completed,
        "previews_completed_unshown": completed.saturating_sub(drag.previews_shown),
        "previews_started_while_dragging": during.started,
        "shown_per_s": round(drag.previews_shown as f64 / options.seconds),
        "latency_ms_p50": percentile(&drag.latencies_ms, 0.5).map(round),
        "latency_ms_p95": percentile(&drag.latencies_ms, 0.95).map(round),
        "latency_ms_max": percentile(&drag.latencies_ms, 1.0).map(round),
        "moves_answered": drag.answered,
        "shown_older_than_shown": drag.older_than_shown,
        "choices": choices,
        "final_ms": round(final_ms),
        "final_passes": final_passes,
    });
    if let (Some(out), serde_json::Value::Object(extra)) = (out.as_object_mut(), describe) {
        out.extend(extra);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentiles_take_the_nearest_rank() {
        let v: Vec<f64> = (1..=20).map(f64::from).collect();
        assert_eq!(percentile(&v, 0.5), Some(10.0));
        assert_eq!(percentile(&v, 0.95), Some(19.0));
        assert_eq!(percentile(&v, 1.0), Some(20.0));
        assert_eq!(percentile(&[3.0], 0.95), Some(3.0));
        assert_eq!(percentile(&[], 0.5), None);
    }
}
