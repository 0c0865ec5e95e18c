//! What every shape's intersection test speaks: the prepared ray it takes,
//! the hit and crossings it returns and the surface a hit resolves to. A
//! file of its own so that the shapes and the [`Shape`](super::Shape) enum
//! over them all depend on it and not on each other.

use crate::math::{DVec3, Ray};

/// A ray prepared once for many intersection tests: the watertight triangle
/// test's shear constants (Woop, Benthin & Wald 2013) are computed here.
#[derive(Clone, Copy, Debug)]
pub struct PreparedRay {
    pub ray: Ray,
    /// Axis of the largest direction component, and the two others.
    pub(super) kx: usize,
    pub(super) ky: usize,
    pub(super) kz: usize,
    pub(super) shear: DVec3,
}

impl PreparedRay {
    pub fn new(ray: Ray) -> Self {
        let d = ray.dir;
        let a = d.abs();
        let kz = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        // Keep the winding of the projected triangle independent of the sign.
        if d[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let shear = DVec3::new(d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]);
        Self {
            ray,
            kx,
            ky,
            kz,
            shear,
        }
    }
}

/// The parameter of a hit and what the shape needs to rebuild the surface
/// point there (barycentric coordinates of vertices 1 and 2 for triangles).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ShapeHit {
    pub t: f64,
    pub b1: f64,
    pub b2: f64,
}

impl ShapeHit {
    pub(super) fn at(t: f64) -> Self {
        Self {
            t,
            b1: 0.0,
            b2: 0.0,
        }
    }
}

/// The parameters at which a ray crosses a shape's surface, nearest first:
/// at most two for the shapes glint has (a sphere, a quadric or a cone is
/// entered and left; a triangle or a plane is crossed once).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Crossings {
    pub(super) t: [f64; 2],
    pub(super) len: u8,
}

impl Crossings {
    /// Appends `t`, which must not be nearer than the last one.
    #[inline]
    pub(crate) fn push(&mut self, t: f64) {
        if (self.len as usize) < self.t.len() {
            self.t[self.len as usize] = t;
            self.len += 1;
        }
    }

    #[inline]
    pub fn as_slice(&self) -> &[f64] {
        &self.t[..self.len as usize]
    }
}

/// Where a ray met a surface.
#[derive(Clone, Copy, Debug)]
pub struct Surface {
    pub point: DVec3,
    /// Unit geometric normal, on the shape's outside (for triangles the side
    /// from which the vertices run counter-clockwise).
    pub geometric_normal: DVec3,
    /// Unit normal used for shading (interpolated on smooth meshes).
    pub shading_normal: DVec3,
}

/// The unit gradient direction, or `None` where it vanishes (a cone's apex).
pub(super) fn unit_or_none(v: DVec3) -> Option<DVec3> {
    let len = v.length();
    (len > 0.0 && len.is_finite()).then(|| v / len)
}
