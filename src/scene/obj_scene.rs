//! An `.obj` opened directly: glint writes the TOML scene around it (the
//! model with its own MTL materials, a camera that frames it, one light over
//! the camera's shoulder) and loads that. The written text is the scene's
//! source, so an export records it and re-renders the same picture.

use std::path::Path;

use crate::accel::WalkStack;
use crate::camera::{Camera, CameraSpec};
use crate::math::{Aabb, DVec3};

use super::file_source::FileSource;
use super::interior_view::interior_view;
use super::model::{Scene, SceneError};
use super::model_axes::{ModelAxes, model_axes};
use super::model_probe::ModelProbe;
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
    let bounds = scene.geometry_bounds();
    let header = scene.meshes.first().and_then(|m| m.header.as_deref());
    let axes = model_axes(&scene.shapes, bounds, header);
    // A model with no faces (only lines or points): the unit box.
    let bounds = if bounds.is_empty() {
        Aabb::new(DVec3::splat(-1.0), DVec3::splat(1.0))
    } else {
        bounds
    };
    let too_large = || SceneError::Model {
        path: path.to_owned(),
        message: "the model's coordinates are too large to frame with a camera \
                  (the camera's distance from it would overflow a double)"
            .into(),
    };
    let direction = view_direction(bounds.max - bounds.min, axes);
    let (mut camera, mut light) = frame(bounds, axes, direction).ok_or_else(too_large)?;
    let probe = ModelProbe::new(&scene.shapes, &scene.vertex_normals);
    if let Some(probe) = &probe {
        if let Some(inside) = interior_view(probe, bounds, axes.up, [axes.side, axes.front])
            && shows_more(probe, &inside.0, &camera)
        {
            // An enclosed model: its shell hides what it was made for.
            (camera, light) = inside;
        } else {
            // The view from behind, from the other side, or from both,
            // when one shows clearly more of the model than the front: its
            // features rather than a flat back, the inside of a box or of a
            // room's corner open on that side, a face rather than the back
            // of a head. The one that shows most, the first of equals.
            let front = direction.dot(axes.front.abs()) * axes.front.abs();
            let side = direction.dot(axes.side.abs()) * axes.side.abs();
            let mut best = (structure_seen(probe, &camera), None);
            let least = best.0 * 5 / 4 + 1;
            for turned in [
                direction - 2.0 * front - 2.0 * side,
                direction - 2.0 * front,
                direction - 2.0 * side,
            ] {
                if let Some(view) = frame(bounds, axes, turned) {
                    let seen = structure_seen(probe, &view.0);
                    if seen > least && seen > best.0 {
                        best = (seen, Some(view));
                    }
                }
            }
            if let (_, Some(view)) = best {
                (camera, light) = view;
            }
        }
    }
    let text = wrapper_text(path, &camera, light);
    scene.camera = camera;
    if let Some(l) = scene.lights.first_mut() {
        l.position = light;
    }
    scene.source_text = std::sync::Arc::from(text.as_str());
    Ok(scene)
}

/// A camera that frames `bounds` and a light over its shoulder, seen from
/// `direction` (`view_direction`: the model's broad side a little from
/// above), with the up axis the model suggests (`model_axes`). Far enough that the bounding
/// sphere fits the view. `None` if that place is not a finite number (a
/// model reaching 1e300), or so far that the camera's own length
/// computations overflow (a model 1e154 across).
fn frame(bounds: Aabb, axes: ModelAxes, direction: DVec3) -> Option<(CameraSpec, DVec3)> {
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
    let distance = radius / (0.5 * FOV.to_radians()).sin() * 1.05;
    let camera = CameraSpec {
        eye: center + direction * distance,
        lookat: center,
        up: axes.up,
        fov: FOV,
    };
    // Over the camera's left shoulder, whichever side it looks from.
    let right = axes.up.cross(direction).normalize();
    let over_shoulder = (direction * 0.8 + axes.up - right * 0.5).normalize();
    let light = center + over_shoulder * (distance * 1.5);
    (camera.eye.is_finite() && light.is_finite() && camera.check().is_ok())
        .then_some((camera, light))
}

/// Where the camera looks from, seen from the model: its broad side, a
/// little off square (so depth shows) and a little from above. The front
/// is that side unless the model is clearly broader seen from the side (a
/// car or a cow modelled facing the front would show its nose or its
/// tail). A model flat across its up axis (a floor, a terrain, a city
/// plan) is seen from higher up, never edge-on; a flat sheet standing
/// upright is seen square on.
fn view_direction(extent: DVec3, axes: ModelAxes) -> DVec3 {
    let along = |axis: DVec3| extent.dot(axis.abs());
    let (side, up, front) = (along(axes.side), along(axes.up), along(axes.front));
    // A sheet (a cut-out, a drawing, a single face) facing the camera is
    // seen square on: off square it only shrinks.
    let off_square = |depth: f64| {
        if depth < 0.05 * extent.max_element() {
            0.0
        } else {
            1.0
        }
    };
    let direction = if up < 0.5 * side.min(front) {
        axes.front + 0.3 * axes.side + 0.8 * axes.up
    } else if side < 0.8 * front {
        axes.side + off_square(side) * (0.35 * axes.front + 0.3 * axes.up)
    } else {
        axes.front + off_square(front) * (0.35 * axes.side + 0.3 * axes.up)
    };
    direction.normalize()
}

/// Whether view `a` shows clearly more of the model's structure than
/// view `b` (`structure_seen`): a quarter more, and two directions at least.
fn shows_more(probe: &ModelProbe, a: &CameraSpec, b: &CameraSpec) -> bool {
    structure_seen(probe, a) > structure_seen(probe, b) * 5 / 4 + 1
}

/// How much of a model's structure a view shows: the number of distinct
/// directions (to a fifth of a radian or so) the surfaces seen in a 32x32
/// thumbnail face. A flat face, the closed back of a box or the back of a
/// head shows few; a model's features, the inside of a box, many.
fn structure_seen(probe: &ModelProbe, camera: &CameraSpec) -> u32 {
    const SIDE: u32 = 32;
    let Ok(camera) = Camera::new(camera, SIDE, SIDE) else {
        return 0;
    };
    let mut stack = WalkStack::default();
    // 5 steps per component: 125 bins of directions.
    let mut seen = [false; 125];
    for j in 0..SIDE {
        for i in 0..SIDE {
            let ray = camera.ray(i, j, 0.5, 0.5);
            let Some(hit) = probe.closest(ray, f64::INFINITY, &mut stack) else {
                continue;
            };
            let bin = |x: f64| ((x + 1.0) * 2.0).round().clamp(0.0, 4.0) as usize;
            let facing = hit.facing;
            seen[bin(facing.x) + 5 * bin(facing.y) + 25 * bin(facing.z)] = true;
        }
    }
    seen.iter().filter(|&&s| s).count() as u32
}

/// Parses `text`, the TOML an OBJ file `path` was opened with (an
/// export's record), as that scene again.
pub(super) fn reload(text: &str, path: &Path, files: &dyn FileSource) -> Result<Scene, SceneError> {
    toml_format::parse(text, path, files)
}

#[cfg(test)]
mod tests {
    use super::super::model_axes::Y_UP;
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
        let huge = Aabb::new(DVec3::ZERO, DVec3::splat(1.5e308));
        let direction = view_direction(huge.max - huge.min, Y_UP);
        assert!(frame(huge, Y_UP, direction).is_none());
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

    /// The OBJ text of the box `min`..`max`, without the faces `omit`
    /// names (`-z` for its bottom if z is up, `+x`, ...).
    fn box_obj(min: DVec3, max: DVec3, omit: &[&str]) -> String {
        let mut text = String::new();
        for i in 0..8 {
            let pick = |bit: usize, axis: usize| if i & bit == 0 { min[axis] } else { max[axis] };
            text += &format!("v {} {} {}\n", pick(1, 0), pick(2, 1), pick(4, 2));
        }
        // Vertex numbers of each side, by the side's outward axis.
        for (name, face) in [
            ("-x", "1 5 7 3"),
            ("+x", "2 4 8 6"),
            ("-y", "1 2 6 5"),
            ("+y", "3 7 8 4"),
            ("-z", "1 3 4 2"),
            ("+z", "5 6 8 7"),
        ] {
            if !omit.contains(&name) {
                text += &format!("f {face}\n");
            }
        }
        text
    }

    /// The model's faces appended to `base` (its vertex numbers shifted).
    fn with(base: String, more: &str) -> String {
        let shift = base.lines().filter(|l| l.starts_with("v ")).count();
        let more: String = more
            .lines()
            .map(|l| match l.strip_prefix("f ") {
                Some(face) => {
                    let ids: Vec<String> = face
                        .split_whitespace()
                        .map(|n| (n.parse::<usize>().unwrap() + shift).to_string())
                        .collect();
                    format!("f {}\n", ids.join(" "))
                }
                None => format!("{l}\n"),
            })
            .collect();
        base + &more
    }

    fn framed(obj: String) -> CameraSpec {
        struct One(String);
        impl FileSource for One {
            fn read(&self, _: &Path) -> std::io::Result<Vec<u8>> {
                Ok(self.0.clone().into_bytes())
            }
        }
        load(Path::new("m.obj"), &One(obj)).unwrap().camera
    }

    /// Issue 36 point 10: a statue on a plinth written z-up (a scan's, a
    /// 3D print's habit) is seen upright, from its front (-y) a little from
    /// above; the same statue written y-up keeps +y up and the +z front.
    #[test]
    fn the_up_axis_is_the_one_the_model_stands_on() {
        // A plinth without a top (the figure stands on it) and a spire.
        let plinth = box_obj(
            DVec3::new(-1.0, -1.0, 0.0),
            DVec3::new(1.0, 1.0, 0.3),
            &["+z"],
        );
        let spire = "v -0.5 -0.5 0.3\nv 0.5 -0.5 0.3\nv 0.5 0.5 0.3\nv -0.5 0.5 0.3\nv 0 0 3\n\
                     f 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\n";
        let z_up = with(plinth, spire);
        let camera = framed(z_up.clone());
        assert_eq!(camera.up, DVec3::Z);
        let seen_from = camera.eye - camera.lookat;
        assert!(seen_from.y < 0.0 && seen_from.z > 0.0, "{seen_from}");
        assert!(seen_from.y.abs() > seen_from.x.abs(), "{seen_from}");
        // The same statue with y and z swapped (and the winding turned).
        let y_up: String = z_up
            .lines()
            .map(|l| match l.strip_prefix("v ") {
                Some(v) => {
                    let c: Vec<&str> = v.split_whitespace().collect();
                    format!("v {} {} {}\n", c[0], c[2], c[1])
                }
                None => format!("{l}\n"),
            })
            .collect();
        let camera = framed(y_up);
        assert_eq!(camera.up, DVec3::Y);
        let seen_from = camera.eye - camera.lookat;
        assert!(seen_from.z > 0.0 && seen_from.y > 0.0, "{seen_from}");
        // Under a header naming a y-up exporter, a clear base still stands
        // the statue on z (the exporter's default was changed), and the
        // eye stays above the ground.
        for header in [
            "# Blender v2.79 (sub 0) OBJ File: ''\n# www.blender.org\n",
            "####\n#\n# 3ds Max Wavefront OBJ Exporter v0.97b - (c)2007 guruware\n",
        ] {
            let camera = framed(format!("{header}{z_up}"));
            assert_eq!(camera.up, DVec3::Z, "{header}");
            assert!(camera.eye.z > camera.lookat.z, "{header}");
        }
        // A faint base (3 % of the footprint, a spindle on a small flat
        // end) stands it on z alone, not against Blender's header.
        let spindle = "v -0.175 -0.175 0\nv 0.175 -0.175 0\nv 0.175 0.175 0\nv -0.175 0.175 0\n\
                       v -1 -1 1\nv 1 -1 1\nv 1 1 1\nv -1 1 1\nv 0 0 3\n\
                       f 4 3 2 1\nf 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n\
                       f 5 6 9\nf 6 7 9\nf 7 8 9\nf 8 5 9\n";
        assert_eq!(framed(spindle.to_string()).up, DVec3::Z);
        let camera = framed(format!("# Blender v2.82 (sub 7) OBJ File: ''\n{spindle}"));
        assert_eq!(camera.up, DVec3::Y);
        // A header naming no exporter (MeshLab's, a scanner's) leaves it to
        // the content.
        let camera = framed(format!("# OBJ File Generated by Meshlab\n{z_up}"));
        assert_eq!(camera.up, DVec3::Z);
        // A beam lying along z, flat at both ends (a rifle's butt and
        // muzzle), stands on nothing: +y stays up, and its long side
        // faces the camera.
        let camera = framed(box_obj(
            DVec3::new(-0.2, -0.5, -5.0),
            DVec3::new(0.2, 0.5, 5.0),
            &[],
        ));
        assert_eq!(camera.up, DVec3::Y);
        let seen_from = camera.eye - camera.lookat;
        assert!(seen_from.x > 2.0 * seen_from.z.abs(), "{seen_from}");
        // A cube is flat everywhere: the convention, seen from the front.
        let camera = framed(box_obj(DVec3::ZERO, DVec3::ONE, &[]));
        assert_eq!(camera.up, DVec3::Y);
        let seen_from = camera.eye - camera.lookat;
        assert!(seen_from.z > 2.0 * seen_from.x.abs(), "{seen_from}");
    }

    /// A z-up model that is wide and low (a house on its ground slab) is
    /// seen from above its front, not straight down; a sheet standing
    /// upright is seen square on, not obliquely.
    #[test]
    fn flat_models_are_seen_from_above_and_sheets_square_on() {
        let ground = box_obj(
            DVec3::new(-10.0, -8.0, 0.0),
            DVec3::new(10.0, 8.0, 0.2),
            &[],
        );
        let house = box_obj(
            DVec3::new(-3.0, -2.0, 0.2),
            DVec3::new(3.0, 2.0, 3.0),
            &["-z"],
        );
        let camera = framed(with(ground, &house));
        assert_eq!(camera.up, DVec3::Z);
        let seen_from = (camera.eye - camera.lookat).normalize();
        assert!(
            seen_from.y < 0.0 && seen_from.z > 0.4 && seen_from.z < 0.9,
            "{seen_from}"
        );
        let sheet = "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3 4\n".to_string();
        let camera = framed(sheet);
        assert_eq!((camera.eye - camera.lookat).normalize(), DVec3::Z);
    }

    /// A model seen better from behind is seen from behind: a room open on
    /// its back (a Cornell box) with a pyramid inside shows the pyramid
    /// from the open side; open at the front, the conventional side
    /// already shows it. Closed, the room keeps the front (the other side
    /// shows no more of it).
    #[test]
    fn the_camera_takes_the_side_that_shows_more_of_the_model() {
        let size = DVec3::new(2.0, 1.5, 1.0);
        // Its faces wound to face out.
        let pyramid = "v 1 0 0.2\nv 1.4 0 0.5\nv 1 0 0.8\nv 0.6 0 0.5\nv 1 1 0.5\n\
                       f 5 2 1\nf 5 3 2\nf 5 4 3\nf 5 1 4\n";
        let room = |omit: &[&str]| framed(with(box_obj(DVec3::ZERO, size, omit), pyramid));
        let open_back = room(&["-z"]);
        assert!(open_back.eye.z < open_back.lookat.z, "{open_back:?}");
        let open_front = room(&["+z"]);
        assert!(open_front.eye.z > open_front.lookat.z, "{open_front:?}");
        let closed = room(&[]);
        assert!(closed.eye.z > closed.lookat.z, "{closed:?}");
        // The up axis stays the model's either way.
        assert_eq!(open_back.up, DVec3::Y);
    }

    /// `text`'s faces turned the other way (their vertex order reversed):
    /// a box's faces then face its inside.
    fn turned_inwards(text: String) -> String {
        text.lines()
            .map(|l| match l.strip_prefix("f ") {
                Some(face) => {
                    let mut ids: Vec<&str> = face.split_whitespace().collect();
                    ids.reverse();
                    format!("f {}\n", ids.join(" "))
                }
                None => format!("{l}\n"),
            })
            .collect()
    }

    /// A hall 20 long (x), 8 high (y) and 12 deep (z) with walls, floor
    /// and roof half a unit thick (an outer box facing out, an inner one
    /// facing in) and two pillars inside.
    fn hall() -> String {
        let mut model = box_obj(DVec3::ZERO, DVec3::new(20.0, 8.0, 12.0), &[]);
        model = with(
            model,
            &turned_inwards(box_obj(DVec3::splat(0.5), DVec3::new(19.5, 7.5, 11.5), &[])),
        );
        for x in [7.0, 13.0] {
            model = with(
                model,
                &box_obj(DVec3::new(x, 0.5, 5.5), DVec3::new(x + 1.0, 7.5, 6.5), &[]),
            );
        }
        model
    }

    /// Whether `p` is inside the hall's inner box.
    fn in_hall(p: DVec3) -> bool {
        p.cmpgt(DVec3::splat(0.5)).all() && p.cmplt(DVec3::new(19.5, 7.5, 11.5)).all()
    }

    /// Issue 65 point 2: an enclosed hall is seen from inside, standing on
    /// its floor at eye height, looking along its length with a wider
    /// view, the light inside too.
    #[test]
    fn an_enclosed_hall_is_seen_from_inside() {
        struct One(String);
        impl FileSource for One {
            fn read(&self, _: &Path) -> std::io::Result<Vec<u8>> {
                Ok(self.0.clone().into_bytes())
            }
        }
        let path = Path::new("hall.obj");
        let scene = load(path, &One(hall())).unwrap();
        let camera = scene.camera;
        assert_eq!(camera.up, DVec3::Y);
        assert_eq!(camera.fov, 60.0);
        let eye = camera.eye;
        assert!(in_hall(eye), "eye {eye}");
        // Eye height: between a fifth and a half of the room's height
        // over its floor (at 0.5), never below it.
        assert!(eye.y > 0.5 + 0.2 * 7.0 && eye.y < 0.5 + 0.5 * 7.0, "{eye}");
        let look = (camera.lookat - eye).normalize();
        assert!(look.x.abs() > 0.99, "looks along the length: {look}");
        // From most of the way back along the length, to the far end.
        assert!(
            (look.x < 0.0 && eye.x > 14.0) || (look.x > 0.0 && eye.x < 6.0),
            "{eye} {look}"
        );
        assert!(in_hall(scene.lights[0].position));
        // Written so: the scene text loads the same camera and light.
        let again = reload(&scene.source_text, path, &One(hall())).unwrap();
        assert_eq!(again.camera, scene.camera);
        assert_eq!(again.lights, scene.lights);
    }

    /// The same hall with z up (a CAD or scan habit): inside it, standing
    /// on the floor along z.
    #[test]
    fn an_enclosed_hall_with_z_up_is_seen_from_inside() {
        // (x, y, z) becomes (x, -z, y): winding is kept by a rotation.
        let z_up: String = hall()
            .lines()
            .map(|l| match l.strip_prefix("v ") {
                Some(v) => {
                    let c: Vec<f64> = v.split_whitespace().map(|x| x.parse().unwrap()).collect();
                    format!("v {} {} {}\n", c[0], -c[2], c[1])
                }
                None => format!("{l}\n"),
            })
            .collect();
        struct One(String);
        impl FileSource for One {
            fn read(&self, _: &Path) -> std::io::Result<Vec<u8>> {
                Ok(self.0.clone().into_bytes())
            }
        }
        let scene = load(Path::new("hall.obj"), &One(z_up)).unwrap();
        let probe = ModelProbe::new(&scene.shapes, &scene.vertex_normals).unwrap();
        let (camera, light) = interior_view(
            &probe,
            scene.geometry_bounds(),
            DVec3::Z,
            [DVec3::X, DVec3::NEG_Y],
        )
        .unwrap();
        let back = |v: DVec3| DVec3::new(v.x, v.z, -v.y);
        assert_eq!(camera.up, DVec3::Z);
        let eye = back(camera.eye);
        assert!(in_hall(eye), "eye {eye}");
        assert!(eye.y > 0.5 + 0.2 * 7.0 && eye.y < 0.5 + 0.5 * 7.0, "{eye}");
        assert!((back(camera.lookat) - eye).normalize().x.abs() > 0.99);
        assert!(in_hall(back(light)));
    }

    /// A room of single walls facing in (a room modelled to be seen from
    /// inside, as the conference room is) is seen from inside; the same
    /// box facing out is an object (`the_camera_takes_the_side_...`), and
    /// a room open at its front is seen through that side.
    #[test]
    fn a_room_facing_in_is_seen_from_inside_and_an_open_one_from_outside() {
        let size = DVec3::new(10.0, 4.0, 6.0);
        let table = box_obj(DVec3::new(4.0, 0.0, 2.5), DVec3::new(6.0, 1.0, 3.5), &[]);
        let room = turned_inwards(box_obj(DVec3::ZERO, size, &[]));
        let camera = framed(with(room.clone(), &table));
        let eye = camera.eye;
        assert!(
            eye.cmpgt(DVec3::ZERO).all() && eye.cmplt(size).all(),
            "{camera:?}"
        );
        assert!(eye.y > 0.0 && eye.y < 2.0, "{eye}");
        // Open at the front (+z): rays from its centre leave through it.
        let open = turned_inwards(box_obj(DVec3::ZERO, size, &["+z"]));
        let camera = framed(with(open, &table));
        assert!(camera.eye.z > size.z, "{camera:?}");
        assert_eq!(camera.fov, FOV);
    }

    /// Issue 65 point 3: the faces' lean names the up axis where the base
    /// does not. A bumpy z-up terrain with no flat base stands on z; an
    /// open-backed mask facing +z (y up) leans along z but its area sits
    /// at its front, so it keeps y; a Blender header gives way to a
    /// terrain's lean (Blender's y-up default was changed), and the eye
    /// stays above the ground.
    #[test]
    fn the_faces_lean_names_the_up_axis() {
        // A 6x6 grid of heights over 10x10 in x and y, bumps up to 0.6.
        let mut terrain = String::new();
        let n = 6;
        for j in 0..n {
            for i in 0..n {
                let h = 0.3 * ((i * 7 + j * 3) % 5) as f64 / 2.0;
                terrain += &format!("v {} {} {h}\n", 2 * i, 2 * j);
            }
        }
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let k = j * n + i + 1;
                terrain += &format!("f {} {} {} {}\n", k, k + 1, k + n + 1, k + n);
            }
        }
        let camera = framed(terrain.clone());
        assert_eq!(camera.up, DVec3::Z);
        assert!(camera.eye.z > camera.lookat.z);
        let camera = framed(format!("# Blender v2.90.0 OBJ File: ''\n{terrain}"));
        assert_eq!(camera.up, DVec3::Z);
        // The mask: a shallow dome bulging towards +z, open at the back.
        let mut mask = String::new();
        for j in 0..n {
            for i in 0..n {
                let (x, y) = (i as f64 - 2.5, j as f64 - 2.5);
                mask += &format!("v {x} {y} {}\n", 3.0 - 0.2 * (x * x + y * y));
            }
        }
        for j in 0..n - 1 {
            for i in 0..n - 1 {
                let k = j * n + i + 1;
                mask += &format!("f {} {} {} {}\n", k, k + 1, k + n + 1, k + n);
            }
        }
        let camera = framed(mask);
        assert_eq!(camera.up, DVec3::Y);
    }

    /// Issue 65 point 3: a weaker lean names the up axis too. A y-up
    /// building open underneath (its roof faces up, nothing faces down)
    /// behind a fence whose flat back looks like a base at the lowest z
    /// stands on y (raylib's barracks); a z-up room corner, a floor and two
    /// walls, stands on z and is seen from its open side (the Vulkan
    /// tutorial's viking room); a room open at its front, with a floor and
    /// a ceiling, leans forwards and keeps y.
    #[test]
    fn a_weaker_lean_names_the_up_axis_unless_the_model_has_a_floor_and_a_ceiling() {
        let house = box_obj(
            DVec3::new(-3.0, 0.0, -2.0),
            DVec3::new(3.0, 3.0, 2.0),
            &["-y"],
        );
        let fence = box_obj(DVec3::new(-8.0, 0.0, -3.0), DVec3::new(8.0, 3.0, -2.8), &[]);
        let camera = framed(with(house, &fence));
        assert_eq!(camera.up, DVec3::Y);
        assert!(camera.eye.y > camera.lookat.y, "{camera:?}");
        // The corner: a 12x12 floor facing up, walls 5 high at x = 0 and
        // y = 0 facing in, and three pyramids behind the y = 0 wall.
        let mut corner = "v 0 0 0\nv 12 0 0\nv 12 12 0\nv 0 12 0\nv 0 0 5\nv 12 0 5\nv 0 12 5\n\
                          f 1 2 3 4\nf 1 4 7 5\nf 1 5 6 2\n"
            .to_string();
        for (x, size, height, turn) in [
            (3.0, 1.2, 2.0, 0.8),
            (6.0, 1.2, 1.0, 0.0),
            (9.0, 1.2, 3.0, 0.4),
        ] {
            let mut pyramid = String::new();
            for k in 0..4 {
                let angle = turn + k as f64 * std::f64::consts::FRAC_PI_2;
                pyramid += &format!(
                    "v {} {} 0\n",
                    x + size * angle.cos(),
                    2.0 + size * angle.sin()
                );
            }
            pyramid += &format!("v {x} 2 {height}\nf 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\n");
            corner = with(corner, &pyramid);
        }
        let camera = framed(corner);
        assert_eq!(camera.up, DVec3::Z);
        assert!(
            camera.eye.y > 12.0 && camera.eye.z > camera.lookat.z,
            "{camera:?}"
        );
        // A room open at its front (+z) with a crate: floor and ceiling.
        let size = DVec3::new(10.0, 4.0, 6.0);
        let room = turned_inwards(box_obj(DVec3::ZERO, size, &["+z"]));
        let table = box_obj(DVec3::new(4.0, 0.0, 2.5), DVec3::new(6.0, 1.0, 3.5), &[]);
        let camera = framed(with(room, &table));
        assert_eq!(camera.up, DVec3::Y);
    }
}
