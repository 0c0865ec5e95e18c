//! The passes that make a frame, each swept tile by tile in parallel:
//! progressive (a watcher sees every tile as it finishes and every pass as
//! it ends) and cancellable (the watcher is asked before each tile). This
//! is the one engine: `glint render`, `bench`, `study` and the viewer all
//! render through [`Renderer::render_frame`], so what the viewer shows is
//! what the command line writes.
//!
//! The split follows pbrt's: the integrator finds the colour along one ray
//! (`integrator.rs`), this file owns the tile and progress loop.

use std::sync::atomic::{AtomicU64, Ordering};
use std::time::Instant;

use rayon::prelude::*;

use crate::image::frame::{Frame, TileEncoder};
use crate::image::metrics::ImageError;
use crate::math::DVec3;
use crate::settings::{AntiAliasing, RenderSettings, ViewMode};
use crate::stats::RenderCounts;

use super::adaptive::refine_mask;
use super::renderer::Renderer;
use super::tile_job::TileJob;
use super::tiles::{Tile, TileBands, corner_bands, place_tile, tiles};

/// One sweep over the image.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum PassKind {
    /// One ray through each pixel's centre.
    OneSample,
    /// The regular grid of samples in every pixel.
    Grid,
    /// The grid only where the one-sample pass shows an edge (adaptive
    /// anti-aliasing); the other pixels keep their centre sample.
    Refine,
    /// The SPD protocol's rays through the pixel corners, each pixel the
    /// mean of its four.
    Corners,
}

impl PassKind {
    pub fn name(self) -> &'static str {
        match self {
            PassKind::OneSample => "1 sample",
            PassKind::Grid => "full grid",
            PassKind::Refine => "adaptive refinement",
            PassKind::Corners => "SPD corners",
        }
    }
}

/// How a frame is rendered, beyond its settings.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct PassOptions {
    /// Count Havran's work measures (intersection tests, traversal steps,
    /// leaves) per ray; tracing compiles the counting away otherwise.
    pub count_work: bool,
    /// Show the picture early, as the viewer does: a one-sample pass before
    /// the full grid, and each refining pass's error against it.
    pub progressive: bool,
}

/// The settings pass `kind` of a frame of `frame` settings traces with:
/// its own sampling (1 ray for the one-sample pass; the grid, adaptive or
/// not, for the others; the aa-need view's grid is always the 4x4 one) and
/// the view its pixels show (shaded, for the aa-need view's passes). What
/// a pass renders is decided here, once; the viewer's pass cache and
/// export records read it from [`PassInfo::settings`].
pub fn pass_settings(frame: RenderSettings, kind: PassKind) -> RenderSettings {
    let mut s = frame;
    let aa_need = frame.view == ViewMode::AaNeed;
    if aa_need {
        s.view = ViewMode::Shaded;
    }
    let grid = if aa_need {
        AntiAliasing::SAMPLES
    } else {
        frame.samples
    };
    match kind {
        PassKind::OneSample => (s.samples, s.adaptive) = (1, false),
        PassKind::Grid => (s.samples, s.adaptive) = (grid, false),
        PassKind::Refine => (s.samples, s.adaptive) = (grid, true),
        PassKind::Corners => {}
    }
    s
}

/// A pass as it starts: which one, of how many, over how many tiles.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PassInfo {
    pub kind: PassKind,
    /// The settings this pass traces with ([`pass_settings`]).
    pub settings: RenderSettings,
    /// Position in the frame's passes, from 0.
    pub index: usize,
    pub passes: usize,
    pub width: u32,
    pub height: u32,
    /// Units of work in this pass (tiles; rows of tiles for corner rays).
    pub tiles: u64,
    /// Tiles in the frame's earlier passes, and in all of them.
    pub tiles_before: u64,
    pub frame_tiles: u64,
    /// What the pass's pixels show: the frame's view, except that the
    /// aa-need view shows shaded passes until its last one is done.
    pub view: ViewMode,
}

impl PassInfo {
    pub fn is_last(&self) -> bool {
        self.index + 1 == self.passes
    }
}

/// A finished tile: where it lies in the image, and (when the watcher
/// [shows tiles](PassWatch::shows_tiles)) its pixels and their display
/// bytes on demand: depth and cost normalised by what the pass has seen so
/// far, which the finished pass's frame replaces with the exact picture.
pub struct FinishedTile<'a> {
    pub tile: Tile,
    values: Option<&'a [DVec3]>,
    encoder: &'a TileEncoder,
}

impl<'a> FinishedTile<'a> {
    pub(super) fn new(tile: Tile, values: Option<&'a [DVec3]>, encoder: &'a TileEncoder) -> Self {
        Self {
            tile,
            values,
            encoder,
        }
    }

    /// The tile's values, row-major, as its pass's frame holds them.
    pub fn values(&self) -> Option<&[DVec3]> {
        self.values
    }

    /// Paints the tile's display colours into `rgba`, an RGBA8 image
    /// `width` pixels wide; `false` without pixels.
    pub fn paint_rgba(&self, rgba: &mut [u8], width: u32) -> bool {
        let Some(values) = self.values else {
            return false;
        };
        let bytes = crate::image::frame::rgb_to_rgba(&self.encoder.rgb(values));
        place_tile(rgba, width, &self.tile, &bytes, 4);
        true
    }
}

/// What a pass took and found.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PassSummary {
    pub kind: PassKind,
    pub seconds: f64,
    pub counts: RenderCounts,
    /// For an adaptive refinement: the pixels it refined.
    pub refined_pixels: Option<u64>,
    /// For a pass refining a one-sample pass of the same frame (when
    /// progressive): the one-sample picture's error against it, i.e. what
    /// anti-aliasing changed.
    pub one_sample_error: Option<ImageError>,
}

/// A finished pass: its frame as it should be shown (for the aa-need view's
/// last pass, the difference image) and its summary.
pub struct FinishedPass<'a> {
    pub info: PassInfo,
    /// The frame to show.
    pub frame: &'a Frame,
    /// What the pass traced: `frame` itself, except for the aa-need view's
    /// last pass, whose `frame` is the difference of two traced frames.
    pub traced: &'a Frame,
    pub summary: &'a PassSummary,
}

/// Sees a frame being rendered; every method has a default that does
/// nothing, so a watcher implements what it needs. Called from the render
/// threads (tiles) and the calling thread (passes).
pub trait PassWatch: Sync {
    /// Asked before each tile; `false` abandons the frame (stale work is
    /// dropped within one tile per thread).
    fn start_tile(&self, _pass: &PassInfo) -> bool {
        true
    }
    /// Whether [`PassWatch::tile_done`] wants the tiles' pixels.
    fn shows_tiles(&self) -> bool {
        false
    }
    fn pass_started(&self, _pass: &PassInfo) {}
    /// A tile of the image is done.
    fn tile_done(&self, _pass: &PassInfo, _tile: &FinishedTile) {}
    fn pass_done(&self, _pass: &FinishedPass) {}
}

/// Watches nothing.
impl PassWatch for () {}

/// Reports progress as (tiles done, tiles in the frame).
struct Progress<'a> {
    done: AtomicU64,
    report: &'a (dyn Fn(u64, u64) + Sync),
}

impl PassWatch for Progress<'_> {
    fn tile_done(&self, pass: &PassInfo, _tile: &FinishedTile) {
        let n = self.done.fetch_add(1, Ordering::Relaxed) + 1;
        (self.report)(n, pass.frame_tiles);
    }
}

/// A rendered frame: the picture, the counts of all its passes, and each
/// pass's own figures.
#[derive(Clone, Debug)]
pub struct RenderedFrame {
    pub frame: Frame,
    pub counts: RenderCounts,
    pub passes: Vec<PassSummary>,
}

/// The one-sample pass of a frame, kept for the passes that refine it.
struct FirstPass {
    frame: Frame,
    signatures: Vec<u64>,
}

impl Renderer<'_> {
    /// The passes a frame of these settings takes: the SPD's corners; one
    /// sample; adaptive refinement after the one-sample pass; the full grid
    /// (after a one-sample pass when `progressive`, or for the aa-need view,
    /// which shows their difference).
    pub fn plan(&self, progressive: bool) -> Vec<PassKind> {
        let s = &self.settings;
        if s.corner_rays() {
            return vec![PassKind::Corners];
        }
        let aa_need = s.view == ViewMode::AaNeed;
        if s.samples == 1 && !aa_need {
            vec![PassKind::OneSample]
        } else if s.adaptive {
            vec![PassKind::OneSample, PassKind::Refine]
        } else if progressive || aa_need {
            vec![PassKind::OneSample, PassKind::Grid]
        } else {
            vec![PassKind::Grid]
        }
    }

    /// Renders every pass of the frame on the current rayon pool, telling
    /// `watch`; `None` if the watcher abandoned it.
    pub fn render_frame(
        &self,
        options: PassOptions,
        watch: &dyn PassWatch,
    ) -> Option<RenderedFrame> {
        let plan = self.plan(options.progressive);
        let (w, h) = (self.settings.width, self.settings.height);
        let tile_list = tiles(w, h);
        let tiles_of = |kind: PassKind| match kind {
            PassKind::Corners => corner_bands(h).len() as u64,
            _ => tile_list.len() as u64,
        };
        let frame_tiles = plan.iter().map(|&k| tiles_of(k)).sum();
        let view = self.settings.view;
        let traced_view = if view == ViewMode::AaNeed {
            ViewMode::Shaded
        } else {
            view
        };
        let colors = self.settings.colors;
        let mut first: Option<FirstPass> = None;
        let mut total = RenderCounts::default();
        let mut summaries = Vec::new();
        let mut tiles_before = 0;
        for (index, &kind) in plan.iter().enumerate() {
            let info = PassInfo {
                kind,
                settings: pass_settings(self.settings, kind),
                index,
                passes: plan.len(),
                width: w,
                height: h,
                tiles: tiles_of(kind),
                tiles_before,
                frame_tiles,
                view: traced_view,
            };
            tiles_before += info.tiles;
            watch.pass_started(&info);
            let start = Instant::now();
            let encoder = TileEncoder::new(traced_view, colors);
            let (pixels, signatures, counts) = match kind {
                PassKind::Corners => {
                    let (pixels, counts) =
                        self.corner_pass(&info, options.count_work, watch, &encoder)?;
                    (pixels, Vec::new(), counts)
                }
                PassKind::OneSample => {
                    let job = TileJob::Centre {
                        signatures: plan.contains(&PassKind::Refine),
                    };
                    self.tile_pass(&info, &tile_list, job, options.count_work, watch, &encoder)?
                }
                PassKind::Grid => self.tile_pass(
                    &info,
                    &tile_list,
                    TileJob::Grid,
                    options.count_work,
                    watch,
                    &encoder,
                )?,
                PassKind::Refine => {
                    let one = first.as_ref()?;
                    let mask = refine_mask(&one.frame.to_rgb8(), &one.signatures, w, h);
                    let job = TileJob::Refine {
                        first: &one.frame.pixels,
                        mask: &mask,
                    };
                    self.tile_pass(&info, &tile_list, job, options.count_work, watch, &encoder)?
                }
            };
            let frame = Frame {
                width: w,
                height: h,
                view: traced_view,
                colors,
                pixels,
            };
            let seconds = start.elapsed().as_secs_f64();
            let refines = matches!(kind, PassKind::Grid | PassKind::Refine);
            let summary = PassSummary {
                kind,
                seconds,
                counts,
                refined_pixels: (kind == PassKind::Refine).then_some(counts.refined_pixels),
                one_sample_error: first
                    .as_ref()
                    .filter(|_| options.progressive && refines)
                    .map(|one| {
                        crate::image::metrics::image_error(&one.frame.pixels, &frame.pixels, colors)
                    }),
            };
            total += counts;
            let difference = match &first {
                Some(one) if info.is_last() && view == ViewMode::AaNeed => {
                    Some(Frame::aa_need(&one.frame, &frame))
                }
                _ => None,
            };
            watch.pass_done(&FinishedPass {
                info,
                frame: difference.as_ref().unwrap_or(&frame),
                traced: &frame,
                summary: &summary,
            });
            let shown = difference.unwrap_or(frame);
            summaries.push(summary);
            if info.is_last() {
                return Some(RenderedFrame {
                    frame: shown,
                    counts: total,
                    passes: summaries,
                });
            }
            if kind == PassKind::OneSample {
                first = Some(FirstPass {
                    frame: shown,
                    signatures,
                });
            }
        }
        None
    }

    /// Renders the whole frame (every pass, none shown) on the current
    /// rayon pool; `progress` is told (tiles done, tiles in the frame).
    pub fn render(
        &self,
        count_work: bool,
        progress: Option<&(dyn Fn(u64, u64) + Sync)>,
    ) -> (Frame, RenderCounts) {
        let options = PassOptions {
            count_work,
            progressive: false,
        };
        let rendered = match progress {
            Some(report) => self.render_frame(
                options,
                &Progress {
                    done: AtomicU64::new(0),
                    report,
                },
            ),
            None => self.render_frame(options, &()),
        };
        match rendered {
            Some(r) => (r.frame, r.counts),
            None => unreachable!("a watcher that never abandons a frame"),
        }
    }

    /// Traces every `every`-th row of the image (rows 0, every, 2 every, ...)
    /// with the frame's full sampling (the grid, or the corner rays of the
    /// row's top edge) without keeping the pixels: a deterministic subset
    /// for estimating the cost of slow configurations.
    pub fn trace_rows(&self, every: u32, count_work: bool) -> RenderCounts {
        let w = self.settings.width;
        let rows: Vec<u32> = (0..self.settings.height)
            .step_by(every.max(1) as usize)
            .collect();
        let per_row: Vec<RenderCounts> = rows
            .par_iter()
            .map(|&y| {
                let (job, width) = if self.settings.corner_rays() {
                    (TileJob::Corners, w + 1)
                } else if self.grid.len() == 1 {
                    (TileJob::Centre { signatures: false }, w)
                } else {
                    (TileJob::Grid, w)
                };
                let tile = Tile {
                    x: 0,
                    y,
                    width,
                    height: 1,
                };
                self.run_tile(job, tile, count_work).counts
            })
            .collect();
        let mut total = RenderCounts::default();
        for c in per_row {
            total += c;
        }
        total
    }

    /// One pass of `job` over `tiles` in parallel: the frame's pixels, the
    /// signatures of a centre pass that keeps them, and the counts summed
    /// in tile order. `None` if the watcher abandoned it.
    fn tile_pass(
        &self,
        info: &PassInfo,
        tiles: &[Tile],
        job: TileJob,
        count_work: bool,
        watch: &dyn PassWatch,
        encoder: &TileEncoder,
    ) -> Option<(Vec<DVec3>, Vec<u64>, RenderCounts)> {
        let shows = watch.shows_tiles();
        let (w, h) = (info.width, info.height);
        let keeps_signatures = matches!(job, TileJob::Centre { signatures: true });
        // Each tile is placed as it finishes (under the lock of its band of
        // rows), so the frame is whole when the last one is: placed after
        // the pass, one by one, the tiles of an 800x600 frame kept the
        // other threads idle for 5-8 ms of its 120 ms.
        let mut pixels = filled(w, h, DVec3::ZERO);
        let mut signatures = if keeps_signatures {
            filled(w, h, 0u64)
        } else {
            Vec::new()
        };
        let (pixel_bands, signature_bands) = (
            TileBands::new(&mut pixels, w),
            TileBands::new(&mut signatures, w),
        );
        let per_tile: Vec<Option<RenderCounts>> = tiles
            .par_iter()
            .map(|&tile| {
                if !watch.start_tile(info) {
                    return None;
                }
                let out = self.run_tile(job, tile, count_work);
                let values = shows.then_some(out.values.as_slice());
                watch.tile_done(info, &FinishedTile::new(tile, values, encoder));
                pixel_bands.place(&tile, &out.values);
                if keeps_signatures {
                    signature_bands.place(&tile, &out.signatures);
                }
                Some(out.counts)
            })
            .collect();
        let mut counts = RenderCounts::default();
        for tile_counts in per_tile {
            counts += tile_counts?;
        }
        Some((pixels, signatures, counts))
    }
}

/// `width` x `height` copies of `value`, written in parallel (a frame of
/// 1024x768 pixels is 19 MB).
fn filled<T: Copy + Send + Sync>(width: u32, height: u32, value: T) -> Vec<T> {
    (0..width as usize * height as usize)
        .into_par_iter()
        .map(|_| value)
        .collect()
}
