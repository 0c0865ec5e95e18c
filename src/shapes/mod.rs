//! The closed set of shapes glint renders. Dispatch is a `match` on [`Shape`],
//! never a trait object, so the hot intersection loop inlines.

mod cone;
mod hit;
mod packet;
mod plane;
mod quadric;
mod sphere;
mod triangle;
mod triangle_lanes;

pub use cone::Cone;
pub(crate) use hit::unit_or_none;
pub use hit::{Crossings, PreparedRay, ShapeHit, Surface, probe_past, wins};
pub use packet::{LaneHits, PacketHits, RayPacket};
pub use plane::Plane;
pub use quadric::Quadric;
pub use sphere::Sphere;
pub use triangle::{NO_NORMALS, Triangle, triangle_overlaps_box};
pub use triangle_lanes::{FourHits, TriangleLanes};

use crate::math::{Aabb, DVec3, Ray};

/// The kinds of shape, as messages and the ray tree's JSON name them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum ShapeKind {
    Sphere,
    Plane,
    Triangle,
    Quadric,
    Cone,
}

impl ShapeKind {
    pub fn name(self) -> &'static str {
        match self {
            ShapeKind::Sphere => "sphere",
            ShapeKind::Plane => "plane",
            ShapeKind::Triangle => "triangle",
            ShapeKind::Quadric => "quadric",
            ShapeKind::Cone => "cone",
        }
    }
}

#[derive(Clone, Debug, PartialEq)]
pub enum Shape {
    Sphere(Sphere),
    Plane(Plane),
    Triangle(Triangle),
    // The rarer, larger shapes are boxed so that the common ones (triangles,
    // spheres) pack densely: `Shape` is 80 bytes instead of 144.
    Quadric(Box<Quadric>),
    Cone(Box<Cone>),
}

impl Shape {
    /// Closest hit with `0 < t < t_max`.
    #[inline(always)]
    pub fn intersect(&self, ray: &PreparedRay, t_max: f64) -> Option<ShapeHit> {
        match self {
            Shape::Sphere(s) => s.intersect(&ray.ray, t_max),
            Shape::Plane(p) => p.intersect(&ray.ray, t_max),
            Shape::Triangle(t) => t.intersect(ray, t_max),
            Shape::Quadric(q) => q.intersect(&ray.ray, t_max),
            Shape::Cone(c) => c.intersect(&ray.ray, t_max),
        }
    }

    /// The nearest hit with `0 < t < t_max` on the outside of the surface:
    /// a one-sided shape is invisible from behind (the SPD's rule for opaque
    /// primitives). The outside of a triangle is the side from which its
    /// vertices run counter-clockwise; of a quadric, where `F > 0`.
    #[inline(always)]
    pub fn intersect_front(&self, ray: &PreparedRay, t_max: f64) -> Option<ShapeHit> {
        let d = ray.ray.dir;
        let front = |outward: DVec3| d.dot(outward) < 0.0;
        match self {
            Shape::Triangle(t) => {
                let [a, b, c] = t.vertices;
                if !front((b - a).cross(c - a)) {
                    return None;
                }
                t.intersect(ray, t_max)
            }
            Shape::Plane(p) => {
                if !front(p.normal) {
                    return None;
                }
                p.intersect(&ray.ray, t_max)
            }
            _ => {
                let outward = |t: f64| {
                    let p = ray.ray.at(t);
                    match self {
                        Shape::Sphere(s) => p - s.center,
                        Shape::Quadric(q) => q.gradient(p),
                        Shape::Cone(c) => c.outward(p),
                        Shape::Triangle(_) | Shape::Plane(_) => DVec3::ZERO,
                    }
                };
                self.crossings(ray, t_max)
                    .as_slice()
                    .iter()
                    .copied()
                    .find(|&t| front(outward(t)))
                    .map(ShapeHit::at)
            }
        }
    }

    /// Every crossing of the surface with `0 < t < t_max`, nearest first:
    /// what a shadow ray needs to attenuate light once per surface crossed.
    #[inline(always)]
    pub fn crossings(&self, ray: &PreparedRay, t_max: f64) -> Crossings {
        match self {
            Shape::Sphere(s) => s.crossings(&ray.ray, t_max),
            Shape::Quadric(q) => q.crossings(&ray.ray, t_max),
            Shape::Cone(c) => c.crossings(&ray.ray, t_max),
            // Flat shapes are crossed at most once: the nearest hit is all.
            _ => {
                let mut out = Crossings::default();
                if let Some(hit) = self.intersect(ray, t_max) {
                    out.push(hit.t);
                }
                out
            }
        }
    }

    /// The surface point of a hit found by [`Shape::intersect`] with `ray`.
    #[inline(always)]
    pub fn surface(&self, ray: &Ray, hit: &ShapeHit, vertex_normals: &[[DVec3; 3]]) -> Surface {
        match self {
            Shape::Sphere(s) => s.surface(ray, hit),
            Shape::Plane(p) => p.surface(ray, hit),
            Shape::Triangle(t) => t.surface(hit, vertex_normals),
            Shape::Quadric(q) => q.surface(ray, hit),
            Shape::Cone(c) => c.surface(ray, hit),
        }
    }

    /// Bounding box, `None` for unbounded shapes (planes, unclipped quadrics).
    pub fn bounds(&self) -> Option<Aabb> {
        match self {
            Shape::Sphere(s) => Some(s.bounds()),
            Shape::Plane(_) => None,
            Shape::Triangle(t) => Some(t.bounds()),
            Shape::Quadric(q) => q.clip,
            Shape::Cone(c) => Some(c.bounds()),
        }
    }

    /// Whether the shape's surface may touch the closed box `b`: exact for
    /// triangles and spheres (a box inside a sphere does not touch its
    /// surface), by the enclosing capsule for cones, by bounding box
    /// otherwise. Never false when it does touch.
    pub fn overlaps_box(&self, b: &Aabb) -> bool {
        match self {
            Shape::Sphere(s) => s.overlaps_box(b),
            Shape::Triangle(t) => triangle_overlaps_box(&t.vertices, b),
            Shape::Cone(c) => c.overlaps_box(b),
            _ => self.bounds().is_none_or(|sb| sb.overlaps(b)),
        }
    }

    /// Whether the shape is a triangle shaded with vertex normals: a piece
    /// of a tessellated curved surface (NFF `pp`, smooth meshes).
    pub fn has_vertex_normals(&self) -> bool {
        matches!(self, Shape::Triangle(t) if t.vertex_normals != triangle::NO_NORMALS)
    }

    pub fn kind(&self) -> ShapeKind {
        match self {
            Shape::Sphere(_) => ShapeKind::Sphere,
            Shape::Plane(_) => ShapeKind::Plane,
            Shape::Triangle(_) => ShapeKind::Triangle,
            Shape::Quadric(_) => ShapeKind::Quadric,
            Shape::Cone(_) => ShapeKind::Cone,
        }
    }
}
