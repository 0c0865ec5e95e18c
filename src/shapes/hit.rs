//! What every shape's intersection test speaks: the prepared ray it takes,
//! the hit and crossings it returns and the surface a hit resolves to. A
//! file of its own so that the shapes and the [`Shape`](super::Shape) enum
//! over them all depend on it and not on each other.

use crate::math::{Aabb, DVec3, Ray};

/// Runs `$body` with the axes `(KX, KY, KZ)` of the watertight test's
/// permutation `$permutation` bound as constants (a vector indexed by a
/// variable costs a match per access): `KZ` the dominant axis, the others
/// in cyclic order, swapped when the dominant component is negative. The
/// one table of the six permutations, for the single ray's and the
/// packet's shear and triangle tests alike.
macro_rules! along_axes {
    ($permutation:expr, |$kx:ident, $ky:ident, $kz:ident| $body:expr) => {
        match $permutation {
            0 => along_axes!(@bind 1, 2, 0, $kx, $ky, $kz, $body),
            1 => along_axes!(@bind 2, 1, 0, $kx, $ky, $kz, $body),
            2 => along_axes!(@bind 2, 0, 1, $kx, $ky, $kz, $body),
            3 => along_axes!(@bind 0, 2, 1, $kx, $ky, $kz, $body),
            4 => along_axes!(@bind 0, 1, 2, $kx, $ky, $kz, $body),
            _ => along_axes!(@bind 1, 0, 2, $kx, $ky, $kz, $body),
        }
    };
    (@bind $x:literal, $y:literal, $z:literal, $kx:ident, $ky:ident, $kz:ident, $body:expr) => {{
        const $kx: usize = $x;
        const $ky: usize = $y;
        const $kz: usize = $z;
        $body
    }};
}
pub(crate) use along_axes;

/// The closest-hit tie rule: a hit at `t` on shape `index` beats the best
/// so far (`best_t`, `best_index`) if it is closer, or as close on a lower
/// index, so the answer never depends on the order of the tests (single
/// rays and packets, octree and brute force, give the same shape).
#[inline(always)]
pub fn wins(t: f64, index: u32, best_t: f64, best_index: u32) -> bool {
    t < best_t || (t == best_t && index < best_index)
}

/// The exclusive limit that lets a hit tie with one at `t` (the smallest
/// `f64` above a finite, non-negative `t`), so [`wins`] can see the tie.
#[inline(always)]
pub fn probe_past(t: f64) -> f64 {
    if t.is_finite() {
        f64::from_bits(t.to_bits() + 1)
    } else {
        t
    }
}

/// A ray prepared once for every query it takes part in: the octree walk's
/// reciprocal direction and sign bits, and the watertight triangle test's
/// axis permutation and shear constants (Woop, Benthin & Wald 2013).
#[derive(Clone, Copy, Debug)]
pub struct PreparedRay {
    pub ray: Ray,
    /// `1 / dir` per axis, and 0 where a component is too small to invert:
    /// the walk then treats the ray as parallel to that axis's planes,
    /// which moves it by less than the cells' padding over any finite
    /// distance.
    pub inv_dir: [f64; 3],
    /// Bit `k`: the direction's component `k` is negative (components
    /// treated as parallel count as positive).
    pub negative: u32,
    /// Bit `k`: component `k` is treated as parallel (see `inv_dir`).
    pub parallel: u32,
    /// Axis of the largest direction component, and the two others, as
    /// one of six permutations (see [`PreparedRay::axes`]).
    pub(super) permutation: u8,
    pub(super) shear: DVec3,
}

impl PreparedRay {
    pub fn new(ray: Ray) -> Self {
        let d = ray.dir;
        let permutation = Self::permutation_of(d);
        let shear = along_axes!(permutation, |KX, KY, KZ| {
            DVec3::new(d[KX] / d[KZ], d[KY] / d[KZ], 1.0 / d[KZ])
        });
        let d = d.to_array();
        let mut inv_dir = [0.0; 3];
        let (mut negative, mut parallel) = (0, 0);
        for k in 0..3 {
            let inv = 1.0 / d[k];
            if inv.is_finite() {
                inv_dir[k] = inv;
                negative |= ((d[k] < 0.0) as u32) << k;
            } else {
                parallel |= 1 << k;
            }
        }
        Self {
            ray,
            inv_dir,
            negative,
            parallel,
            permutation,
            shear,
        }
    }

    /// The ray's parameter range inside the box `bounds`, within
    /// `[0, t_max]`, or `None` if it misses: the slab test (Kay & Kajiya
    /// 1986), each far parameter passed through `widen_far` (the identity,
    /// or a margin for boxes stored in lower precision), and components
    /// treated as parallel (`parallel`) tested as inside their slab or not.
    /// The octree's root and the BVH's nodes use it.
    #[inline(always)]
    pub fn box_range(
        &self,
        bounds: &Aabb,
        t_max: f64,
        widen_far: impl Fn(f64) -> f64,
    ) -> Option<(f64, f64)> {
        let (lo, hi) = (bounds.min.to_array(), bounds.max.to_array());
        let o = self.ray.origin.to_array();
        let (mut t0, mut t1) = (0.0f64, t_max);
        for k in 0..3 {
            if self.parallel >> k & 1 == 1 {
                if o[k] < lo[k] || o[k] > hi[k] {
                    return None;
                }
                continue;
            }
            let inv = self.inv_dir[k];
            let (mut near, mut far) = ((lo[k] - o[k]) * inv, (hi[k] - o[k]) * inv);
            if near > far {
                std::mem::swap(&mut near, &mut far);
            }
            t0 = t0.max(near);
            t1 = t1.min(widen_far(far));
        }
        (t0 <= t1).then_some((t0, t1))
    }

    /// The dominant axis of `d`, and whether the direction is negative
    /// along it: one of six permutations, each with constant axes (a
    /// vector indexed by a variable costs a match per access).
    #[inline(always)]
    pub(super) fn permutation_of(d: DVec3) -> u8 {
        let a = d.abs();
        if a.x >= a.y && a.x >= a.z {
            (d.x < 0.0) as u8
        } else if a.y >= a.z {
            2 + (d.y < 0.0) as u8
        } else {
            4 + (d.z < 0.0) as u8
        }
    }

    /// The direction's dominant axis and its components along the next two
    /// axes in cyclic order over the dominant one's magnitude: where it
    /// meets a cube of directions, read off the watertight test's shear
    /// without a division (bit for bit those quotients: dividing by the
    /// negated component only flips the sign).
    #[inline(always)]
    pub fn cube_face(&self) -> (usize, f64, f64) {
        let major = (self.permutation / 2) as usize;
        // Up the dominant axis the shear holds the next axis then the one
        // after; down it, the two swapped, over a negative component.
        if self.permutation & 1 == 0 {
            (major, self.shear.x, self.shear.y)
        } else {
            (major, -self.shear.y, -self.shear.x)
        }
    }

    /// The permutation's axes `(kx, ky, kz)`: `kz` the dominant one, the
    /// others in cyclic order, swapped when the dominant component is
    /// negative.
    #[cfg(test)]
    pub(super) fn axes_of(permutation: u8) -> (usize, usize, usize) {
        along_axes!(permutation, |KX, KY, KZ| (KX, KY, KZ))
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

/// `v` as a unit vector, or `None` where it has no direction (zero, or not
/// finite): a gradient that vanishes (a cone's apex), or a vertex normal
/// given as zero. A vector whose squared length over- or underflows (1e200
/// or 1e-200 long) is scaled by its largest component first, so it keeps
/// its direction.
pub(crate) fn unit_or_none(v: DVec3) -> Option<DVec3> {
    let length_squared = v.length_squared();
    if length_squared.is_normal() {
        return Some(v / length_squared.sqrt());
    }
    let largest = v.abs().max_element();
    if !(largest > 0.0 && largest.is_finite()) {
        return None;
    }
    let v = v / largest;
    let len = v.length();
    (len > 0.0 && len.is_finite()).then(|| v / len)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn unit_or_none_keeps_the_direction_of_tiny_and_huge_vectors() {
        let expected = DVec3::new(3.0, -4.0, 0.0) / 5.0;
        for scale in [1e-300, 1e-200, 1e-160, 1e-3, 1.0, 1e3, 1e160, 1e200, 1e300] {
            let n = unit_or_none(DVec3::new(3.0, -4.0, 0.0) * scale)
                .unwrap_or_else(|| panic!("no direction at scale {scale}"));
            assert!((n - expected).length() < 1e-15, "scale {scale}: {n}");
        }
        for v in [
            DVec3::ZERO,
            DVec3::new(f64::NAN, 1.0, 0.0),
            DVec3::new(f64::INFINITY, 1.0, 0.0),
        ] {
            assert_eq!(unit_or_none(v), None, "{v}");
        }
    }

    #[test]
    fn each_permutation_is_woops_axes_and_shear() {
        // Woop et al.: kz the largest |d|, kx and ky the next ones in
        // cyclic order, swapped when d[kz] < 0; shear (dx/dz, dy/dz, 1/dz).
        for d in [
            DVec3::new(3.0, 1.0, -2.0),
            DVec3::new(-3.0, 1.0, 2.0),
            DVec3::new(0.5, 2.0, 1.0),
            DVec3::new(0.5, -2.0, 1.0),
            DVec3::new(0.25, 1.0, 3.0),
            DVec3::new(0.25, 1.0, -3.0),
            DVec3::new(1.0, 1.0, 1.0),
        ] {
            let r = PreparedRay::new(Ray::new(DVec3::ZERO, d));
            let a = d.abs();
            let kz = if a.x >= a.y && a.x >= a.z {
                0
            } else if a.y >= a.z {
                1
            } else {
                2
            };
            let (mut kx, mut ky) = ((kz + 1) % 3, (kz + 2) % 3);
            if d[kz] < 0.0 {
                std::mem::swap(&mut kx, &mut ky);
            }
            assert_eq!(PreparedRay::axes_of(r.permutation), (kx, ky, kz), "{d}");
            let shear = DVec3::new(d[kx] / d[kz], d[ky] / d[kz], 1.0 / d[kz]);
            assert_eq!(r.shear, shear, "{d}");
        }
    }
}
