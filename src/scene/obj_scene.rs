//! An `.obj` opened directly: glint writes the TOML scene around it (the
//! model with its own MTL materials, a camera that frames it, one light over
//! the camera's shoulder) and loads that. The written text is the scene's
//! source, so an export records it and re-renders the same picture.

use std::path::Path;

use crate::camera::CameraSpec;
use crate::math::{Aabb, DVec3};

use super::file_source::FileSource;
use super::model::{Scene, SceneError};
use super::toml_format;

/// Vertical field of view of the framing camera, degrees.
const FOV: f64 = 40.0;

/// The TOML scene around the OBJ file `path`, with `camera` and the light
/// at `light`.
fn wrapper_text(path: &Path, camera: &CameraSpec, light: DVec3) -> String {
    let file = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let quoted = toml::Value::String(file.clone()).to_string();
    // `{:?}` writes 1e300 as `1e300` (TOML reads it back as the same
    // double), where `{}` would write 301 digits TOML takes for an integer.
    let v = |p: DVec3| format!("[{:?}, {:?}, {:?}]", p.x, p.y, p.z);
    format!(
        "# The scene glint writes around {file} when it is opened directly: the\n\
         # model in its own materials, a camera that frames it, one light over\n\
         # the camera's shoulder. Save it as .toml to change any of it.\n\
         \n\
         [camera]\n\
         eye = {}\n\
         lookat = {}\n\
         up = {}\n\
         fov = {}\n\
         \n\
         [image]\n\
         width = 640\n\
         height = 480\n\
         samples = 16\n\
         max_depth = 5\n\
         background = [0.05, 0.05, 0.05]\n\
         ambient = [0.1, 0.1, 0.1]\n\
         \n\
         [[lights]]\n\
         position = {}\n\
         color = [1, 1, 1]\n\
         \n\
         [[objects]]\n\
         kind = \"mesh\"\n\
         path = {quoted}\n",
        v(camera.eye),
        v(camera.lookat),
        v(camera.up),
        camera.fov,
        v(light),
    )
}

/// Loads the OBJ file `path` as a scene of its own.
pub(super) fn load(path: &Path, files: &dyn FileSource) -> Result<Scene, SceneError> {
    // Parse once with a provisional camera, then frame the bounds.
    let provisional = CameraSpec {
        eye: DVec3::Z,
        lookat: DVec3::ZERO,
        up: DVec3::Y,
        fov: FOV,
    };
    let text = wrapper_text(path, &provisional, DVec3::Y);
    // The written scene is correct by construction: any error is the
    // model's, and is told as the model's, not as a place in that text.
    let mut scene = toml_format::parse(&text, path, files).map_err(|e| match e {
        SceneError::Mesh { mesh, message, .. } => SceneError::Model {
            path: mesh,
            message,
        },
        other => other,
    })?;
    let (camera, light) = frame(scene.geometry_bounds()).ok_or_else(|| SceneError::Model {
        path: path.to_owned(),
        message: "the model's coordinates are too large to frame with a camera \
                  (the camera's distance from it would overflow a double)"
            .into(),
    })?;
    let text = wrapper_text(path, &camera, light);
    scene.camera = camera;
    if let Some(l) = scene.lights.first_mut() {
        l.position = light;
    }
    scene.source_text = std::sync::Arc::from(text.as_str());
    Ok(scene)
}

/// A camera that frames `bounds` and a light over its shoulder: seen from
/// the front (+z, the usual forward of OBJ exports) a little from above,
/// unless the model is far thinner along x or y: then from its broad side
/// (+x), or from above (a floor or a terrain flat in y), never edge-on (a
/// model in a plane containing the z axis showed nothing). Far enough
/// that the bounding sphere fits the view. `None` if that place
/// is not a finite number (a model reaching 1e300), or so far that the
/// camera's own length computations overflow (a model 1e154 across).
fn frame(bounds: Aabb) -> Option<(CameraSpec, DVec3)> {
    // A model with no faces (only lines or points): the unit box.
    let bounds = if bounds.is_empty() {
        Aabb::new(DVec3::splat(-1.0), DVec3::splat(1.0))
    } else {
        bounds
    };
    // Halves first: min + max overflows for a model spanning 1e308.
    let center = 0.5 * bounds.min + 0.5 * bounds.max;
    let extent = bounds.max - bounds.min;
    let largest = extent.max_element();
    // Scaled, so the squares of a 1e200 model do not overflow.
    let radius = if largest > 0.0 {
        0.5 * largest * (extent / largest).length()
    } else {
        0.0
    };
    // A point model, or one far smaller than its distance from the origin,
    // still needs an eye apart from the lookat point.
    let radius = radius.max(center.abs().max_element() * 1e-9).max(1e-150);
    let direction = view_direction(extent);
    let distance = radius / (0.5 * FOV.to_radians()).sin() * 1.05;
    let camera = CameraSpec {
        eye: center + direction * distance,
        lookat: center,
        up: DVec3::Y,
        fov: FOV,
    };
    let light = center + DVec3::new(-0.5, 1.0, 0.8).normalize() * (distance * 1.5);
    (camera.eye.is_finite() && light.is_finite() && camera.check().is_ok())
        .then_some((camera, light))
}

/// Where the camera looks from, seen from the model: +z a little from
/// above, unless x or y is under half of z's extent (the model's broad
/// side then faces that axis). OBJ's up is +y, so a model flat in y is
/// seen steeply from above rather than straight down the up vector.
fn view_direction(extent: DVec3) -> DVec3 {
    let thin = |axis: f64| axis < 0.5 * extent.z;
    let direction = if thin(extent.x) && extent.x <= extent.y {
        DVec3::new(1.0, 0.25, 0.0)
    } else if thin(extent.y) {
        DVec3::new(0.0, 1.0, 0.6)
    } else {
        DVec3::new(0.0, 0.25, 1.0)
    };
    direction.normalize()
}

/// Parses `text`, the TOML an OBJ file `path` was opened with (an
/// export's record), as that scene again.
pub(super) fn reload(text: &str, path: &Path, files: &dyn FileSource) -> Result<Scene, SceneError> {
    toml_format::parse(text, path, files)
}

#[cfg(test)]
mod tests {
    use super::*;

    struct Files;
    impl FileSource for Files {
        fn read(&self, path: &Path) -> std::io::Result<Vec<u8>> {
            match path.file_name().and_then(|n| n.to_str()) {
                Some("two.obj") => Ok(b"mtllib two.mtl\nv 10 0 0\nv 12 0 0\nv 12 2 0\nv 10 2 0\nusemtl red\nf 1 2 3\nusemtl blue\nf 1 3 4\n".to_vec()),
                Some("two.mtl") => Ok(b"newmtl red\nKd 1 0 0\nnewmtl blue\nKd 0 0 1\n".to_vec()),
                _ => Err(std::io::ErrorKind::NotFound.into()),
            }
        }
    }

    #[test]
    fn an_obj_is_framed_and_its_text_loads_it_again() {
        let path = Path::new("models/two.obj");
        let scene = load(path, &Files).unwrap();
        assert_eq!(scene.camera.lookat, DVec3::new(11.0, 1.0, 0.0));
        let names: Vec<&str> = scene.materials.iter().map(|m| m.name.as_str()).collect();
        assert_eq!(names, ["red", "blue"]);
        assert_eq!(*scene.shape_materials, [0, 1]);
        let again = reload(&scene.source_text, path, &Files).unwrap();
        assert_eq!(again.camera, scene.camera);
        assert_eq!(again.lights, scene.lights);
        assert_eq!(again.materials, scene.materials);
    }

    /// Found by `tests/integration/round_trip.rs`: models the framing overflowed wrote
    /// `NaN` (or 301-digit integers) into the scene text, which then did
    /// not load again.
    #[test]
    fn extreme_models_are_framed_with_finite_numbers_or_refused() {
        struct One(&'static [u8]);
        impl FileSource for One {
            fn read(&self, _: &Path) -> std::io::Result<Vec<u8>> {
                Ok(self.0.to_vec())
            }
        }
        let path = Path::new("m.obj");
        // Each beside a face of ordinary size: a model with no face that
        // has an area is refused (below).
        let small = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 4 5 6\n";
        for model in [
            "v 1e300 0 0\nv 0 1e300 0\nv 0 0 1e300\nf 1 2 3\n",
            "v -1e200 0 0\nv 1e200 0 0\nv 0 1e200 0\nf 1 2 3\n",
            "v 1e6 0 0\nv 1e6 1e-9 0\nv 1e6 0 1e-9\nf 1 2 3\n",
        ] {
            let model: &'static [u8] = format!("{model}{small}").leak().as_bytes();
            let scene = load(path, &One(model)).unwrap();
            assert!(scene.camera.eye.is_finite() && scene.camera.eye != scene.camera.lookat);
            let again = reload(&scene.source_text, path, &One(model)).unwrap();
            assert_eq!(again.camera, scene.camera);
            assert_eq!(again.lights, scene.lights);
        }
        // A model whose only face's area overflows has no face to show:
        // refused like one without faces.
        let e = load(
            path,
            &One(b"v 0 0 0\nv 1.5e308 0 0\nv 0 1.5e308 0\nf 1 2 3\n"),
        )
        .unwrap_err();
        assert!(e.to_string().contains("no face with an area"), "{e}");
        // Bounds the camera would have to stand beyond the largest double
        // to see (no triangle reaches them: a face this size overflows its
        // area and is dropped at load).
        assert!(frame(Aabb::new(DVec3::ZERO, DVec3::splat(1.5e308))).is_none());
        // A face 1e154 across keeps a finite area, but a camera that sees
        // it stands where eye - lookat has no finite length: refused with
        // the reason, not written as a scene that cannot load again (found
        // by the round-trip property test).
        let e = load(
            path,
            &One(b"v 0 0 0\nv 0 -8.8e153 0\nv 0 0 1e154\nf 1 2 3\n"),
        )
        .unwrap_err();
        assert!(e.to_string().contains("too large to frame"), "{e}");
    }
}
