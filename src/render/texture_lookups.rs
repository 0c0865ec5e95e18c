//! Textures looked up at hits: a colour map's colour, and cut-outs, the
//! gaps a map's alpha below one half makes, which eye rays and shadow rays
//! pass through.
//!
//! Only triangles carry texture coordinates, so only they are textured or
//! cut. A ray that meets a gap goes on from just past it in the same
//! direction; a shadow ray's crossings of cut-out triangles are looked up
//! where they lie ([`Renderer::pass_through`]).

use crate::accel::ClosestHit;
use crate::math::{Color, DVec3, Ray, offset_ray_origin};
use crate::shapes::{PreparedRay, Shape, ShapeHit};
use crate::stats::Counter;

use super::renderer::{Query, Renderer};
use super::texturing::Texturing;

/// How many gaps one ray passes before the surface behind the last one is
/// taken as its hit: a bound on a ray grazing a stack of leaves, never met
/// by a ray that crosses a model's foliage.
const MAX_GAPS: u32 = 1024;

impl Renderer<'_> {
    /// `color`, the diffuse colour of material `material`, times its colour
    /// map at the hit `hit` of shape `shape` where it has one.
    #[inline(always)]
    pub(super) fn textured_color(
        &self,
        color: Color,
        material: u32,
        shape: u32,
        hit: &ShapeHit,
    ) -> Color {
        match &self.texturing {
            None => color,
            Some(texturing) => self.color_map_at(texturing, color, material, shape, hit),
        }
    }

    /// [`Renderer::textured_color`] in a render with textures: apart, so
    /// that renders without them keep their shading code as it was.
    #[inline(never)]
    fn color_map_at(
        &self,
        texturing: &Texturing,
        color: Color,
        material: u32,
        shape: u32,
        hit: &ShapeHit,
    ) -> Color {
        let Some(map) = &self.materials[material as usize].color_map else {
            return color;
        };
        let Some(st) = self
            .scene
            .uv_at(shape, hit.b1, hit.b2)
            .and_then(|uv| map.lookup(uv))
        else {
            return color;
        };
        let texture = &self.scene.textures[map.texture as usize];
        color * texture.sample(st, map.clamp, &texturing.values).0
    }

    /// Whether shape `shape` is cut away at barycentric coordinates
    /// `(b1, b2)`: its cut-out map's coverage there is below one half (off a
    /// clamped map's single copy the surface is whole).
    #[inline]
    pub(super) fn cut_away(&self, shape: u32, b1: f64, b2: f64) -> bool {
        let Some(texturing) = &self.texturing else {
            return false;
        };
        let material = self.scene.shape_materials[shape as usize] as usize;
        if !texturing.cuts[material] {
            return false;
        }
        let Some(map) = &self.materials[material].cutout_map else {
            return false;
        };
        let Some(st) = self
            .scene
            .uv_at(shape, b1, b2)
            .and_then(|uv| map.lookup(uv))
        else {
            return false;
        };
        let texture = &self.scene.textures[map.texture as usize];
        texture.coverage(st, map.clamp, map.channel) < 0.5
    }

    /// Whether the shadow ray `ray` crosses shape `shape` at `t` through a gap.
    #[inline(never)]
    pub(super) fn crosses_gap(&self, ray: &Ray, shape: u32, t: f64) -> bool {
        match &self.scene.shapes[shape as usize] {
            Shape::Triangle(triangle) => {
                let (b1, b2) = triangle.barycentric(ray.at(t));
                self.cut_away(shape, b1, b2)
            }
            _ => false,
        }
    }

    /// `hit`, the nearest surface along `ray`, or where `ray` meets it past
    /// the gaps of cut-out triangles: from just beyond each gap the query
    /// goes on in the same direction. The hit's distance is measured along
    /// `ray` from its own origin.
    #[inline(never)]
    pub(super) fn past_gaps<C: Counter>(
        &self,
        ray: &PreparedRay,
        mut hit: Option<ClosestHit>,
        query: &mut Query<C>,
    ) -> Option<ClosestHit> {
        let dir = ray.ray.dir;
        for _ in 0..MAX_GAPS {
            let h = hit?;
            let Shape::Triangle(triangle) = &self.scene.shapes[h.shape as usize] else {
                return hit;
            };
            if !self.cut_away(h.shape, h.hit.b1, h.hit.b2) {
                return hit;
            }
            // Beyond the gap: off the triangle's plane on the far side.
            let point = triangle.point_at(h.hit.b1, h.hit.b2);
            let normal = triangle.normal();
            let across = if normal.dot(dir) < 0.0 {
                -normal
            } else {
                normal
            };
            let origin = offset_ray_origin(point, across, self.floor_scale);
            let next = self.nearest_surface(&PreparedRay::new(Ray::new(origin, dir)), query);
            hit = next.map(|mut n| {
                n.hit.t = along(&ray.ray, origin, n.hit.t);
                n
            });
        }
        hit
    }
}

/// The distance along `ray` (from its origin) of the point `t` along a ray
/// from `origin` in the same direction.
#[inline]
fn along(ray: &Ray, origin: DVec3, t: f64) -> f64 {
    (origin + ray.dir * t - ray.origin).dot(ray.dir) / ray.dir.length_squared()
}
