//! Camera moves driven by the mouse: orbit about lookat, pan, dolly.

use crate::camera::CameraSpec;
use crate::math::DVec3;

/// Elevation limit in radians: the camera stops short of the poles, where
/// `up` would become parallel to the view direction and the image flip.
const MAX_ELEVATION: f64 = 89.0 * std::f64::consts::PI / 180.0;

/// Rotates the eye about `lookat`: `azimuth` about the up axis, `elevation`
/// towards it, both in radians; the elevation is clamped below the poles.
pub fn orbit(camera: &CameraSpec, azimuth: f64, elevation: f64) -> CameraSpec {
    let axis = camera.up.normalize_or_zero();
    let offset = camera.eye - camera.lookat;
    let radius = offset.length();
    if axis == DVec3::ZERO || !(radius > 0.0) {
        return *camera;
    }
    let height = offset.dot(axis);
    let mut horizontal = offset - height * axis;
    if horizontal.length_squared() <= (radius * 1e-12).powi(2) {
        // At a pole: any horizontal direction will do.
        horizontal = crate::math::orthonormal_basis(axis).0;
    }
    let horizontal = horizontal.normalize();
    let current = (height / radius).clamp(-1.0, 1.0).asin();
    let new_elevation = (current + elevation).clamp(-MAX_ELEVATION, MAX_ELEVATION);
    let (s, c) = azimuth.sin_cos();
    // Rodrigues' rotation of a vector perpendicular to the axis.
    let rotated = horizontal * c + axis.cross(horizontal) * s;
    let eye = camera.lookat + radius * (new_elevation.cos() * rotated + new_elevation.sin() * axis);
    CameraSpec { eye, ..*camera }
}

/// Moves eye and lookat together in the image plane; `dx`, `dy` in pixels
/// of an image `height_px` tall, so the scene follows the pointer at lookat.
pub fn pan(camera: &CameraSpec, dx: f64, dy: f64, height_px: f64) -> CameraSpec {
    let back = camera.eye - camera.lookat;
    let distance = back.length();
    let w = back.normalize_or_zero();
    let u = camera.up.cross(w).normalize_or_zero();
    let v = w.cross(u);
    let per_pixel = 2.0 * distance * (camera.fov.to_radians() * 0.5).tan() / height_px.max(1.0);
    let shift = (-dx * u + dy * v) * per_pixel;
    if !shift.is_finite() {
        return *camera;
    }
    CameraSpec {
        eye: camera.eye + shift,
        lookat: camera.lookat + shift,
        ..*camera
    }
}

/// Moves the eye towards lookat by the factor `exp(-amount)`, never onto it.
pub fn dolly(camera: &CameraSpec, amount: f64) -> CameraSpec {
    let offset = camera.eye - camera.lookat;
    let scaled = offset * (-amount).exp().clamp(0.01, 100.0);
    if scaled.length() < 1e-9 * (1.0 + camera.lookat.length()) || !scaled.is_finite() {
        return *camera;
    }
    CameraSpec {
        eye: camera.lookat + scaled,
        ..*camera
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cam() -> CameraSpec {
        CameraSpec {
            eye: DVec3::new(0.0, 1.0, 5.0),
            lookat: DVec3::new(0.0, 1.0, 0.0),
            up: DVec3::Y,
            fov: 40.0,
        }
    }

    #[test]
    fn orbit_keeps_distance_and_never_passes_the_pole() {
        let mut c = cam();
        for _ in 0..100 {
            c = orbit(&c, 0.1, 0.1);
            assert!(((c.eye - c.lookat).length() - 5.0).abs() < 1e-9);
            let elevation = ((c.eye - c.lookat).normalize().dot(DVec3::Y)).asin();
            assert!(elevation <= MAX_ELEVATION + 1e-9);
            assert!(
                crate::camera::Camera::new(&c, 4, 4).is_ok(),
                "camera stays valid at the pole"
            );
        }
    }

    #[test]
    fn quarter_turn_azimuth() {
        let c = orbit(&cam(), std::f64::consts::FRAC_PI_2, 0.0);
        assert!(
            (c.eye - DVec3::new(5.0, 1.0, 0.0)).length() < 1e-9,
            "{}",
            c.eye
        );
    }

    #[test]
    fn pan_moves_both_and_dolly_keeps_direction() {
        let c = pan(&cam(), 10.0, 0.0, 100.0);
        assert!(c.eye.x < 0.0 && (c.eye - c.lookat - (cam().eye - cam().lookat)).length() < 1e-12);
        let d = dolly(&cam(), 0.5);
        assert!(((d.eye - d.lookat).length() - 5.0 * (-0.5f64).exp()).abs() < 1e-12);
    }
}
