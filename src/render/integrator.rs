//! Whitted's integrator: the colour seen along one ray. At a hit, the local
//! term (ambient plus each visible light's Lambert and Phong terms, with
//! its shadow ray) and the secondary rays (refraction, then the mirror
//! ray), each traced recursively to the depth limit (Whitted 1980).

use crate::accel::ClosestHit;
use crate::math::{Color, DVec3, Ray, offset_distance, offset_ray_origin, reflect, refract};
use crate::render::ray_tree::{HitRecord, RayKind, RayRecorder, ShadowRecord, ShadowVerdict};
use crate::settings::Protocol;
use crate::shapes::{PreparedRay, Shape};
use crate::stats::{Counter, RayCounts};

use super::renderer::{Query, Renderer};

/// A hit resolved for shading: where, which way the surface faces, and
/// with what material.
pub(super) struct ShadingPoint {
    point: DVec3,
    /// Where shadow rays start before their offset: on a smooth-shaded
    /// triangle (glint's protocol) the smooth surface above `point`.
    shadow_point: DVec3,
    /// Shaded with interpolated normals under glint's protocol: the light
    /// test asks the shading normal alone.
    smooth: bool,
    /// The geometric normal turned towards the incoming ray.
    facing: DVec3,
    /// The shading normal on the same side as `facing`.
    normal: DVec3,
    /// Whether the ray meets the surface from outside.
    entering: bool,
    /// The shape hit.
    pub(super) shape: u32,
    material: u32,
    /// The diffuse colour here: the material's, or the vertex colours
    /// interpolated across a triangle that has them.
    color: Color,
}

/// A secondary ray of a hit: its kind, the ray and the weight of what it
/// sees in the hit's colour.
#[derive(Clone, Copy, Debug)]
pub(super) struct Secondary {
    pub kind: RayKind,
    pub ray: Ray,
    pub weight: f64,
}

impl Renderer<'_> {
    /// Colour seen along `ray`, which is at recursion `depth` (eye ray = 1).
    pub(super) fn trace<C: Counter, R: RayRecorder>(
        &self,
        ray: &Ray,
        depth: u32,
        query: &mut Query<C>,
        rays: &mut RayCounts,
        rec: &mut R,
    ) -> Color {
        let Some(at) = self.shading_point(ray, query, rec) else {
            let background = self.background;
            rec.local(background);
            rec.finish(background);
            return background;
        };
        if depth == 1 {
            rays.primary_hits += 1;
        }
        let mut color = self.direct_light(ray, &at, query, rays, rec);
        rec.local(color);
        if depth < self.settings.max_depth {
            self.secondary_rays(ray, &at, depth, &mut color, query, rays, rec);
        }
        rec.finish(color);
        color
    }

    /// The nearest hit along `ray`, resolved for shading (`None`: the ray
    /// leaves the scene).
    fn shading_point<C: Counter, R: RayRecorder>(
        &self,
        ray: &Ray,
        query: &mut Query<C>,
        rec: &mut R,
    ) -> Option<ShadingPoint> {
        let hit = self.closest(&PreparedRay::new(*ray), query);
        rec.query(|| query.counter.take_query());
        Some(self.shading_point_at(ray, &hit?, rec))
    }

    /// The hit `hit` of `ray` resolved for shading, told to `rec`.
    #[inline(always)]
    pub(super) fn shading_point_at<R: RayRecorder>(
        &self,
        ray: &Ray,
        hit: &ClosestHit,
        rec: &mut R,
    ) -> ShadingPoint {
        let scene = self.scene;
        let shape = &scene.shapes[hit.shape as usize];
        let surface = shape.surface(ray, &hit.hit, &scene.vertex_normals);
        let material = scene.shape_materials[hit.shape as usize];
        let entering = ray.dir.dot(surface.geometric_normal) < 0.0;
        // Normals facing the incoming ray: glint's surfaces are two-sided.
        let facing = if entering {
            surface.geometric_normal
        } else {
            -surface.geometric_normal
        };
        let mut normal = if surface.shading_normal.dot(facing) < 0.0 {
            -surface.shading_normal
        } else {
            surface.shading_normal
        };
        if !normal.is_finite() {
            normal = facing;
        }
        let point = surface.point;
        let shadow_point = match (self.settings.protocol, shape) {
            (Protocol::Glint, Shape::Triangle(t)) => {
                t.smooth_point(&hit.hit, point, facing, &scene.vertex_normals)
            }
            _ => point,
        };
        let smooth = self.settings.protocol == Protocol::Glint
            && matches!(shape, Shape::Triangle(t) if t.has_vertex_normals());
        let color = match scene.shape_colors.get(hit.shape as usize) {
            Some(&i) if i != u32::MAX => {
                let [c0, c1, c2] = scene.vertex_colors[i as usize];
                let (b1, b2) = (hit.hit.b1, hit.hit.b2);
                let c = (1.0 - b1 - b2) * c0 + b1 * c1 + b2 * c2;
                self.settings
                    .colors
                    .shading_color(scene.color_values, c.clamp(Color::ZERO, Color::ONE))
            }
            _ => self.materials[material as usize].color,
        };
        let color = self.textured_color(color, material, hit.shape, &hit.hit);
        rec.material(material);
        rec.surface(point);
        rec.hit(|| HitRecord {
            object: hit.shape,
            kind: shape.kind(),
            material: self.materials[material as usize].name.clone(),
            distance: hit.hit.t,
            point: point.to_array(),
            normal: normal.to_array(),
            entering,
        });
        ShadingPoint {
            shape: hit.shape,
            point,
            shadow_point,
            smooth,
            facing,
            normal,
            entering,
            material,
            color,
        }
    }

    /// The local term at `at`: ambient light plus, for every light the
    /// surface faces and its shadow ray reaches, Lambert's diffuse and
    /// Phong's specular term, dimmed by what the shadow ray passed through.
    fn direct_light<C: Counter, R: RayRecorder>(
        &self,
        ray: &Ray,
        at: &ShadingPoint,
        query: &mut Query<C>,
        rays: &mut RayCounts,
        rec: &mut R,
    ) -> Color {
        let mut color = self.ambient(at);
        let shadow_origin = self.shadow_origin(at);
        for (index, light) in self.scene.lights.iter().enumerate() {
            let Some((l, distance, n_dot_l)) = self.toward_light(at, shadow_origin, light) else {
                self.faces_away(index, rec);
                continue;
            };
            let pass = if self.settings.shadows {
                rays.shadow += 1;
                let shadow = PreparedRay::new(Ray::new(shadow_origin, l));
                let left = self.left_behind(at.shape, shadow_origin, l);
                self.transmittance(&shadow, distance, index, left, query)
            } else {
                1.0
            };
            if let Some(direct) = self.light_through(ray, at, index, l, n_dot_l, pass, rec) {
                color += direct;
            }
            if self.settings.shadows {
                rec.shadow_query(|| query.counter.take_query());
            }
        }
        color
    }

    /// The ambient term at `at`.
    #[inline(always)]
    pub(super) fn ambient(&self, at: &ShadingPoint) -> Color {
        let material = &self.materials[at.material as usize];
        material.ka * self.scene.image.ambient * at.color
    }

    /// Where shadow rays from `at` start: off the surface on the side the
    /// ray came from.
    #[inline(always)]
    pub(super) fn shadow_origin(&self, at: &ShadingPoint) -> DVec3 {
        offset_ray_origin(at.shadow_point, at.facing, self.floor_scale)
    }

    /// The direction to `light` from `origin`, how far its shadow ray
    /// reaches (the distance less [`offset_distance`]) and the cosine at
    /// the surface; `None` where the surface faces away from the light
    /// (or the light sits on the origin): then it gets neither light nor a
    /// shadow ray. On a flat surface glint asks the geometric normal too
    /// (an interpolated normal can face the light where the surface itself
    /// does not); on a smooth-shaded triangle the shading normal alone, as
    /// its shadow ray starts on the smooth surface ([`Triangle::smooth_point`]),
    /// so the terminator follows the smooth surface, not whole facets. The
    /// SPD asks the shading normal alone and starts shadow rays on the
    /// facet (its published shadow counts on the smooth-shaded teapot match
    /// only that way).
    ///
    /// [`Triangle::smooth_point`]: crate::shapes::Triangle::smooth_point
    #[inline(always)]
    pub(super) fn toward_light(
        &self,
        at: &ShadingPoint,
        origin: DVec3,
        light: &crate::material::Light,
    ) -> Option<(DVec3, f64, f64)> {
        let to_light = light.position - origin;
        let distance = to_light.length();
        if !(distance > 0.0) {
            return None;
        }
        let l = to_light / distance;
        // The shadow ray stops short of the light as far as it starts off
        // its surface: a light set in a surface (a lamp in a ceiling) is
        // then neither hidden nor shown by that surface point by point as
        // rounding falls, where the ray meets it at the light itself.
        let reach = (distance - offset_distance(light.position, self.floor_scale)).max(0.0);
        let n_dot_l = at.normal.dot(l);
        let faces_away = match self.settings.protocol {
            Protocol::Glint if at.smooth => n_dot_l <= 0.0,
            Protocol::Glint => n_dot_l <= 0.0 || at.facing.dot(l) <= 0.0,
            Protocol::Spd => n_dot_l <= 0.0,
        };
        (!faces_away).then_some((l, reach, n_dot_l))
    }

    /// Tells `rec` that light `index` faces away from the point.
    #[inline(always)]
    pub(super) fn faces_away<R: RayRecorder>(&self, index: usize, rec: &mut R) {
        rec.light(index, false);
        rec.shadow(|| ShadowRecord {
            light: index,
            verdict: ShadowVerdict::FacesAway,
            transmittance: 0.0,
            color: [0.0; 3],
            query: None,
        });
    }

    /// Light `index`'s diffuse and specular terms at `at` (direction `l`,
    /// cosine `n_dot_l`) times `pass`, the share its shadow ray let
    /// through; `None` when it let nothing through. Tells `rec`.
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    pub(super) fn light_through<R: RayRecorder>(
        &self,
        ray: &Ray,
        at: &ShadingPoint,
        index: usize,
        l: DVec3,
        n_dot_l: f64,
        pass: f64,
        rec: &mut R,
    ) -> Option<Color> {
        let verdict = |verdict, transmittance, color: Color| ShadowRecord {
            light: index,
            verdict,
            transmittance,
            color: color.to_array(),
            query: None,
        };
        rec.light(index, pass > 0.0);
        if pass == 0.0 {
            rec.shadow(|| verdict(ShadowVerdict::Blocked, 0.0, Color::ZERO));
            return None;
        }
        let material = &self.materials[at.material as usize];
        let n = at.normal;
        let light = &self.scene.lights[index];
        let diffuse = material.kd * n_dot_l * at.color;
        // Without a highlight the Phong term is exactly 0 (its power is
        // at most 1): skip the power, the costliest step of shading.
        let specular = if material.ks == 0.0 {
            0.0
        } else {
            let r = 2.0 * n_dot_l * n - l;
            material.ks * r.dot(-ray.dir).max(0.0).powf(material.shininess)
        };
        let direct = (diffuse + DVec3::splat(specular)) * light.color * pass;
        rec.shadow(|| {
            let kind = if pass < 1.0 {
                ShadowVerdict::Attenuated
            } else {
                ShadowVerdict::Lit
            };
            verdict(kind, pass, direct)
        });
        Some(direct)
    }

    /// Adds what the refracted and the mirror ray from `at` see, each
    /// weighted by the material, to `color`.
    #[allow(clippy::too_many_arguments)]
    pub(super) fn secondary_rays<C: Counter, R: RayRecorder>(
        &self,
        ray: &Ray,
        at: &ShadingPoint,
        depth: u32,
        color: &mut Color,
        query: &mut Query<C>,
        rays: &mut RayCounts,
        rec: &mut R,
    ) {
        for secondary in self.secondary_of(ray, at, rays).into_iter().flatten() {
            let Secondary { kind, ray, weight } = secondary;
            let mut child = rec.child(kind, &ray, depth + 1, weight);
            let seen = self.trace(&ray, depth + 1, query, rays, &mut child);
            rec.attach(child, seen);
            *color += weight * seen;
        }
    }

    /// The refracted and the mirror ray from `at`, in the order their
    /// colours are added (each where the material spawns it), counted in
    /// `rays`.
    #[inline(always)]
    pub(super) fn secondary_of(
        &self,
        ray: &Ray,
        at: &ShadingPoint,
        rays: &mut RayCounts,
    ) -> [Option<Secondary>; 2] {
        let material = &self.materials[at.material as usize];
        let (p, n, facing) = (at.point, at.normal, at.facing);
        let mut reflect_weight = material.reflectivity;
        let mut refraction = None;
        if material.transparency > 0.0 {
            let eta = if at.entering {
                1.0 / material.ior
            } else {
                material.ior
            };
            match refract(ray.dir, n, eta) {
                Some(dir) => {
                    rays.refraction += 1;
                    let origin = offset_ray_origin(p, -facing, self.floor_scale);
                    refraction = Some(Secondary {
                        kind: RayKind::Refraction,
                        ray: Ray::new(origin, dir),
                        weight: material.transparency,
                    });
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
        // An `if`, not `bool::then`: a closure the compiler keeps apart is
        // compiled without the SIMD level of the packet code calling this.
        let reflection = if spawn_reflection {
            rays.reflection += 1;
            let mut dir = reflect(ray.dir, n);
            // An interpolated normal can send the mirror ray below the
            // surface; fall back to the geometric mirror direction.
            if dir.dot(facing) <= 0.0 {
                dir = reflect(ray.dir, facing);
            }
            let origin = offset_ray_origin(p, facing, self.floor_scale);
            Some(Secondary {
                kind: RayKind::Reflection,
                ray: Ray::new(origin, dir.normalize()),
                weight: reflect_weight,
            })
        } else {
            None
        };
        [refraction, reflection]
    }
}
