//! Pinhole camera built from eye, lookat, up and a vertical field of view.

use crate::math::{DVec3, Ray};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraSpec {
    pub eye: DVec3,
    pub lookat: DVec3,
    pub up: DVec3,
    /// Vertical field of view in degrees, edge to edge of the image.
    pub fov: f64,
}

#[derive(Debug, thiserror::Error, PartialEq)]
pub enum CameraError {
    #[error("camera eye and lookat coincide: no view direction")]
    NoViewDirection,
    #[error("camera up vector is parallel to the view direction (or zero)")]
    UpParallelToView,
    #[error("camera fov must lie strictly between 0 and 180 degrees, got {0}")]
    FovOutOfRange(f64),
    #[error("image size must be at least 1x1, got {0}x{1}")]
    EmptyImage(u32, u32),
    #[error("camera values must be finite")]
    NotFinite,
}

/// A camera ready to generate rays for a `width` x `height` image.
///
/// `w` points from the scene back to the eye, `u` to the right of the image
/// and `v` up, so the view direction is `-w` (Shirley's convention).
#[derive(Clone, Copy, Debug)]
pub struct Camera {
    pub eye: DVec3,
    pub u: DVec3,
    pub v: DVec3,
    pub w: DVec3,
    width: u32,
    height: u32,
    /// Image-plane offset (at distance 1 along -w) of the top-left corner of
    /// the image, in units of u and v.
    left: f64,
    top: f64,
    pixel_size: f64,
}

impl CameraSpec {
    /// Why the spec cannot make a camera, with which of its keys is at
    /// fault (`eye`, `up` or `fov`), checked at load so errors can point
    /// into the scene file.
    pub fn check(&self) -> Result<(), (&'static str, String)> {
        let back = self.eye - self.lookat;
        let distance = back.length();
        if !distance.is_finite() {
            return Err((
                "eye",
                "eye and lookat are so far apart that their distance overflows".into(),
            ));
        }
        if !(distance > 0.0) {
            return Err(("eye", "eye and lookat coincide: no view direction".into()));
        }
        if !self.up.length().is_finite() {
            return Err(("up", "the up vector's length overflows".into()));
        }
        match Camera::new(self, 1, 1) {
            Err(CameraError::UpParallelToView) => Err((
                "up",
                "up is parallel to the view direction (or zero)".into(),
            )),
            Err(CameraError::FovOutOfRange(_)) => {
                Err(("fov", "must lie strictly between 0 and 180 degrees".into()))
            }
            Err(e) => Err(("eye", e.to_string())),
            Ok(_) => Ok(()),
        }
    }
}

impl Camera {
    pub fn new(spec: &CameraSpec, width: u32, height: u32) -> Result<Self, CameraError> {
        if !(spec.eye.is_finite()
            && spec.lookat.is_finite()
            && spec.up.is_finite()
            && spec.fov.is_finite())
        {
            return Err(CameraError::NotFinite);
        }
        if width == 0 || height == 0 {
            return Err(CameraError::EmptyImage(width, height));
        }
        if !(spec.fov > 0.0 && spec.fov < 180.0) {
            return Err(CameraError::FovOutOfRange(spec.fov));
        }
        let back = spec.eye - spec.lookat;
        let back_len = back.length();
        if !(back_len > 0.0) || !back_len.is_finite() {
            return Err(CameraError::NoViewDirection);
        }
        let w = back / back_len;
        let up_len = spec.up.length();
        if !(up_len > 0.0 && up_len.is_finite()) {
            return Err(CameraError::UpParallelToView);
        }
        let side = (spec.up / up_len).cross(w);
        // Relative to unit vectors: below this the basis is numerically meaningless.
        if side.length() < 1e-9 {
            return Err(CameraError::UpParallelToView);
        }
        let u = side.normalize();
        let v = w.cross(u);
        let half_height = (spec.fov.to_radians() * 0.5).tan();
        let pixel_size = 2.0 * half_height / height as f64;
        let half_width = pixel_size * width as f64 * 0.5;
        Ok(Self {
            eye: spec.eye,
            u,
            v,
            w,
            width,
            height,
            left: -half_width,
            top: half_height,
            pixel_size,
        })
    }

    pub fn width(&self) -> u32 {
        self.width
    }

    pub fn height(&self) -> u32 {
        self.height
    }

    /// Ray through pixel column `i`, row `j` (row 0 at the top), at offset
    /// `(dx, dy)` in `[0, 1)^2` from the pixel's top-left corner.
    pub fn ray(&self, i: u32, j: u32, dx: f64, dy: f64) -> Ray {
        let x = self.left + (i as f64 + dx) * self.pixel_size;
        let y = self.top - (j as f64 + dy) * self.pixel_size;
        let dir = (x * self.u + y * self.v - self.w).normalize();
        Ray::new(self.eye, dir)
    }
}

impl Camera {
    /// Depth of `p` along the view direction (positive in front of the eye).
    pub fn view_depth(&self, p: DVec3) -> f64 {
        -(p - self.eye).dot(self.w)
    }

    /// The image plane at distance 1 along the view: its top-left corner's
    /// offsets along `u` and `v` and a pixel's size, so that a direction
    /// `d` ahead of the eye shows at `((d.u / z - left) / size, (top - d.v
    /// / z) / size)` with `z = -d.w` ([`Camera::project_direction`], for
    /// callers that project many points with their own arithmetic).
    pub fn image_plane(&self) -> (f64, f64, f64) {
        (self.left, self.top, self.pixel_size)
    }

    /// Continuous image coordinates of `p` (pixels, x to the right, y down
    /// from the top-left corner), for points with positive view depth.
    pub fn project(&self, p: DVec3) -> Option<(f64, f64)> {
        self.project_direction(p - self.eye)
    }

    /// Continuous image coordinates of the point at infinity in direction
    /// `d` (where a ray leaving the scene that way is seen), for directions
    /// ahead of the eye; also of the point `eye + d`.
    pub fn project_direction(&self, d: DVec3) -> Option<(f64, f64)> {
        let z = -d.dot(self.w);
        if !(z > 0.0) {
            return None;
        }
        let (x, y) = (d.dot(self.u) / z, d.dot(self.v) / z);
        Some((
            (x - self.left) / self.pixel_size,
            (self.top - y) / self.pixel_size,
        ))
    }
}

/// Sub-pixel offsets for `samples` rays per pixel: the centre for 1, a regular
/// `k x k` grid at `(a + 0.5) / k` for `k^2` samples (4x4 for 16).
pub fn sample_offsets(samples: u32) -> Vec<(f64, f64)> {
    let k = (samples as f64).sqrt().round().max(1.0) as u32;
    let mut offsets = Vec::with_capacity((k * k) as usize);
    for b in 0..k {
        for a in 0..k {
            offsets.push(((a as f64 + 0.5) / k as f64, (b as f64 + 0.5) / k as f64));
        }
    }
    offsets
}

#[cfg(test)]
mod tests {
    use super::*;

    fn spec() -> CameraSpec {
        CameraSpec {
            eye: DVec3::new(0.0, 0.0, 5.0),
            lookat: DVec3::ZERO,
            up: DVec3::Y,
            fov: 90.0,
        }
    }

    #[test]
    fn centre_ray_looks_at_lookat() {
        let cam = Camera::new(&spec(), 2, 2).unwrap();
        // The image centre is the shared corner of the four pixels.
        let ray = cam.ray(1, 1, 0.0, 0.0);
        assert!((ray.dir - DVec3::new(0.0, 0.0, -1.0)).length() < 1e-15);
        let odd = Camera::new(&spec(), 3, 3).unwrap().ray(1, 1, 0.5, 0.5);
        assert!((odd.dir - DVec3::new(0.0, 0.0, -1.0)).length() < 1e-15);
    }

    #[test]
    fn corner_rays_span_the_field_of_view() {
        let cam = Camera::new(&spec(), 4, 2).unwrap();
        // fov 90: the top edge is at 45 degrees; aspect 2: the left edge at atan(2).
        let top_left = cam.ray(0, 0, 0.0, 0.0).dir;
        let expected = DVec3::new(-2.0, 1.0, -1.0).normalize();
        assert!((top_left - expected).length() < 1e-15, "{top_left}");
        let bottom_right = cam.ray(3, 1, 1.0, 1.0).dir;
        assert!((bottom_right - DVec3::new(2.0, -1.0, -1.0).normalize()).length() < 1e-15);
    }

    #[test]
    fn basis_is_orthonormal_with_non_perpendicular_up() {
        let mut s = spec();
        s.eye = DVec3::new(3.0, 4.0, 5.0);
        s.up = DVec3::new(0.2, 1.0, 0.3);
        let cam = Camera::new(&s, 10, 10).unwrap();
        for (a, b) in [(cam.u, cam.v), (cam.v, cam.w), (cam.w, cam.u)] {
            assert!(a.dot(b).abs() < 1e-14);
        }
        for a in [cam.u, cam.v, cam.w] {
            assert!((a.length() - 1.0).abs() < 1e-14);
        }
        assert!(cam.v.dot(s.up) > 0.0, "v keeps the side of up");
        assert!(cam.u.cross(cam.v).dot(cam.w) > 0.0, "right-handed");
    }

    #[test]
    fn invalid_cameras_are_errors() {
        let mut s = spec();
        s.up = DVec3::new(0.0, 0.0, 2.0);
        assert_eq!(
            Camera::new(&s, 4, 4).unwrap_err(),
            CameraError::UpParallelToView
        );
        for fov in [0.0, 180.0, -5.0, 200.0, f64::NAN] {
            s = spec();
            s.fov = fov;
            assert!(Camera::new(&s, 4, 4).is_err(), "fov {fov}");
        }
        assert_eq!(
            Camera::new(&spec(), 0, 4).unwrap_err(),
            CameraError::EmptyImage(0, 4)
        );
        s = spec();
        s.lookat = s.eye;
        assert_eq!(
            Camera::new(&s, 4, 4).unwrap_err(),
            CameraError::NoViewDirection
        );
    }

    #[test]
    fn sixteen_samples_form_a_regular_grid() {
        let offsets = sample_offsets(16);
        assert_eq!(offsets.len(), 16);
        assert_eq!(offsets[0], (0.125, 0.125));
        assert_eq!(offsets[15], (0.875, 0.875));
        assert_eq!(sample_offsets(1), vec![(0.5, 0.5)]);
    }
}
