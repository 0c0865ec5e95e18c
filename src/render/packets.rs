//! Tiles traced in packets: the eye rays of neighbouring pixels (or a
//! pixel's samples, or neighbouring corners) walk the octree together for
//! their closest hits. Each lane is then shaded by the same code, operation
//! for operation, as a single ray: the pixels are the single-ray path's,
//! byte for byte, at every SIMD level. The hits' refraction rays, then
//! their reflection rays, are grouped the same way at every depth (a
//! mirror's or a glass sphere's neighbouring pixels stay coherent).
//! Shadow rays go one by one through the wide walk, which skips the empty
//! part of each cell: in packets they cost more on the SPD scenes
//! (docs/notes/experiments.md). Packets need coherent rays (one sign
//! pattern and axis permutation, none parallel to an axis plane); any
//! other group falls back to single rays, lane by lane.

// Lane loops index several arrays by the same lane number.
#![allow(clippy::needless_range_loop)]

use crate::accel::{ClosestHit, Octree, PacketStack, Primitives};
use crate::math::{Color, DVec3, Ray};
use crate::render::ray_tree::{NoRecord, RayKind, RayRecorder};
use crate::shapes::{PacketHits, PreparedRay, RayPacket, ShapeHit};
use crate::simd::{LaneWork, splat};
use crate::stats::{Counter, NoCounts, RayCounts, RenderCounts};

use super::adaptive::Signature;
use super::integrator::{Secondary, ShadingPoint};
use super::renderer::{Query, Renderer, Scratch};
use super::tile_job::{PixelSum, TileJob, TileOutput, keep_scratch, spare_scratch};
use super::tiles::Tile;

/// Scratch space for a tile's packets: the walk's stack.
pub(super) struct PacketScratch<const N: usize> {
    walk: PacketStack<N>,
}

/// A tile's job, run by [`crate::simd::dispatch`] with the level's lanes.
pub(super) struct PacketTile<'r, 'a> {
    pub renderer: &'r Renderer<'a>,
    pub job: TileJob<'r>,
    pub tile: Tile,
}

impl LaneWork for PacketTile<'_, '_> {
    type Output = TileOutput;

    #[inline(always)]
    fn run<S: pulp::Simd, const N: usize>(self, simd: S) -> TileOutput {
        let mut out = TileOutput {
            values: Vec::with_capacity(self.tile.pixels()),
            signatures: Vec::new(),
            counts: RenderCounts::default(),
        };
        let r = self.renderer;
        let mut scratch = spare_scratch::<Scratch>();
        let mut stack = spare_scratch::<PacketScratch<N>>();
        let mut query = Query {
            counter: &mut NoCounts,
            scratch: &mut scratch,
        };
        r.fill_tile_lanes::<S, _, N>(simd, self.job, self.tile, &mut query, &mut stack, &mut out);
        keep_scratch(stack);
        keep_scratch(scratch);
        out
    }
}

/// A packet's closest hits, as a function of its own per SIMD level: the
/// walk with its shape tests inlined is the largest code glint compiles,
/// and the four places that trace eye rays share it.
struct ClosestWalk<'w, 'r, C, const N: usize> {
    octree: &'r Octree,
    prims: &'w Primitives<'r>,
    packet: &'w RayPacket<N>,
    stack: &'w mut PacketStack<N>,
    counter: &'w mut C,
}

impl<C: Counter, const N: usize> pulp::WithSimd for ClosestWalk<'_, '_, C, N> {
    type Output = PacketHits<N>;

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) -> PacketHits<N> {
        self.octree.closest_packet(
            self.prims,
            self.packet,
            splat(f64::INFINITY),
            self.stack,
            self.counter,
        )
    }
}

/// The secondary rays of a packet's hits, as a function of its own per
/// SIMD level (see [`ClosestWalk`]): inlined into the eye rays' function,
/// its size would slow the scenes without secondary rays.
struct SecondaryWork<'w, 'r, 'a, 'q, C, R, const N: usize> {
    renderer: &'r Renderer<'a>,
    rays: &'w [Ray],
    depth: u32,
    points: &'w [Option<ShadingPoint>; N],
    colors: &'w mut [Color; N],
    query: &'w mut Query<'q, C>,
    stack: &'w mut PacketScratch<N>,
    ray_counts: &'w mut RayCounts,
    recs: &'w mut [R; N],
}

impl<C: Counter, R: RayRecorder, const N: usize> pulp::WithSimd
    for SecondaryWork<'_, '_, '_, '_, C, R, N>
{
    type Output = ();

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, simd: S) {
        self.renderer.secondary_lanes(
            simd,
            self.rays,
            self.depth,
            self.points,
            self.colors,
            self.query,
            self.stack,
            self.ray_counts,
            self.recs,
        );
    }
}

impl<const N: usize> Default for PacketScratch<N> {
    fn default() -> Self {
        Self {
            walk: PacketStack::default(),
        }
    }
}

impl Renderer<'_> {
    /// Whether this render traces packets: a SIMD level with lanes, a
    /// view that does not count each ray's own work (the cost views trace
    /// ray by ray), and no cut-out textures (a ray through a gap goes on
    /// alone).
    pub(super) fn uses_packets(&self) -> bool {
        self.simd.packet_width() > 1 && !self.settings.view.is_cost() && !self.cuts_out
    }

    /// [`Renderer::run_tile`]'s work, in packets of `N` eye rays.
    #[inline(always)]
    fn fill_tile_lanes<S: pulp::Simd, C: Counter, const N: usize>(
        &self,
        simd: S,
        job: TileJob,
        tile: Tile,
        query: &mut Query<C>,
        stack: &mut PacketScratch<N>,
        out: &mut TileOutput,
    ) {
        let width = self.settings.width;
        let view = self.settings.view;
        match job {
            TileJob::Centre { signatures } => {
                for j in tile.y..tile.y + tile.height {
                    let mut i = tile.x;
                    while i < tile.x + tile.width {
                        let n = N.min((tile.x + tile.width - i) as usize);
                        let mut rays = [Ray::new(DVec3::ZERO, DVec3::X); N];
                        for (k, ray) in rays.iter_mut().enumerate() {
                            *ray = self.camera.ray(i + k as u32, j, 0.5, 0.5);
                        }
                        let values = if signatures {
                            let mut recs = [Signature::default(); N];
                            let v = self.sample_lanes(
                                simd,
                                &rays[..n],
                                query,
                                stack,
                                &mut out.counts,
                                &mut recs,
                            );
                            out.signatures.extend(recs[..n].iter().map(|s| s.value));
                            v
                        } else {
                            let mut recs = [NoRecord; N];
                            self.sample_lanes(
                                simd,
                                &rays[..n],
                                query,
                                stack,
                                &mut out.counts,
                                &mut recs,
                            )
                        };
                        for v in &values[..n] {
                            let mut pixel = PixelSum::default();
                            pixel.add(*v);
                            out.values.push(pixel.value(view, true));
                        }
                        i += n as u32;
                    }
                }
            }
            TileJob::Corners => {
                for j in tile.y..tile.y + tile.height {
                    let mut i = tile.x;
                    while i < tile.x + tile.width {
                        let n = N.min((tile.x + tile.width - i) as usize);
                        let mut rays = [Ray::new(DVec3::ZERO, DVec3::X); N];
                        for (k, ray) in rays.iter_mut().enumerate() {
                            *ray = self.camera.ray(i + k as u32, j, 0.0, 0.0);
                        }
                        let mut recs = [NoRecord; N];
                        let values = self.sample_lanes(
                            simd,
                            &rays[..n],
                            query,
                            stack,
                            &mut out.counts,
                            &mut recs,
                        );
                        out.values.extend_from_slice(&values[..n]);
                        i += n as u32;
                    }
                }
            }
            TileJob::Grid | TileJob::Refine { .. } => {
                for (i, j) in tile.coordinates() {
                    let value = match job {
                        TileJob::Refine { first, mask } if !mask[(j * width + i) as usize] => {
                            first[(j * width + i) as usize]
                        }
                        _ => {
                            if matches!(job, TileJob::Refine { .. }) {
                                out.counts.refined_pixels += 1;
                            }
                            self.grid_pixel_lanes(simd, i, j, query, stack, &mut out.counts)
                        }
                    };
                    out.values.push(value);
                }
            }
        }
    }

    /// Pixel `(i, j)` from its full grid of samples, traced `N` at a time
    /// and summed in the grid's order.
    #[inline(always)]
    fn grid_pixel_lanes<S: pulp::Simd, C: Counter, const N: usize>(
        &self,
        simd: S,
        i: u32,
        j: u32,
        query: &mut Query<C>,
        stack: &mut PacketScratch<N>,
        counts: &mut RenderCounts,
    ) -> DVec3 {
        let mut pixel = PixelSum::default();
        for chunk in self.grid.chunks(N) {
            let mut rays = [Ray::new(DVec3::ZERO, DVec3::X); N];
            for (k, ray) in rays.iter_mut().enumerate() {
                let (dx, dy) = chunk[k.min(chunk.len() - 1)];
                *ray = self.camera.ray(i, j, dx, dy);
            }
            let mut recs = [NoRecord; N];
            let values =
                self.sample_lanes(simd, &rays[..chunk.len()], query, stack, counts, &mut recs);
            for v in &values[..chunk.len()] {
                pixel.add(*v);
            }
        }
        pixel.value(self.settings.view, true)
    }

    /// [`Renderer::sample`] for each of `rays` (at most `N`), with their
    /// recorders `recs`.
    #[inline(always)]
    pub(super) fn sample_lanes<S: pulp::Simd, C: Counter, R: RayRecorder, const N: usize>(
        &self,
        simd: S,
        rays: &[Ray],
        query: &mut Query<C>,
        stack: &mut PacketScratch<N>,
        counts: &mut RenderCounts,
        recs: &mut [R; N],
    ) -> [DVec3; N] {
        counts.rays.primary += rays.len() as u64;
        let hits = self.closest_lanes::<S, C, N>(simd, rays, query, stack);
        let mut values = if self.settings.view.traces_shading() {
            self.shade_lanes(simd, rays, &hits, query, stack, &mut counts.rays, recs)
        } else {
            let mut values = [DVec3::ZERO; N];
            for (k, ray) in rays.iter().enumerate() {
                values[k] = self.inspect_hit(ray, hits[k].as_ref(), &mut counts.rays);
            }
            values
        };
        for v in values.iter_mut().take(rays.len()) {
            if !v.is_finite() {
                counts.nonfinite_samples += 1;
                *v = DVec3::ZERO;
            }
        }
        values
    }

    /// Each ray's closest hit: as a packet through the octree where the
    /// rays allow, one by one otherwise.
    #[inline(always)]
    pub(super) fn closest_lanes<S: pulp::Simd, C: Counter, const N: usize>(
        &self,
        simd: S,
        rays: &[Ray],
        query: &mut Query<C>,
        stack: &mut PacketScratch<N>,
    ) -> [Option<ClosestHit>; N] {
        if let Some(octree) = self.walked_octree::<C>()
            && let Some(packet) = RayPacket::<N>::from_rays(rays)
        {
            let prims = self.primitives();
            let best = simd.vectorize(ClosestWalk {
                octree,
                prims: &prims,
                packet: &packet,
                stack: &mut stack.walk,
                counter: &mut *query.counter,
            });
            let mut hits = [None; N];
            for k in 0..rays.len() {
                if best.shape[k] != PacketHits::<N>::NONE {
                    hits[k] = Some(ClosestHit {
                        shape: best.shape[k],
                        hit: ShapeHit {
                            t: best.t[k],
                            b1: best.b1[k],
                            b2: best.b2[k],
                        },
                    });
                }
            }
            return hits;
        }
        let mut hits = [None; N];
        for (k, ray) in rays.iter().enumerate() {
            hits[k] = self.closest(&PreparedRay::new(*ray), query);
        }
        hits
    }

    /// The colours of eye rays that met `hits`: what
    /// [`Renderer::trace`] computes for each at depth 1, with the shadow
    /// rays of the hits towards each light traced together, and the
    /// secondary rays as [`Renderer::secondary_lanes`] traces them.
    // The single-ray shading's arguments, plus the instruction set's token
    // and the packets' scratch.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn shade_lanes<S: pulp::Simd, C: Counter, R: RayRecorder, const N: usize>(
        &self,
        simd: S,
        rays: &[Ray],
        hits: &[Option<ClosestHit>; N],
        query: &mut Query<C>,
        stack: &mut PacketScratch<N>,
        ray_counts: &mut RayCounts,
        recs: &mut [R; N],
    ) -> [Color; N] {
        ray_counts.primary_hits += hits[..rays.len()].iter().flatten().count() as u64;
        let mut colors = [Color::ZERO; N];
        let mut points: [Option<ShadingPoint>; N] = [const { None }; N];
        self.direct_lanes(
            rays,
            hits,
            &mut points,
            &mut colors,
            query,
            ray_counts,
            recs,
        );
        if 1 < self.settings.max_depth {
            simd.vectorize(SecondaryWork {
                renderer: self,
                rays,
                depth: 1,
                points: &points,
                colors: &mut colors,
                query,
                stack,
                ray_counts,
                recs,
            });
        } else {
            for k in 0..rays.len() {
                if points[k].is_some() {
                    recs[k].local(colors[k]);
                    recs[k].finish(colors[k]);
                }
            }
        }
        colors
    }

    /// The shading points of `rays`' hits into `points` (left `None`
    /// where a ray has none) and their local colours into `colors`:
    /// ambient, then each light's term in turn ([`Renderer::direct_light`]
    /// for each ray). A ray without a hit gets the background, told to its
    /// recorder as final.
    // The single-ray shading's arguments, in lanes.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn direct_lanes<C: Counter, R: RayRecorder, const N: usize>(
        &self,
        rays: &[Ray],
        hits: &[Option<ClosestHit>; N],
        points: &mut [Option<ShadingPoint>; N],
        colors: &mut [Color; N],
        query: &mut Query<C>,
        ray_counts: &mut RayCounts,
        recs: &mut [R; N],
    ) {
        let n = rays.len();
        for k in 0..n {
            match &hits[k] {
                None => {
                    colors[k] = self.background;
                    recs[k].local(colors[k]);
                    recs[k].finish(colors[k]);
                }
                Some(hit) => {
                    let at = self.shading_point_at(&rays[k], hit, &mut recs[k]);
                    colors[k] = self.ambient(&at);
                    points[k] = Some(at);
                }
            }
        }
        // Loops, not `std::array::from_fn`: its closures, once too large to
        // inline, are compiled apart from this function's SIMD level and
        // run without its vector instructions.
        let mut origins = [DVec3::ZERO; N];
        let mut shapes = [0; N];
        for k in 0..n {
            if let Some(at) = &points[k] {
                origins[k] = self.shadow_origin(at);
                shapes[k] = at.shape;
            }
        }
        for (index, light) in self.scene.lights.iter().enumerate() {
            let mut toward: [Option<(DVec3, f64, f64)>; N] = [None; N];
            for k in 0..n {
                if let Some(at) = &points[k] {
                    toward[k] = self.toward_light(at, origins[k], light);
                }
            }
            let passes = if self.settings.shadows {
                self.transmittance_lanes(&origins, &shapes, &toward, index, query, ray_counts)
            } else {
                [1.0; N]
            };
            for k in 0..n {
                let Some(at) = &points[k] else { continue };
                match toward[k] {
                    None => self.faces_away(index, &mut recs[k]),
                    Some((l, _, n_dot_l)) => {
                        if let Some(direct) = self.light_through(
                            &rays[k],
                            at,
                            index,
                            l,
                            n_dot_l,
                            passes[k],
                            &mut recs[k],
                        ) {
                            colors[k] += direct;
                        }
                    }
                }
            }
        }
    }

    /// The secondary rays of the hits `points` of rays at `depth` (lane
    /// k's seen along `rays[k]`), added to `colors` as
    /// [`Renderer::secondary_rays`] adds them, byte for byte: the
    /// refraction rays of all lanes, then their reflection rays, go as a
    /// packet where they are coherent (a mirror's or a glass sphere's
    /// neighbouring pixels) and the shadow rays of their hits towards each
    /// light too, and so on down to the scene's depth. Each ray's own
    /// arithmetic, and the order in which a hit adds what its rays see, are
    /// the single-ray path's.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    fn secondary_lanes<S: pulp::Simd, C: Counter, R: RayRecorder, const N: usize>(
        &self,
        simd: S,
        rays: &[Ray],
        depth: u32,
        points: &[Option<ShadingPoint>; N],
        colors: &mut [Color; N],
        query: &mut Query<C>,
        stack: &mut PacketScratch<N>,
        ray_counts: &mut RayCounts,
        recs: &mut [R; N],
    ) {
        let n = rays.len();
        let mut secondary: [[Option<Secondary>; 2]; N] = [[None; 2]; N];
        for k in 0..n {
            if let Some(at) = &points[k] {
                recs[k].local(colors[k]);
                secondary[k] = self.secondary_of(&rays[k], at, ray_counts);
            }
        }
        // What each lane's rays saw, and their recorders, by kind.
        let mut seen = [[Color::ZERO; 2]; N];
        let mut child_recs: [[Option<R>; 2]; N] = std::array::from_fn(|_| [None, None]);
        for kind in 0..2 {
            let mut lanes = [0usize; N];
            let mut child_rays = [Ray::new(DVec3::ZERO, DVec3::X); N];
            let mut m = 0;
            for k in 0..n {
                if let Some(s) = &secondary[k][kind] {
                    lanes[m] = k;
                    child_rays[m] = s.ray;
                    m += 1;
                }
            }
            if m == 0 {
                continue;
            }
            let mut crecs: [R; N] = std::array::from_fn(|j| {
                let k = lanes[j.min(m - 1)];
                let s = secondary[k][kind].as_ref().map_or(
                    (RayKind::Reflection, Ray::new(DVec3::ZERO, DVec3::X), 0.0),
                    |s| (s.kind, s.ray, s.weight),
                );
                recs[k].child(s.0, &s.1, depth + 1, s.2)
            });
            let child_rays = &child_rays[..m];
            let hits = self.closest_lanes::<S, C, N>(simd, child_rays, query, stack);
            let mut child_colors = [Color::ZERO; N];
            let mut child_points: [Option<ShadingPoint>; N] = [const { None }; N];
            self.direct_lanes(
                child_rays,
                &hits,
                &mut child_points,
                &mut child_colors,
                query,
                ray_counts,
                &mut crecs,
            );
            if depth + 1 < self.settings.max_depth {
                // The next level the same way, in a call of its own (the
                // depth is at most 64: the stack holds 64 such frames).
                simd.vectorize(SecondaryWork {
                    renderer: self,
                    rays: child_rays,
                    depth: depth + 1,
                    points: &child_points,
                    colors: &mut child_colors,
                    query: &mut *query,
                    stack: &mut *stack,
                    ray_counts: &mut *ray_counts,
                    recs: &mut crecs,
                });
            } else {
                for j in 0..m {
                    if child_points[j].is_some() {
                        crecs[j].local(child_colors[j]);
                        crecs[j].finish(child_colors[j]);
                    }
                }
            }
            for (j, crec) in crecs.into_iter().enumerate().take(m) {
                seen[lanes[j]][kind] = child_colors[j];
                child_recs[lanes[j]][kind] = Some(crec);
            }
        }
        for k in 0..n {
            if points[k].is_none() {
                continue;
            }
            for kind in 0..2 {
                if let (Some(s), Some(crec)) = (&secondary[k][kind], child_recs[k][kind].take()) {
                    recs[k].attach(crec, seen[k][kind]);
                    colors[k] += s.weight * seen[k][kind];
                }
            }
            recs[k].finish(colors[k]);
        }
    }

    /// What each shadow ray towards one light lets through (`toward`: its
    /// direction and length, `None` where none is cast), each traced on its
    /// own by the wide walk: in packets, shadow rays cost more than single
    /// rays on the SPD scenes (docs/notes/experiments.md).
    #[inline(always)]
    fn transmittance_lanes<C: Counter, const N: usize>(
        &self,
        origins: &[DVec3; N],
        shapes: &[u32; N],
        toward: &[Option<(DVec3, f64, f64)>; N],
        light: usize,
        query: &mut Query<C>,
        ray_counts: &mut RayCounts,
    ) -> [f64; N] {
        let mut passes = [1.0; N];
        for k in 0..N {
            if let Some((l, distance, _)) = toward[k] {
                ray_counts.shadow += 1;
                let ray = PreparedRay::new(Ray::new(origins[k], l));
                let left = self.left_behind(shapes[k], origins[k], l);
                passes[k] = self.transmittance(&ray, distance, light, left, query);
            }
        }
        passes
    }
}
