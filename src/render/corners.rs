//! The SPD protocol's corner pass: an image of `w x h` pixels shoots its
//! `(w + 1) x (h + 1)` pixel corners once each, and each pixel is the mean
//! of its four. The corners are traced in bands of rows in parallel; a band
//! of pixels is shown as soon as its corner rows and the first row of the
//! next band are traced, so the pass sweeps in like the others without
//! tracing any corner twice.

use std::sync::{Arc, Mutex};

use rayon::prelude::*;

use crate::image::frame::TileEncoder;
use crate::math::DVec3;
use crate::stats::RenderCounts;

use super::passes::{FinishedTile, PassInfo, PassWatch};
use super::renderer::Renderer;
use super::tile_job::{PixelSum, TileJob};
use super::tiles::{Tile, corner_bands};

/// Corner rows traced so far, by band, and which bands of pixels were shown.
struct Traced {
    rows: Vec<Option<Arc<Vec<DVec3>>>>,
    shown: Vec<bool>,
}

impl Renderer<'_> {
    /// Every corner ray once, then the pixels from them; `None` if the
    /// watcher abandoned the pass.
    pub(super) fn corner_pass(
        &self,
        info: &PassInfo,
        count_work: bool,
        watch: &dyn PassWatch,
        encoder: &TileEncoder,
    ) -> Option<(Vec<DVec3>, RenderCounts)> {
        let (w, h) = (info.width, info.height);
        let stride = w + 1;
        let bands = corner_bands(h);
        let traced = Mutex::new(Traced {
            rows: vec![None; bands.len()],
            shown: vec![false; bands.len()],
        });
        let shows = watch.shows_tiles();
        let results: Vec<Option<(Arc<Vec<DVec3>>, RenderCounts)>> = bands
            .par_iter()
            .enumerate()
            .map(|(k, &(start, end))| {
                if !watch.start_tile(info) {
                    return None;
                }
                let tile = Tile {
                    x: 0,
                    y: start,
                    width: stride,
                    height: end - start,
                };
                let out = self.run_tile(TileJob::Corners, tile, count_work);
                let rows = Arc::new(out.values);
                // The pixel bands this band completes: its own (if the next
                // band's first row is in) and the one above (if it waited
                // for this band's first row).
                let ready: Vec<(usize, Vec<DVec3>)> = {
                    let mut t = traced.lock().unwrap_or_else(|e| e.into_inner());
                    t.rows[k] = Some(Arc::clone(&rows));
                    let mut ready = Vec::new();
                    for b in [k.wrapping_sub(1), k] {
                        if b >= bands.len() || t.shown[b] {
                            continue;
                        }
                        let own = t.rows[b].clone();
                        let next = t.rows.get(b + 1).cloned();
                        let corners = match (own, next) {
                            (Some(own), None) if b + 1 == bands.len() => own.to_vec(),
                            (Some(own), Some(Some(next))) => {
                                let mut c = own.to_vec();
                                c.extend_from_slice(&next[..stride as usize]);
                                c
                            }
                            _ => continue,
                        };
                        t.shown[b] = true;
                        ready.push((b, corners));
                    }
                    ready
                };
                for (b, corners) in ready {
                    let (start, end) = bands[b];
                    let last_row = if b + 1 == bands.len() { end - 1 } else { end };
                    let tile = Tile {
                        x: 0,
                        y: start,
                        width: w,
                        height: last_row - start,
                    };
                    let values =
                        shows.then(|| self.pixels_from_corners(&corners, stride, w, tile.height));
                    watch.tile_done(info, &FinishedTile::new(tile, values.as_deref(), encoder));
                }
                Some((rows, out.counts))
            })
            .collect();
        let mut counts = RenderCounts::default();
        let mut corners = Vec::with_capacity((stride * (h + 1)) as usize);
        for result in results {
            let (rows, c) = result?;
            counts += c;
            corners.extend_from_slice(&rows);
        }
        Some((self.pixels_from_corners(&corners, stride, w, h), counts))
    }

    /// Pixels of a `width x height` block from its row-major corner values
    /// (`stride = width + 1` per row).
    fn pixels_from_corners(
        &self,
        corners: &[DVec3],
        stride: u32,
        width: u32,
        height: u32,
    ) -> Vec<DVec3> {
        let mut out = Vec::with_capacity((width * height) as usize);
        for j in 0..height {
            for i in 0..width {
                let mut pixel = PixelSum::default();
                for (di, dj) in [(0, 0), (1, 0), (0, 1), (1, 1)] {
                    pixel.add(corners[((j + dj) * stride + i + di) as usize]);
                }
                out.push(pixel.value(self.settings.view, false));
            }
        }
        out
    }
}
