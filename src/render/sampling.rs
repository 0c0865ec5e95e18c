//! From eye rays to pixels: a sample is the view's value for one eye ray
//! (a shaded colour, a normal, a distance or the work it took), a pixel
//! the mean of its samples; a tile job fills one tile of a pass, in
//! packets of rays where the scene allows it and one ray at a time elsewhere.

use crate::math::{DVec3, Ray};
use crate::render::ray_tree::{NoRecord, RayRecorder};
use crate::settings::ViewMode;
use crate::shapes::PreparedRay;
use crate::stats::{Counter, NoCounts, RayCounts, RenderCounts, WorkCounts};

use super::adaptive::Signature;
use super::renderer::{Query, Renderer, Scratch};
use super::tile_job::{PixelSum, TileJob, TileOutput, keep_scratch, spare_scratch};
use super::tiles::Tile;

impl Renderer<'_> {
    /// Runs `job` over `tile`, counting Havran's work measures when
    /// `count_work` (tracing is generic over the counter, so the other
    /// case costs nothing). The tile's rays share one scratch space.
    ///
    /// Counted tiles trace single rays: a counting instance of the packet
    /// kernels would double the largest code glint compiles (the library's
    /// release build took 110 s of CPU with it, 75 s without), and the
    /// pixels are the same bytes either way.
    pub(super) fn run_tile(&self, job: TileJob, tile: Tile, count_work: bool) -> TileOutput {
        if self.uses_packets() && !count_work {
            let packets = super::packets::PacketTile {
                renderer: self,
                job,
                tile,
            };
            if let Some(out) = crate::simd::dispatch(self.simd, packets) {
                return out;
            }
        }
        let mut out = TileOutput {
            values: Vec::with_capacity(tile.pixels()),
            signatures: Vec::new(),
            counts: RenderCounts::default(),
        };
        let mut scratch = spare_scratch::<Scratch>();
        self.fill_tile_counting(job, tile, count_work, &mut scratch, &mut out);
        keep_scratch(scratch);
        out
    }

    fn fill_tile_counting(
        &self,
        job: TileJob,
        tile: Tile,
        count_work: bool,
        scratch: &mut Scratch,
        out: &mut TileOutput,
    ) {
        if count_work {
            let mut work = WorkCounts::default();
            let mut query = Query {
                counter: &mut work,
                scratch,
            };
            self.fill_tile(job, tile, &mut query, out);
            out.counts.work = work;
        } else {
            let mut query = Query {
                counter: &mut NoCounts,
                scratch,
            };
            self.fill_tile(job, tile, &mut query, out);
        }
    }

    fn fill_tile<C: Counter>(
        &self,
        job: TileJob,
        tile: Tile,
        query: &mut Query<C>,
        out: &mut TileOutput,
    ) {
        let width = self.settings.width;
        for (i, j) in tile.coordinates() {
            let value = match job {
                TileJob::Centre { signatures } => {
                    let ray = self.camera.ray(i, j, 0.5, 0.5);
                    let mut pixel = PixelSum::default();
                    if signatures {
                        let mut signature = Signature::default();
                        pixel.add(self.sample_recorded(
                            &ray,
                            query,
                            &mut out.counts,
                            &mut signature,
                        ));
                        out.signatures.push(signature.value);
                    } else {
                        pixel.add(self.sample(&ray, query, &mut out.counts));
                    }
                    pixel.value(self.settings.view, true)
                }
                TileJob::Grid => self.grid_pixel(i, j, query, &mut out.counts),
                TileJob::Corners => {
                    self.sample(&self.camera.ray(i, j, 0.0, 0.0), query, &mut out.counts)
                }
                TileJob::Refine { first, mask } => {
                    let at = (j * width + i) as usize;
                    if mask[at] {
                        out.counts.refined_pixels += 1;
                        self.grid_pixel(i, j, query, &mut out.counts)
                    } else {
                        first[at]
                    }
                }
            };
            out.values.push(value);
        }
    }

    /// Value of pixel `(i, j)` from its full grid of samples.
    fn grid_pixel<C: Counter>(
        &self,
        i: u32,
        j: u32,
        query: &mut Query<C>,
        counts: &mut RenderCounts,
    ) -> DVec3 {
        let mut pixel = PixelSum::default();
        for &(dx, dy) in &self.grid {
            pixel.add(self.sample(&self.camera.ray(i, j, dx, dy), query, counts));
        }
        pixel.value(self.settings.view, true)
    }

    /// The view's value for one eye ray (shaded colour, normal, distance
    /// or work), with its rays and work counted; non-finite values are
    /// counted and shown black.
    pub(super) fn sample<C: Counter>(
        &self,
        ray: &Ray,
        query: &mut Query<C>,
        counts: &mut RenderCounts,
    ) -> DVec3 {
        self.sample_recorded(ray, query, counts, &mut NoRecord)
    }

    /// [`Renderer::sample`], telling `rec` what the ray met.
    pub(super) fn sample_recorded<C: Counter, R: RayRecorder>(
        &self,
        ray: &Ray,
        query: &mut Query<C>,
        counts: &mut RenderCounts,
        rec: &mut R,
    ) -> DVec3 {
        counts.rays.primary += 1;
        let view = self.settings.view;
        let value = if view.is_cost() {
            // Count this ray's work on its own, then pass it on.
            let mut work = WorkCounts::default();
            let mut own = Query {
                counter: &mut work,
                scratch: &mut *query.scratch,
            };
            self.trace(ray, 1, &mut own, &mut counts.rays, rec);
            query.counter.add_work(&work);
            DVec3::new(
                work.intersection_tests as f64,
                work.traversal_steps as f64,
                work.leaves_visited as f64,
            )
        } else if view.traces_shading() {
            self.trace(ray, 1, query, &mut counts.rays, rec)
        } else {
            self.inspect(ray, query, &mut counts.rays)
        };
        if value.is_finite() {
            value
        } else {
            counts.nonfinite_samples += 1;
            DVec3::ZERO
        }
    }

    /// One sample of a non-shaded view for the eye ray `ray`.
    fn inspect<C: Counter>(&self, ray: &Ray, query: &mut Query<C>, rays: &mut RayCounts) -> DVec3 {
        let hit = self.closest(&PreparedRay::new(*ray), query);
        self.inspect_hit(ray, hit.as_ref(), rays)
    }

    /// The non-shaded view's value for the eye ray `ray` that met `hit`.
    #[inline(always)]
    pub(super) fn inspect_hit(
        &self,
        ray: &Ray,
        hit: Option<&crate::accel::ClosestHit>,
        rays: &mut RayCounts,
    ) -> DVec3 {
        let Some(hit) = hit else {
            return DVec3::ZERO;
        };
        rays.primary_hits += 1;
        match self.settings.view {
            ViewMode::Normals => {
                let s = self.scene.shapes[hit.shape as usize].surface(
                    ray,
                    &hit.hit,
                    &self.scene.vertex_normals,
                );
                let n = s.geometric_normal;
                let facing = if n.dot(ray.dir) > 0.0 { -n } else { n };
                (facing + DVec3::ONE) * 0.5
            }
            _ => DVec3::new(hit.hit.t, 1.0, 0.0),
        }
    }
}
