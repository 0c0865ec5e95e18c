//! The Whitted integrator: a scene and its octree rendered into a frame,
//! tile by tile, with the per-view sampling (shaded, normals, depth, cost)
//! and the SPD protocol's corner rays.

use std::sync::atomic::{AtomicU64, Ordering};

use rayon::prelude::*;

use crate::accel::{
    ClosestHit, Octree, Primitives, ShadowCrossings, closest_brute_force, occlusion_brute_force,
};
use crate::adaptive::{Signature, refine_mask};
use crate::camera::{Camera, CameraError, CameraSpec, sample_offsets};
use crate::frame::Frame;
use crate::material::Material;
use crate::math::{Color, DVec3, Ray, offset_ray_origin, reflect, refract};
use crate::ray_tree::{HitRecord, NoRecord, RayKind, RayNode, RayRecorder, ShadowRecord};
use crate::scene::Scene;
use crate::settings::{AntiAliasing, Protocol, RenderSettings, Sides, ViewMode};
use crate::shapes::PreparedRay;
use crate::stats::{Counter, NoCounts, RayCounts, WorkCounts};
use crate::tiles::{Tile, TileCounts, assemble_tiles, place_tile, tiles};

use crate::scene::{MAX_IMAGE_SIDE, MAX_PIXELS};

#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    #[error(transparent)]
    Camera(#[from] CameraError),
    #[error("samples must be a square grid of 1 to 256 rays (1, 4, 9, 16, ...), got {0}")]
    Samples(u32),
    #[error("max depth must be at least 1, got {0}")]
    MaxDepth(u32),
    #[error(
        "an image of {0}x{1} pixels is too large: glint renders at most {max} pixels ({side} on a side)",
        max = MAX_PIXELS,
        side = MAX_IMAGE_SIDE
    )]
    TooLarge(u32, u32),
    #[error(
        "a {width}x{height} render needs about {need} MiB of memory, more than the {limit} MiB \
         this machine has available: choose a smaller image",
        need = needed / (1 << 20),
        limit = available / (1 << 20)
    )]
    OutOfMemory {
        width: u32,
        height: u32,
        needed: u64,
        available: u64,
    },
}

thread_local! {
    /// A shadow ray's crossings, kept per thread: the array is set up once,
    /// not for every ray.
    static SHADOW_CROSSINGS: std::cell::RefCell<ShadowCrossings> =
        std::cell::RefCell::new(ShadowCrossings::default());
}

/// Crossings of one material closer than this, relative to the scene's
/// magnitude, are one surface: far above the rounding of hit distances,
/// far below any thickness a scene models.
const SAME_SURFACE_RELATIVE: f64 = 1e-9;

/// A scene prepared for rendering with fixed settings.
pub struct Renderer<'a> {
    scene: &'a Scene,
    octree: &'a Octree,
    settings: RenderSettings,
    camera: Camera,
    offsets: Vec<(f64, f64)>,
    is_transparent: Vec<bool>,
    /// Per shape: seen from outside only ([`Sides::One`]); empty otherwise.
    one_sided: Vec<bool>,
    /// The scene's materials and background as this render shades them
    /// (decoded into linear light for a linear render of display values).
    materials: Vec<Material>,
    background: Color,
    /// Magnitude of the scene's surfaces and the eye: the floor of ray offsets.
    floor_scale: f64,
}

impl<'a> Renderer<'a> {
    pub fn new(
        scene: &'a Scene,
        octree: &'a Octree,
        settings: RenderSettings,
    ) -> Result<Self, RenderError> {
        Self::with_camera(scene, octree, settings, &scene.camera)
    }

    /// Like [`Renderer::new`], seen from `camera` instead of the scene's own
    /// (the viewer moves the camera without touching the scene).
    pub fn with_camera(
        scene: &'a Scene,
        octree: &'a Octree,
        settings: RenderSettings,
        camera: &CameraSpec,
    ) -> Result<Self, RenderError> {
        // Scene files and the command line offer 1 and 16; the study also
        // measures the other square grids (4 = 2x2, 64 = 8x8, 256 = 16x16).
        let side = (settings.samples as f64).sqrt().round() as u32;
        if settings.samples == 0 || side * side != settings.samples || side > 16 {
            return Err(RenderError::Samples(settings.samples));
        }
        if settings.max_depth == 0 {
            return Err(RenderError::MaxDepth(settings.max_depth));
        }
        if settings.width as u64 * settings.height as u64 > MAX_PIXELS
            || settings.width.max(settings.height) > MAX_IMAGE_SIDE
        {
            return Err(RenderError::TooLarge(settings.width, settings.height));
        }
        let camera = Camera::new(camera, settings.width, settings.height)?;
        let is_transparent: Vec<bool> = scene
            .shape_materials
            .iter()
            .map(|&m| scene.materials[m as usize].transparency > 0.0)
            .collect();
        let one_sided = match settings.sides {
            Sides::Two => Vec::new(),
            Sides::One => scene
                .shapes
                .iter()
                .zip(&is_transparent)
                .map(|(shape, &transparent)| !transparent && !shape.has_vertex_normals())
                .collect(),
        };
        let shade = |c| settings.colors.shading_color(scene.color_values, c);
        let materials = scene
            .materials
            .iter()
            .map(|m| Material {
                color: shade(m.color),
                ..m.clone()
            })
            .collect();
        Ok(Self {
            scene,
            octree,
            settings,
            camera,
            offsets: sample_offsets(settings.samples),
            is_transparent,
            one_sided,
            materials,
            background: shade(scene.image.background),
            floor_scale: scene
                .geometry_bounds()
                .grow(camera.eye)
                .max_abs()
                .max(f64::MIN_POSITIVE),
        })
    }

    pub fn settings(&self) -> &RenderSettings {
        &self.settings
    }

    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    fn primitives(&self) -> Primitives<'_> {
        Primitives {
            shapes: &self.scene.shapes,
            one_sided: &self.one_sided,
            transparent: &self.is_transparent,
        }
    }

    fn closest<C: Counter>(&self, ray: &PreparedRay, counter: &mut C) -> Option<ClosestHit> {
        let prims = self.primitives();
        if self.settings.use_octree {
            self.octree.closest(&prims, ray, f64::INFINITY, counter)
        } else {
            closest_brute_force(&prims, ray, f64::INFINITY, counter)
        }
    }

    /// Fraction of light passing along the shadow ray to a light `distance`
    /// away. Every surface crossed multiplies it by its material's
    /// transparency (entering and leaving a glass sphere or a closed glass
    /// mesh: T twice), whatever kind of shape it is; crossings of the same
    /// material at the same place count once (coincident triangles, a ray
    /// through a mesh's shared edge, two glass bodies touching: no
    /// interface), and any opaque surface blocks the light.
    fn transmittance<C: Counter>(&self, ray: &PreparedRay, distance: f64, counter: &mut C) -> f64 {
        SHADOW_CROSSINGS.with_borrow_mut(|found| {
            let prims = self.primitives();
            if self.settings.use_octree {
                self.octree.occlusion(&prims, ray, distance, found, counter);
            } else {
                occlusion_brute_force(&prims, ray, distance, found, counter);
            }
            self.pass_through(found)
        })
    }

    /// The light a shadow ray's crossings let through.
    fn pass_through(&self, found: &ShadowCrossings) -> f64 {
        if found.is_blocked() {
            return 0.0;
        }
        // Crossings come sorted by distance, so the product is the same
        // whichever order they were found in.
        let same_place = SAME_SURFACE_RELATIVE * self.floor_scale;
        let mut pass = 1.0;
        let mut previous: Option<(f64, u32)> = None;
        for &(t, shape) in found.transparent() {
            let material = self.scene.shape_materials[shape as usize];
            let repeat = previous.is_some_and(|(pt, pm)| pm == material && t - pt <= same_place);
            if !repeat {
                pass *= self.materials[material as usize].transparency;
            }
            previous = Some((t, material));
        }
        pass
    }

    /// Colour seen along `ray`, which is at recursion `depth` (eye ray = 1).
    fn trace<C: Counter, R: RayRecorder>(
        &self,
        ray: &Ray,
        depth: u32,
        counter: &mut C,
        rays: &mut RayCounts,
        rec: &mut R,
    ) -> Color {
        let prepared = PreparedRay::new(*ray);
        let Some(hit) = self.closest(&prepared, counter) else {
            let background = self.background;
            rec.local(background);
            rec.finish(background);
            return background;
        };
        if depth == 1 {
            rays.primary_hits += 1;
        }
        let scene = self.scene;
        let shape = &scene.shapes[hit.shape as usize];
        let surface = shape.surface(ray, &hit.hit, &scene.vertex_normals);
        let material = &self.materials[scene.shape_materials[hit.shape as usize] as usize];
        let entering = ray.dir.dot(surface.geometric_normal) < 0.0;
        // Normals facing the incoming ray: glint's surfaces are two-sided.
        let facing = if entering {
            surface.geometric_normal
        } else {
            -surface.geometric_normal
        };
        let mut n = if surface.shading_normal.dot(facing) < 0.0 {
            -surface.shading_normal
        } else {
            surface.shading_normal
        };
        if !n.is_finite() {
            n = facing;
        }
        let view = -ray.dir;
        let p = surface.point;
        rec.material(scene.shape_materials[hit.shape as usize]);
        rec.hit(|| HitRecord {
            object: hit.shape,
            kind: shape.kind_name(),
            material: material.name.clone(),
            distance: hit.hit.t,
            point: p.to_array(),
            normal: n.to_array(),
            entering,
        });

        let mut color = material.ka * scene.image.ambient * material.color;
        let shadow_origin = offset_ray_origin(p, facing, self.floor_scale);
        for (index, light) in scene.lights.iter().enumerate() {
            let verdict = |verdict, transmittance, color: Color| ShadowRecord {
                light: index,
                verdict,
                transmittance,
                color: color.to_array(),
            };
            let to_light = light.position - shadow_origin;
            let distance = to_light.length();
            if !(distance > 0.0) {
                rec.light(index, false);
                rec.shadow(|| verdict("faces-away", 0.0, Color::ZERO));
                continue;
            }
            let l = to_light / distance;
            let n_dot_l = n.dot(l);
            // A surface facing away from the light gets neither light nor a
            // shadow ray. glint asks both normals: an interpolated normal can
            // face the light where the surface itself does not. The SPD
            // asks the shading normal alone (its published shadow counts on
            // the smooth-shaded teapot match only that way).
            let faces_away = match self.settings.protocol {
                Protocol::Glint => n_dot_l <= 0.0 || facing.dot(l) <= 0.0,
                Protocol::Spd => n_dot_l <= 0.0,
            };
            if faces_away {
                rec.light(index, false);
                rec.shadow(|| verdict("faces-away", 0.0, Color::ZERO));
                continue;
            }
            let pass = if self.settings.shadows {
                rays.shadow += 1;
                let shadow = PreparedRay::new(Ray::new(shadow_origin, l));
                self.transmittance(&shadow, distance, counter)
            } else {
                1.0
            };
            rec.light(index, pass > 0.0);
            if pass == 0.0 {
                rec.shadow(|| verdict("blocked", 0.0, Color::ZERO));
                continue;
            }
            let diffuse = material.kd * n_dot_l * material.color;
            let r = 2.0 * n_dot_l * n - l;
            let specular = material.ks * r.dot(view).max(0.0).powf(material.shininess);
            let direct = (diffuse + DVec3::splat(specular)) * light.color * pass;
            rec.shadow(|| {
                let name = if pass < 1.0 { "attenuated" } else { "lit" };
                verdict(name, pass, direct)
            });
            color += direct;
        }
        rec.local(color);

        if depth < self.settings.max_depth {
            let mut reflect_weight = material.reflectivity;
            if material.transparency > 0.0 {
                let eta = if entering {
                    1.0 / material.ior
                } else {
                    material.ior
                };
                match refract(ray.dir, n, eta) {
                    Some(dir) => {
                        rays.refraction += 1;
                        let origin = offset_ray_origin(p, -facing, self.floor_scale);
                        let child_ray = Ray::new(origin, dir);
                        let weight = material.transparency;
                        let mut child =
                            rec.child(RayKind::Refraction, &child_ray, depth + 1, weight);
                        let seen = self.trace(&child_ray, depth + 1, counter, rays, &mut child);
                        rec.attach(child, seen);
                        color += weight * seen;
                    }
                    // Total internal reflection: the transmitted share is reflected.
                    None => {
                        rays.total_internal_reflections += 1;
                        reflect_weight += material.transparency;
                    }
                }
            }
            // The SPD counts a reflection ray from every reflective or
            // transmitting surface, even one whose weight is zero.
            let spawn_reflection = match self.settings.protocol {
                Protocol::Glint => reflect_weight > 0.0,
                Protocol::Spd => material.reflectivity > 0.0 || material.transparency > 0.0,
            };
            if spawn_reflection {
                rays.reflection += 1;
                let mut dir = reflect(ray.dir, n);
                // An interpolated normal can send the mirror ray below the
                // surface; fall back to the geometric mirror direction.
                if dir.dot(facing) <= 0.0 {
                    dir = reflect(ray.dir, facing);
                }
                let origin = offset_ray_origin(p, facing, self.floor_scale);
                let child_ray = Ray::new(origin, dir.normalize());
                let mut child =
                    rec.child(RayKind::Reflection, &child_ray, depth + 1, reflect_weight);
                let seen = self.trace(&child_ray, depth + 1, counter, rays, &mut child);
                rec.attach(child, seen);
                color += reflect_weight * seen;
            }
        }
        rec.finish(color);
        color
    }

    /// The tree of rays the centre ray of pixel `(i, j)` spawns (under the
    /// SPD protocol, its top-left corner ray), with what each hit and
    /// contributed. Its root colour is the pixel's value at 1 sample per
    /// pixel in the shaded view.
    pub fn ray_tree(&self, i: u32, j: u32) -> RayNode {
        // The SPD protocol has no centre ray: its top-left corner ray.
        let offset = if self.settings.corner_rays() {
            0.0
        } else {
            0.5
        };
        let ray = self.camera.ray(i, j, offset, offset);
        let mut root = RayNode::new(RayKind::Eye, &ray, 1, 1.0);
        let mut rays = RayCounts::default();
        self.trace(&ray, 1, &mut NoCounts, &mut rays, &mut root);
        root
    }

    /// One sample of a non-shaded view for the eye ray `ray`.
    fn inspect<C: Counter>(&self, ray: &Ray, counter: &mut C, rays: &mut RayCounts) -> DVec3 {
        let prepared = PreparedRay::new(*ray);
        let Some(hit) = self.closest(&prepared, counter) else {
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

    /// The view's value for one eye ray (shaded colour, normal, distance
    /// or work), with its rays and work counted; non-finite values are
    /// counted and shown black.
    fn sample<C: Counter>(&self, ray: &Ray, counter: &mut C, counts: &mut TileCounts) -> DVec3 {
        self.sample_recorded(ray, counter, counts, &mut NoRecord)
    }

    /// [`Renderer::sample`], telling `rec` what the ray met.
    fn sample_recorded<C: Counter, R: RayRecorder>(
        &self,
        ray: &Ray,
        counter: &mut C,
        counts: &mut TileCounts,
        rec: &mut R,
    ) -> DVec3 {
        counts.rays.primary += 1;
        let view = self.settings.view;
        let value = if view.is_cost() {
            // Count this ray's work on its own, then pass it on.
            let mut work = WorkCounts::default();
            self.trace(ray, 1, &mut work, &mut counts.rays, rec);
            counter.add_work(&work);
            DVec3::new(
                work.intersection_tests as f64,
                work.traversal_steps as f64,
                work.leaves_visited as f64,
            )
        } else if view.traces_shading() {
            self.trace(ray, 1, counter, &mut counts.rays, rec)
        } else {
            self.inspect(ray, counter, &mut counts.rays)
        };
        if value.is_finite() {
            value
        } else {
            counts.nonfinite_samples += 1;
            DVec3::ZERO
        }
    }

    /// Value of pixel `(i, j)` from its grid of samples.
    pub fn pixel<C: Counter>(
        &self,
        i: u32,
        j: u32,
        counter: &mut C,
        counts: &mut TileCounts,
    ) -> DVec3 {
        let mut pixel = PixelSum::default();
        for &(dx, dy) in &self.offsets {
            pixel.add(self.sample(&self.camera.ray(i, j, dx, dy), counter, counts));
        }
        pixel.value(self.settings.view, true)
    }

    /// Adaptive anti-aliasing's first pass over a tile: each pixel's centre
    /// sample and the signature of what it met.
    pub fn first_pass_tile(
        &self,
        tile: Tile,
        count_work: bool,
    ) -> (Vec<DVec3>, Vec<u64>, TileCounts) {
        let mut counts = TileCounts::default();
        let mut work = WorkCounts::default();
        let n = (tile.width * tile.height) as usize;
        let (mut values, mut signatures) = (Vec::with_capacity(n), Vec::with_capacity(n));
        for j in tile.y..tile.y + tile.height {
            for i in tile.x..tile.x + tile.width {
                let ray = self.camera.ray(i, j, 0.5, 0.5);
                let mut signature = Signature::default();
                let mut pixel = PixelSum::default();
                let value = if count_work {
                    self.sample_recorded(&ray, &mut work, &mut counts, &mut signature)
                } else {
                    self.sample_recorded(&ray, &mut NoCounts, &mut counts, &mut signature)
                };
                pixel.add(value);
                values.push(pixel.value(self.settings.view, true));
                signatures.push(signature.value);
            }
        }
        counts.work = work;
        (values, signatures, counts)
    }

    /// Adaptive anti-aliasing's second pass over a tile: the full grid for
    /// the pixels `mask` marks (frame-sized, row-major), the first pass's
    /// value (`first`, frame-sized) for the others.
    pub fn refine_tile(
        &self,
        tile: Tile,
        first: &[DVec3],
        mask: &[bool],
        count_work: bool,
    ) -> (Vec<DVec3>, TileCounts) {
        let mut counts = TileCounts::default();
        let mut work = WorkCounts::default();
        let mut out = Vec::with_capacity((tile.width * tile.height) as usize);
        let w = self.settings.width;
        for j in tile.y..tile.y + tile.height {
            for i in tile.x..tile.x + tile.width {
                let at = (j * w + i) as usize;
                if !mask[at] {
                    out.push(first[at]);
                    continue;
                }
                counts.refined_pixels += 1;
                out.push(if count_work {
                    self.pixel(i, j, &mut work, &mut counts)
                } else {
                    self.pixel(i, j, &mut NoCounts, &mut counts)
                });
            }
        }
        counts.work = work;
        (out, counts)
    }

    /// Both passes of adaptive anti-aliasing over the whole frame.
    fn render_adaptive(
        &self,
        count_work: bool,
        progress: Option<&(dyn Fn(u64, u64) + Sync)>,
    ) -> (Frame, TileCounts) {
        let (w, h) = (self.settings.width, self.settings.height);
        let all = tiles(w, h);
        let total = 2 * all.len() as u64;
        let done = AtomicU64::new(0);
        let tick = || {
            let n = done.fetch_add(1, Ordering::Relaxed) + 1;
            if let Some(p) = progress {
                p(n, total);
            }
        };
        let first: Vec<(Vec<DVec3>, Vec<u64>, TileCounts)> = all
            .par_iter()
            .map(|&t| {
                let r = self.first_pass_tile(t, count_work);
                tick();
                r
            })
            .collect();
        let mut signatures = vec![0u64; (w * h) as usize];
        for (tile, (_, sig, _)) in all.iter().zip(&first) {
            place_tile(&mut signatures, w, tile, sig);
        }
        let (first_frame, mut counts) = assemble_tiles(
            &self.settings,
            &all,
            first.into_iter().map(|(values, _, c)| (values, c)),
        );
        let mask = refine_mask(&first_frame.to_rgb8(), &signatures, w, h);
        let second: Vec<(Vec<DVec3>, TileCounts)> = all
            .par_iter()
            .map(|&t| {
                let r = self.refine_tile(t, &first_frame.pixels, &mask, count_work);
                tick();
                r
            })
            .collect();
        let (frame, more) = assemble_tiles(&self.settings, &all, second);
        counts += more;
        (frame, counts)
    }

    /// Renders one tile into a row-major buffer of `tile.width * tile.height`.
    pub fn render_tile(&self, tile: Tile, count_work: bool) -> (Vec<DVec3>, TileCounts) {
        let mut counts = TileCounts::default();
        let out = if count_work {
            let mut work = WorkCounts::default();
            let out = self.tile_pixels(tile, &mut work, &mut counts);
            counts.work = work;
            out
        } else {
            self.tile_pixels(tile, &mut NoCounts, &mut counts)
        };
        (out, counts)
    }

    fn tile_pixels<C: Counter>(
        &self,
        tile: Tile,
        counter: &mut C,
        counts: &mut TileCounts,
    ) -> Vec<DVec3> {
        if self.settings.corner_rays() {
            return self.tile_from_corners(tile, counter, counts);
        }
        let mut out = Vec::with_capacity((tile.width * tile.height) as usize);
        for j in tile.y..tile.y + tile.height {
            for i in tile.x..tile.x + tile.width {
                out.push(self.pixel(i, j, counter, counts));
            }
        }
        out
    }

    /// The SPD's corner rays for a tile: its `(w + 1) x (h + 1)` corners,
    /// each pixel the mean of its four. A corner on the tile's right or
    /// bottom edge belongs to the next tile (unless it is the image's own
    /// edge) and is traced again here without being counted, so the counts
    /// of all tiles add up to exactly `(width + 1) x (height + 1)` eye rays.
    fn tile_from_corners<C: Counter>(
        &self,
        tile: Tile,
        counter: &mut C,
        counts: &mut TileCounts,
    ) -> Vec<DVec3> {
        let (cw, ch) = (tile.width + 1, tile.height + 1);
        let (w, h) = (self.settings.width, self.settings.height);
        let mut corners = Vec::with_capacity((cw * ch) as usize);
        for cj in tile.y..=tile.y + tile.height {
            for ci in tile.x..=tile.x + tile.width {
                let owned =
                    (ci < tile.x + tile.width || ci == w) && (cj < tile.y + tile.height || cj == h);
                let ray = self.camera.ray(ci, cj, 0.0, 0.0);
                corners.push(if owned {
                    self.sample(&ray, counter, counts)
                } else {
                    self.sample(&ray, &mut NoCounts, &mut TileCounts::default())
                });
            }
        }
        self.pixels_from_corners(&corners, cw, tile.width, tile.height)
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

    /// Every corner ray of the image once (rows in parallel), then the
    /// pixels from them: the SPD's `(width + 1) x (height + 1)` eye rays.
    fn render_corners(
        &self,
        count_work: bool,
        progress: Option<&(dyn Fn(u64, u64) + Sync)>,
    ) -> (Frame, TileCounts) {
        let (w, h) = (self.settings.width, self.settings.height);
        let done = AtomicU64::new(0);
        let rows: Vec<(Vec<DVec3>, TileCounts)> = (0..=h)
            .into_par_iter()
            .map(|cj| {
                let mut counts = TileCounts::default();
                let mut work = WorkCounts::default();
                let row: Vec<DVec3> = (0..=w)
                    .map(|ci| {
                        let ray = self.camera.ray(ci, cj, 0.0, 0.0);
                        if count_work {
                            self.sample(&ray, &mut work, &mut counts)
                        } else {
                            self.sample(&ray, &mut NoCounts, &mut counts)
                        }
                    })
                    .collect();
                counts.work = work;
                let n = done.fetch_add(1, Ordering::Relaxed) + 1;
                if let Some(p) = progress {
                    p(n, h as u64 + 1);
                }
                (row, counts)
            })
            .collect();
        let mut counts = TileCounts::default();
        let mut corners = Vec::with_capacity(((w + 1) * (h + 1)) as usize);
        for (row, c) in rows {
            counts += c;
            corners.extend(row);
        }
        let frame = Frame {
            width: w,
            height: h,
            view: self.settings.view,
            colors: self.settings.colors,
            pixels: self.pixels_from_corners(&corners, w + 1, w, h),
        };
        (frame, counts)
    }

    /// Traces every `every`-th row of the image (rows 0, every, 2 every, ...)
    /// without keeping the pixels: a deterministic subset for estimating
    /// the cost of slow configurations.
    pub fn trace_rows(&self, every: u32, count_work: bool) -> TileCounts {
        let rows: Vec<u32> = (0..self.settings.height)
            .step_by(every.max(1) as usize)
            .collect();
        let per_row: Vec<TileCounts> = rows
            .par_iter()
            .map(|&y| {
                let tile = Tile {
                    x: 0,
                    y,
                    width: self.settings.width,
                    height: 1,
                };
                self.render_tile(tile, count_work).1
            })
            .collect();
        let mut total = TileCounts::default();
        for c in per_row {
            total += c;
        }
        total
    }

    /// Renders the whole frame on the current rayon pool. `progress` is
    /// called with (tiles done, tiles total) as tiles finish.
    pub fn render(
        &self,
        count_work: bool,
        progress: Option<&(dyn Fn(u64, u64) + Sync)>,
    ) -> (Frame, TileCounts) {
        if self.settings.corner_rays() {
            return self.render_corners(count_work, progress);
        }
        if self.settings.anti_aliasing() == AntiAliasing::Adaptive {
            return self.render_adaptive(count_work, progress);
        }
        let (w, h) = (self.settings.width, self.settings.height);
        let all = tiles(w, h);
        let total = all.len() as u64;
        let done = AtomicU64::new(0);
        let results: Vec<(Vec<DVec3>, TileCounts)> = all
            .par_iter()
            .map(|&t| {
                let r = self.render_tile(t, count_work);
                let n = done.fetch_add(1, Ordering::Relaxed) + 1;
                if let Some(p) = progress {
                    p(n, total);
                }
                r
            })
            .collect();
        assemble_tiles(&self.settings, &all, results)
    }
}

/// A pixel's samples as they arrive: their sum, and for the depth view the
/// distances of those that hit and their number.
#[derive(Clone, Copy, Default)]
struct PixelSum {
    sum: DVec3,
    n: u32,
}

impl PixelSum {
    #[inline]
    fn add(&mut self, sample: DVec3) {
        self.sum += sample;
        self.n += 1;
    }

    /// The pixel: the samples' mean; for the depth view the mean distance
    /// of those that hit (`x` sums distances, `y` hits) and the share that
    /// hit; for the cost views their sum (`cost_sum`) or mean.
    fn value(&self, view: ViewMode, cost_sum: bool) -> DVec3 {
        let n = self.n.max(1) as f64;
        match view {
            ViewMode::Depth if self.sum.y > 0.0 => {
                DVec3::new(self.sum.x / self.sum.y, self.sum.y / n, 0.0)
            }
            ViewMode::Depth => DVec3::ZERO,
            ViewMode::Cost | ViewMode::CostSteps if cost_sum => self.sum,
            _ => self.sum / n,
        }
    }
}

/// Renders `settings.view` seen from `camera`, including the composite
/// aa-need view (a 1-sample and a 16-sample shaded render; their work is
/// summed). The frame for every other view is [`Renderer::render`]'s.
pub fn render_view(
    scene: &Scene,
    octree: &Octree,
    settings: RenderSettings,
    camera: &CameraSpec,
    count_work: bool,
    progress: Option<&(dyn Fn(u64, u64) + Sync)>,
) -> Result<(Frame, TileCounts), RenderError> {
    if settings.view != ViewMode::AaNeed {
        let renderer = Renderer::with_camera(scene, octree, settings, camera)?;
        return Ok(renderer.render(count_work, progress));
    }
    let pass = |samples| {
        Renderer::with_camera(
            scene,
            octree,
            RenderSettings {
                samples,
                view: ViewMode::Shaded,
                ..settings
            },
            camera,
        )
    };
    let (one, mut counts) = pass(1)?.render(count_work, progress);
    let (sixteen, more) = pass(16)?.render(count_work, progress);
    counts += more;
    Ok((Frame::aa_need(&one, &sixteen), counts))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::Light;
    use crate::scene::ImageSettings;
    use crate::shapes::{Plane, Shape, Sphere};

    /// A scene seen from (0, 0, 10) towards the origin, `size` pixels on
    /// a side, lit by one white light at `light`, with these materials.
    fn scene(size: u32, max_depth: u32, materials: Vec<Material>, light: DVec3) -> Scene {
        let mut scene = Scene::empty(
            "unit".into(),
            CameraSpec {
                eye: DVec3::new(0.0, 0.0, 10.0),
                lookat: DVec3::ZERO,
                up: DVec3::Y,
                fov: 20.0,
            },
            ImageSettings {
                width: size,
                height: size,
                samples: 1,
                max_depth,
                background: DVec3::new(0.2, 0.4, 0.6),
                ambient: DVec3::splat(0.25),
                ..ImageSettings::default()
            },
        );
        scene.materials = materials;
        scene.lights = vec![Light {
            position: light,
            color: DVec3::ONE,
        }];
        scene
    }

    fn render(scene: &Scene) -> (Frame, TileCounts) {
        let octree = Octree::build(&scene.shapes, scene.octree_params).unwrap();
        Renderer::new(scene, &octree, RenderSettings::from_scene(scene))
            .unwrap()
            .render(false, None)
    }

    fn mirror(reflectivity: f64) -> Material {
        Material {
            ka: 0.0,
            kd: 0.0,
            reflectivity,
            ..Material::default()
        }
    }

    #[test]
    fn a_mirror_facing_the_eye_shows_the_background_times_its_weight() {
        // The centre ray comes straight back and leaves the scene.
        let mut s = scene(3, 5, vec![mirror(0.5)], DVec3::new(0.0, 0.0, 10.0));
        s.push(Shape::Plane(Plane::new(DVec3::ZERO, DVec3::Z)), 0);
        let (frame, counts) = render(&s);
        let expected = 0.5 * DVec3::new(0.2, 0.4, 0.6);
        assert!(
            (frame.pixels[4] - expected).length() < 1e-12,
            "{}",
            frame.pixels[4]
        );
        assert_eq!(counts.rays.reflection, 9, "one mirror ray per pixel");
    }

    #[test]
    fn facing_mirrors_spawn_one_reflection_per_level_of_depth() {
        // Mirrors at z = 0 and z = 20 with the eye between them: every ray
        // bounces until the depth limit, `max_depth - 1` reflections.
        for max_depth in [1, 2, 5, 9] {
            let mut s = scene(4, max_depth, vec![mirror(1.0)], DVec3::new(0.0, 3.0, 10.0));
            s.push(Shape::Plane(Plane::new(DVec3::ZERO, DVec3::Z)), 0);
            s.push(
                Shape::Plane(Plane::new(DVec3::new(0.0, 0.0, 20.0), -DVec3::Z)),
                0,
            );
            let (_, counts) = render(&s);
            assert_eq!(counts.rays.primary, 16);
            assert_eq!(
                counts.rays.reflection,
                16 * (max_depth as u64 - 1),
                "max depth {max_depth}"
            );
        }
    }

    #[test]
    fn a_sphere_between_light_and_floor_leaves_only_ambient_below_it() {
        let floor = Material {
            color: DVec3::new(0.9, 0.5, 0.1),
            ka: 1.0,
            kd: 0.7,
            ..Material::default()
        };
        // The sphere halfway from the floor's centre (the centre pixel) to
        // the light, off the eye's line of sight.
        let light = DVec3::new(3.0, 0.0, 6.0);
        let mut s = scene(5, 1, vec![floor.clone()], light);
        s.push(Shape::Plane(Plane::new(DVec3::ZERO, DVec3::Z)), 0);
        let (lit, _) = render(&s);
        s.push(Shape::Sphere(Sphere::new(light * 0.5, 0.3)), 0);
        let (shadowed, _) = render(&s);
        let ambient = 0.25 * floor.color;
        // Lambert: kd * color * cos, the cosine 6 / |(3, 0, 6)|.
        let direct = 0.7 * floor.color * (6.0 / 45f64.sqrt());
        assert!((lit.pixels[12] - (ambient + direct)).length() < 1e-12);
        assert!(
            (shadowed.pixels[12] - ambient).length() < 1e-12,
            "{} vs {ambient}",
            shadowed.pixels[12]
        );
        // A corner of the floor is out of the shadow: unchanged.
        assert_eq!(shadowed.pixels[0], lit.pixels[0]);
    }

    #[test]
    fn an_index_matched_clear_sphere_is_invisible() {
        // ior 1, fully transparent, no local light: the refracted ray goes
        // straight on, so the picture is the one without the sphere.
        let floor = Material {
            color: DVec3::new(0.3, 0.8, 0.4),
            ..Material::default()
        };
        let glass = Material {
            ka: 0.0,
            kd: 0.0,
            transparency: 1.0,
            ior: 1.0,
            ..Material::default()
        };
        let light = DVec3::new(2.0, 3.0, 9.0);
        let mut s = scene(16, 5, vec![floor, glass], light);
        s.push(Shape::Plane(Plane::new(DVec3::ZERO, DVec3::Z)), 0);
        let (without, _) = render(&s);
        s.push(
            Shape::Sphere(Sphere::new(DVec3::new(0.0, 0.0, 2.0), 1.0)),
            1,
        );
        let (with, counts) = render(&s);
        assert!(counts.rays.refraction > 0, "rays went through the sphere");
        for (a, b) in with.pixels.iter().zip(&without.pixels) {
            assert!((*a - *b).length() < 1e-9, "{a} vs {b}");
        }
    }

    #[test]
    fn settings_outside_the_limits_are_refused() {
        let mut s = scene(4, 5, vec![Material::default()], DVec3::Z);
        s.push(Shape::Plane(Plane::new(DVec3::ZERO, DVec3::Z)), 0);
        let octree = Octree::build(&s.shapes, s.octree_params).unwrap();
        let base = RenderSettings::from_scene(&s);
        let with = |settings| Renderer::new(&s, &octree, settings).err();
        assert!(matches!(
            with(RenderSettings { samples: 8, ..base }),
            Some(RenderError::Samples(8))
        ));
        assert!(matches!(
            with(RenderSettings {
                max_depth: 0,
                ..base
            }),
            Some(RenderError::MaxDepth(0))
        ));
        assert!(matches!(
            with(RenderSettings {
                width: MAX_IMAGE_SIDE + 1,
                ..base
            }),
            Some(RenderError::TooLarge(..))
        ));
        assert!(
            with(RenderSettings {
                samples: 16,
                ..base
            })
            .is_none()
        );
    }
}
