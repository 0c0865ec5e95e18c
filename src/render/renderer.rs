//! A scene prepared for rendering with fixed settings: the camera built,
//! materials in the convention the render shades in, which shapes are
//! one-sided or transparent, and the ray queries (octree, BVH or brute
//! force) the integrator asks.

use crate::accel::{
    BoxLanes, Bvh, BvhStack, Candidates, ClosestHit, Octree, OneByOne, Primitives, ShadowCrossings,
    ShapeRange, SkippingPlanes, WalkLog, WalkStack, closest_brute_force, occlusion_among,
    occlusion_among_in_lanes, occlusion_brute_force,
};
use crate::camera::{Camera, CameraError, CameraSpec, sample_offsets};
use crate::limits::LimitError;
use crate::material::Material;
use crate::math::{Color, DVec3, Ray};
use crate::render::accelerator::{Accelerator, Structure};
use crate::render::ray_tree::{RayKind, RayNode};
use crate::render::texturing::Texturing;
use crate::scene::Scene;
use crate::settings::{Accel, RenderSettings, Sides, ViewMode};
use crate::shapes::PreparedRay;
use crate::simd::{SimdLevel, SingleRays};
use crate::stats::{Counter, NoCounts, RayCounts};

#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    #[error(transparent)]
    Camera(#[from] CameraError),
    #[error(transparent)]
    Limit(#[from] LimitError),
    #[error(transparent)]
    Octree(#[from] crate::accel::OctreeError),
    #[error(
        "the settings ask for --accel {asked}, and the accelerator given is {built}: \
         build it from these settings"
    )]
    AccelMismatch {
        asked: &'static str,
        built: &'static str,
    },
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

/// Scratch space for ray queries: the octree walk's and the BVH's stacks
/// and a shadow ray's crossings. One per tile (or per inspected pixel), so
/// no ray sets them up.
#[derive(Default)]
pub struct Scratch {
    stack: WalkStack,
    bvh: BvhStack,
    crossings: ShadowCrossings,
    /// Per light (the first [`HINTED_LIGHTS`]), the opaque shape that last
    /// blocked a shadow ray towards it, tested before any walk where that
    /// has paid: neighbouring shadow rays are often blocked by the same
    /// shape (Haines and Greenberg 1986, the shadow cache).
    hints: [ShadowHint; HINTED_LIGHTS],
}

/// Scenes of at most this many shapes keep no [`ShadowHint`]s.
const HINTS_MIN_SHAPES: usize = 8;

/// Lights whose shadow rays keep a [`ShadowHint`] (the SPD scenes have at
/// most seven).
const HINTED_LIGHTS: usize = 16;

/// The shape that last blocked a shadow ray towards one light, and a score
/// of how often testing it first answers the next ray.
#[derive(Clone, Copy)]
struct ShadowHint {
    shape: u32,
    /// Up by [`ShadowHint::HIT`] when the shape blocks the next ray, down
    /// by one when it does not; the shape is tested first while the score
    /// is not negative, so while more than about one ray in nine is
    /// answered by it (a miss costs one shape test, a hit saves a walk:
    /// ten tests' worth on a mesh, more elsewhere). Untested, a walk
    /// blocked by the same shape counts as a hit, so the test resumes.
    score: i32,
}

impl Default for ShadowHint {
    /// No shape yet (no index is `u32::MAX`), tested on the first ray.
    fn default() -> Self {
        Self {
            shape: u32::MAX,
            score: 0,
        }
    }
}

impl ShadowHint {
    const HIT: i32 = 8;
    /// Bounds that let the score turn within a few dozen rays when the
    /// blocking shapes change (a tile moving onto a mesh, say).
    const MIN: i32 = -16;
    const MAX: i32 = 64;

    #[inline(always)]
    fn count(&mut self, hit: bool) {
        let step = if hit { Self::HIT } else { -1 };
        self.score = (self.score + step).clamp(Self::MIN, Self::MAX);
    }
}

/// What a ray's queries use besides the scene: the counter of their work
/// (Havran's measures, or nothing) and the scratch space.
pub(super) struct Query<'s, C> {
    pub counter: &'s mut C,
    pub scratch: &'s mut Scratch,
}

/// A single ray's query (nothing counted) for the octree's lanes `L`: a
/// closest hit, a shadow ray's crossings, or those among a light buffer's
/// few shapes.
trait SingleQuery {
    type Output;
    fn run<L: BoxLanes>(self, lanes: L) -> Self::Output;
}

/// `Q` with the lanes `L`, as a function compiled for the render's SIMD
/// level ([`SingleRays`]).
struct InLanes<Q, L>(Q, L);

impl<Q: SingleQuery, L: BoxLanes> pulp::WithSimd for InLanes<Q, L> {
    type Output = Q::Output;

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) -> Q::Output {
        self.0.run(self.1)
    }
}

/// A single ray's closest hit.
struct ClosestQuery<'q> {
    octree: &'q Octree,
    prims: &'q Primitives<'q>,
    ray: &'q PreparedRay,
    stack: &'q mut WalkStack,
}

impl SingleQuery for ClosestQuery<'_> {
    type Output = Option<ClosestHit>;

    #[inline(always)]
    fn run<L: BoxLanes>(self, lanes: L) -> Option<ClosestHit> {
        self.octree.closest_inline(
            self.prims,
            self.ray,
            f64::INFINITY,
            self.stack,
            &mut NoCounts,
            lanes,
        )
    }
}

/// A shadow ray's crossings.
struct OcclusionQuery<'q> {
    octree: &'q Octree,
    prims: &'q Primitives<'q>,
    ray: &'q PreparedRay,
    distance: f64,
    crossings: &'q mut ShadowCrossings,
    stack: &'q mut WalkStack,
}

impl SingleQuery for OcclusionQuery<'_> {
    type Output = ();

    #[inline(always)]
    fn run<L: BoxLanes>(self, lanes: L) {
        self.octree.occlusion_inline(
            self.prims,
            self.ray,
            self.distance,
            self.crossings,
            self.stack,
            &mut NoCounts,
            lanes,
        );
    }
}

/// A shadow ray's crossings among a light buffer's few shapes.
struct AmongQuery<'q> {
    prims: &'q Primitives<'q>,
    lists: [&'q [u32]; 2],
    ray: &'q PreparedRay,
    distance: f64,
    crossings: &'q mut ShadowCrossings,
}

impl SingleQuery for AmongQuery<'_> {
    type Output = ();

    #[inline(always)]
    fn run<L: BoxLanes>(self, lanes: L) {
        occlusion_among_in_lanes(
            self.prims,
            self.lists,
            self.ray,
            self.distance,
            self.crossings,
            lanes,
        );
    }
}

/// A single ray's closest hit or shadow crossings through the BVH (nothing
/// counted), as a function compiled for the render's SIMD level.
struct BvhQuery<'q> {
    bvh: &'q Bvh,
    prims: &'q Primitives<'q>,
    ray: &'q PreparedRay,
    stack: &'q mut BvhStack,
    /// `Some((distance, crossings))`: a shadow ray; `None`: a closest hit.
    shadow: Option<(f64, &'q mut ShadowCrossings)>,
    simd: pulp::x86::V3,
}

impl pulp::WithSimd for BvhQuery<'_> {
    type Output = Option<ClosestHit>;

    #[inline(always)]
    fn with_simd<S: pulp::Simd>(self, _simd: S) -> Option<ClosestHit> {
        let Self {
            bvh,
            prims,
            ray,
            stack,
            shadow,
            simd,
        } = self;
        match shadow {
            None => bvh.closest_inline(prims, ray, f64::INFINITY, stack, &mut NoCounts, simd),
            Some((distance, crossings)) => {
                bvh.occlusion_inline(prims, ray, distance, crossings, stack, &mut NoCounts, simd);
                None
            }
        }
    }
}

/// Crossings of one material closer than this, relative to the scene's
/// magnitude, are one surface: far above the rounding of hit distances,
/// far below any thickness a scene models.
const SAME_SURFACE_RELATIVE: f64 = 1e-9;

/// A scene prepared for rendering with fixed settings.
pub struct Renderer<'a> {
    pub(super) scene: &'a Scene,
    /// What every query goes through, built for these settings.
    accel: &'a Accelerator,
    /// Whether shadow rays test the shape that last blocked their light's
    /// first ([`ShadowHint`]): not on a scene of a few shapes, where the
    /// query costs about what the hint does.
    shadow_hints: bool,
    pub(super) settings: RenderSettings,
    pub(super) camera: Camera,
    /// What `camera` was made from (a thumbnail of the same view needs it).
    pub(super) camera_spec: CameraSpec,
    /// Where in a pixel the rays of the full grid pass (the aa-need view
    /// compares one sample with 16 whatever `settings.samples` says).
    pub(super) grid: Vec<(f64, f64)>,
    is_transparent: Vec<bool>,
    /// How textures are drawn, when the scene has them and they are on.
    /// Boxed: its texel table would otherwise double the renderer's size.
    pub(super) texturing: Option<Box<Texturing>>,
    /// Whether some triangle's material cuts it out: queries then look
    /// past the gaps.
    pub(super) cuts_out: bool,
    /// Per shape: seen from outside only ([`Sides::One`]); empty otherwise.
    one_sided: Vec<bool>,
    /// Single rays test triangles four at a time
    /// ([`Primitives::mostly_triangles`]).
    triangle_lanes: bool,
    /// Shadow rays skip the shapes in the plane they leave: where single
    /// rays test triangles four at a time and the scene has shapes that
    /// share a plane ([`crate::accel::PlaneGroups`]).
    skips_planes: bool,
    /// The scene's materials and background as this render shades them
    /// (decoded into linear light for a linear render of display values).
    pub(super) materials: Vec<Material>,
    pub(super) background: Color,
    /// Magnitude of the scene's surfaces and the eye: the floor of ray offsets.
    pub(super) floor_scale: f64,
    /// Packets of this many lanes where rays are coherent (1: single rays).
    pub(super) simd: SimdLevel,
    /// Where single rays' octree queries run (AVX2 or baseline code).
    pub(super) single_rays: SingleRays,
}

impl<'a> Renderer<'a> {
    /// The renderer of `scene` with `settings`, its queries through
    /// `accel` (built with [`Accelerator::build`] from the same settings).
    pub fn new(
        scene: &'a Scene,
        accel: &'a Accelerator,
        settings: RenderSettings,
    ) -> Result<Self, RenderError> {
        Self::with_camera(scene, accel, settings, &scene.camera)
    }

    /// Like [`Renderer::new`], seen from `camera` instead of the scene's own
    /// (the viewer moves the camera without touching the scene).
    pub fn with_camera(
        scene: &'a Scene,
        accel: &'a Accelerator,
        settings: RenderSettings,
        camera: &CameraSpec,
    ) -> Result<Self, RenderError> {
        settings.check()?;
        if settings.accel != accel.kind() {
            return Err(RenderError::AccelMismatch {
                asked: settings.accel.name(),
                built: accel.kind().name(),
            });
        }
        let camera_spec = *camera;
        let camera = Camera::new(camera, settings.width, settings.height)?;
        let texturing = Texturing::new(scene, &settings).map(Box::new);
        // Cut-out triangles let light through their gaps: shadow rays
        // record their crossings as they do a transparent surface's.
        let is_transparent: Vec<bool> = scene
            .shape_materials
            .iter()
            .enumerate()
            .map(|(shape, &m)| {
                scene.materials[m as usize].transparency > 0.0
                    || texturing
                        .as_ref()
                        .is_some_and(|t| t.any_cut && t.cuts_shape(scene, shape))
            })
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
        let triangle_lanes = Primitives::mostly_triangles(&scene.shapes);
        Ok(Self {
            scene,
            accel,
            shadow_hints: scene.shapes.len() > HINTS_MIN_SHAPES,
            triangle_lanes,
            skips_planes: triangle_lanes && accel.planes().is_some_and(|p| p.has_groups()),
            settings,
            camera,
            camera_spec,
            grid: sample_offsets(if settings.view == ViewMode::AaNeed {
                16
            } else {
                settings.samples
            }),
            is_transparent,
            cuts_out: texturing.as_ref().is_some_and(|t| t.any_cut),
            texturing,
            one_sided,
            materials,
            background: shade(scene.image.background),
            floor_scale: scene
                .geometry_bounds()
                .grow(camera.eye)
                .max_abs()
                .max(f64::MIN_POSITIVE),
            simd: if crate::simd::packets_enabled() {
                SimdLevel::current()
            } else {
                SimdLevel::Scalar
            },
            single_rays: SingleRays::at(SimdLevel::current()),
        })
    }

    pub fn settings(&self) -> &RenderSettings {
        &self.settings
    }

    pub fn camera(&self) -> &Camera {
        &self.camera
    }

    /// Renders with packets at `level` instead of the machine's best (at
    /// most the best: a level the machine lacks runs its best). The bytes
    /// are the same at every level; only the time differs.
    pub fn with_simd(mut self, level: SimdLevel) -> Self {
        let level = level.min(SimdLevel::best());
        self.single_rays = SingleRays::at(level);
        self.simd = if crate::simd::packets_enabled() {
            level
        } else {
            SimdLevel::Scalar
        };
        self
    }

    /// The SIMD level this render uses.
    pub fn simd(&self) -> SimdLevel {
        self.simd
    }

    /// Whether shadow rays ask a light buffer first.
    pub fn has_light_buffer(&self) -> bool {
        self.accel.light_buffer().is_some()
    }

    /// What this renderer's queries go through.
    pub fn accelerator(&self) -> &'a Accelerator {
        self.accel
    }

    /// The octree queries counted by `C` walk, if they walk one: counted
    /// queries always do (Havran's counts are the tree's); uncounted ones
    /// go brute force over a one-leaf tree, which holds every shape.
    #[inline(always)]
    pub(super) fn walked_octree<C: Counter>(&self) -> Option<&'a Octree> {
        match self.accel.structure() {
            Structure::Octree(tree) if C::COUNTS || self.accel.walks_uncounted() => Some(tree),
            _ => None,
        }
    }

    pub(super) fn primitives(&self) -> Primitives<'_> {
        Primitives {
            shapes: &self.scene.shapes,
            one_sided: &self.one_sided,
            transparent: &self.is_transparent,
            left_behind: ShapeRange::EMPTY,
        }
    }

    /// The shapes a shadow ray from `origin` along `dir`, leaving a hit on
    /// shape `shape`, skips ([`crate::accel::PlaneGroups::left_behind`]).
    #[inline(always)]
    pub(super) fn left_behind(&self, shape: u32, origin: DVec3, dir: DVec3) -> ShapeRange {
        match self.accel.planes() {
            Some(planes) if self.skips_planes => planes.left_behind(shape, origin, dir),
            _ => ShapeRange::EMPTY,
        }
    }

    /// [`Renderer::single`] for a shadow ray's `query`: skipping the shapes
    /// in the plane the ray leaves where the renderer does.
    #[inline(always)]
    fn single_shadow<Q: SingleQuery>(&self, simd: pulp::x86::V3, query: Q) -> Q::Output {
        if self.skips_planes {
            pulp::Simd::vectorize(simd, InLanes(query, SkippingPlanes(simd)))
        } else {
            self.single(simd, query)
        }
    }

    /// Runs a single ray's `query` compiled for `simd`, its triangles four
    /// at a time where the scene is mostly triangles (one by one
    /// elsewhere, in a copy of the code of its own).
    #[inline(always)]
    fn single<Q: SingleQuery>(&self, simd: pulp::x86::V3, query: Q) -> Q::Output {
        if self.triangle_lanes {
            pulp::Simd::vectorize(simd, InLanes(query, simd))
        } else {
            pulp::Simd::vectorize(simd, InLanes(query, OneByOne(simd)))
        }
    }

    /// The nearest hit along `ray`, through the gaps of cut-out textures
    /// ([`Renderer::past_gaps`]).
    #[inline(always)]
    pub(super) fn closest<C: Counter>(
        &self,
        ray: &PreparedRay,
        query: &mut Query<C>,
    ) -> Option<ClosestHit> {
        let hit = self.nearest_surface(ray, query);
        if self.cuts_out {
            self.past_gaps(ray, hit, query)
        } else {
            hit
        }
    }

    /// The nearest surface along `ray`, gaps or not.
    pub(super) fn nearest_surface<C: Counter>(
        &self,
        ray: &PreparedRay,
        query: &mut Query<C>,
    ) -> Option<ClosestHit> {
        let prims = self.primitives();
        if let Structure::Bvh(bvh) = self.accel.structure() {
            let stack = &mut query.scratch.bvh;
            if !C::COUNTS
                && let Some(simd) = self.single_rays.avx2()
            {
                let query = BvhQuery {
                    bvh,
                    prims: &prims,
                    ray,
                    stack,
                    shadow: None,
                    simd,
                };
                return pulp::Simd::vectorize(simd, query);
            }
            return bvh.closest(&prims, ray, f64::INFINITY, stack, query.counter);
        }
        if let Some(octree) = self.walked_octree::<C>() {
            let stack = &mut query.scratch.stack;
            if !C::COUNTS
                && let Some(simd) = self.single_rays.avx2()
            {
                return self.single(
                    simd,
                    ClosestQuery {
                        octree,
                        prims: &prims,
                        ray,
                        stack,
                    },
                );
            }
            octree.closest(&prims, ray, f64::INFINITY, stack, query.counter)
        } else {
            closest_brute_force(&prims, ray, f64::INFINITY, query.counter)
        }
    }

    /// Fraction of light passing along the shadow ray to a light `distance`
    /// away. Every surface crossed multiplies it by its material's
    /// transparency (entering and leaving a glass sphere or a closed glass
    /// mesh: T twice), whatever kind of shape it is; crossings of the same
    /// material at the same place count once (coincident triangles, a ray
    /// through a mesh's shared edge, two glass bodies touching: no
    /// interface), and any opaque surface blocks the light.
    ///
    /// Uncounted, the shape that last blocked a shadow ray towards the same
    /// `light` is tested first: if it blocks this one too, no light passes,
    /// whatever else the ray meets, so the answer is the query's. Counted
    /// queries walk, so Havran's counts stay the accelerator's. Then, with
    /// a light buffer, a ray whose direction lists few shapes tests those
    /// and the unbounded ones: every shape it can meet, so the answer is
    /// brute force's.
    pub(super) fn transmittance<C: Counter>(
        &self,
        ray: &PreparedRay,
        distance: f64,
        light: usize,
        left_behind: ShapeRange,
        query: &mut Query<C>,
    ) -> f64 {
        let mut prims = self.primitives();
        prims.left_behind = left_behind;
        let Scratch {
            stack,
            bvh,
            crossings,
            hints,
        } = &mut *query.scratch;
        let mut hint = None;
        if !C::COUNTS
            && self.shadow_hints
            && let Some(h) = hints.get_mut(light)
        {
            let tested = h.score >= 0;
            if tested {
                let hit = prims.blocks(h.shape, ray, distance);
                h.count(hit);
                if hit {
                    return 0.0;
                }
            }
            hint = Some((h, tested));
        }
        let few = match self.accel.light_buffer() {
            Some(buffer) if !C::COUNTS => match buffer.candidates(light, ray) {
                Candidates::Few(list) => Some([buffer.unbounded(), list]),
                Candidates::Many => None,
            },
            _ => None,
        };
        if let Some(lists) = few {
            match self.single_rays.avx2() {
                Some(simd) => self.single_shadow(
                    simd,
                    AmongQuery {
                        prims: &prims,
                        lists,
                        ray,
                        distance,
                        crossings,
                    },
                ),
                None => occlusion_among(&prims, lists, ray, distance, crossings, query.counter),
            }
        } else if let Structure::Bvh(tree) = self.accel.structure() {
            match self.single_rays.avx2() {
                Some(simd) if !C::COUNTS => {
                    let query = BvhQuery {
                        bvh: tree,
                        prims: &prims,
                        ray,
                        stack: bvh,
                        shadow: Some((distance, crossings)),
                        simd,
                    };
                    pulp::Simd::vectorize(simd, query);
                }
                _ => tree.occlusion(&prims, ray, distance, crossings, bvh, query.counter),
            }
        } else if let Some(octree) = self.walked_octree::<C>() {
            match self.single_rays.avx2() {
                Some(simd) if !C::COUNTS => self.single_shadow(
                    simd,
                    OcclusionQuery {
                        octree,
                        prims: &prims,
                        ray,
                        distance,
                        crossings,
                        stack,
                    },
                ),
                _ => octree.occlusion(&prims, ray, distance, crossings, stack, query.counter),
            }
        } else {
            occlusion_brute_force(&prims, ray, distance, crossings, query.counter);
        }
        if let Some((h, tested)) = hint
            && let Some(shape) = crossings.blocker()
        {
            if !tested {
                h.count(shape == h.shape);
            }
            h.shape = shape;
        }
        self.pass_through(&ray.ray, crossings)
    }

    /// The light a shadow ray's crossings let through.
    #[inline(always)]
    pub(super) fn pass_through(&self, ray: &Ray, found: &ShadowCrossings) -> f64 {
        if found.is_blocked() {
            return 0.0;
        }
        if self.cuts_out {
            self.pass_through_crossings::<true>(ray, found)
        } else {
            self.pass_through_crossings::<false>(ray, found)
        }
    }

    /// [`Renderer::pass_through`] of a ray not blocked, looking up the
    /// gaps of cut-outs if `GAPS` (a render without cut-outs skips the test).
    fn pass_through_crossings<const GAPS: bool>(&self, ray: &Ray, found: &ShadowCrossings) -> f64 {
        // Crossings come sorted by distance, so the product is the same
        // whichever order they were found in.
        let same_place = SAME_SURFACE_RELATIVE * self.floor_scale;
        let mut pass = 1.0;
        let mut previous: Option<(f64, u32)> = None;
        for &(t, shape) in found.transparent() {
            // Light passes a cut-out's gaps untouched.
            if GAPS && self.crosses_gap(ray, shape, t) {
                continue;
            }
            let material = self.scene.shape_materials[shape as usize];
            let repeat = previous.is_some_and(|(pt, pm)| pm == material && t - pt <= same_place);
            if !repeat {
                pass *= self.materials[material as usize].transparency;
            }
            previous = Some((t, material));
        }
        pass
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
        let mut scratch = Scratch::default();
        // The walk log counts too: each ray's record carries its walk.
        let mut log = WalkLog::new(self.settings.accel == Accel::Octree);
        let mut query = Query {
            counter: &mut log,
            scratch: &mut scratch,
        };
        self.trace(&ray, 1, &mut query, &mut rays, &mut root);
        root
    }
}

#[cfg(test)]
mod tests;
