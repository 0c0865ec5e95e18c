//! An `.obj` opened directly: glint writes the TOML scene around it (the
//! model with its own MTL materials, a camera that frames it, one light over
//! the camera's shoulder) and loads that. The written text is the scene's
//! source, so an export records it and re-renders the same picture.

use std::path::Path;

use crate::accel::{Octree, OctreeParams, Primitives, WalkStack};
use crate::camera::{Camera, CameraSpec};
use crate::math::{Aabb, DVec3};
use crate::shapes::{PreparedRay, Shape};
use crate::stats::NoCounts;

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
    let bounds = scene.geometry_bounds();
    let header = scene.meshes.first().and_then(|m| m.header.as_deref());
    let axes = if header.is_some_and(exporter_writes_y_up) {
        Y_UP
    } else {
        model_axes(&scene.shapes, bounds)
    };
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
    // The same view from the opposite side, when it shows clearly more of
    // the model: its features rather than a flat back, the inside of a box
    // open on that side, a face rather than the back of a head.
    let mirrored = direction
        - 2.0 * direction.dot(axes.front.abs()) * axes.front.abs()
        - 2.0 * direction.dot(axes.side.abs()) * axes.side.abs();
    if let Some((other_camera, other_light)) = frame(bounds, axes, mirrored)
        && let Some(seen) = StructureSeen::new(&scene.shapes, &scene.vertex_normals)
        && seen.of(&other_camera) > seen.of(&camera) * 5 / 4 + 1
    {
        (camera, light) = (other_camera, other_light);
    }
    let text = wrapper_text(path, &camera, light);
    scene.camera = camera;
    if let Some(l) = scene.lights.first_mut() {
        l.position = light;
    }
    scene.source_text = std::sync::Arc::from(text.as_str());
    Ok(scene)
}

/// The model's own axes: which way is up, which side is its front, and
/// the one across. OBJ has no up axis of its own; exporters mostly write
/// +y up with the model facing +z (Blender's and 3ds Max's defaults), but
/// scans and CAD or 3D-printing exports are +z up, facing -y (Blender's
/// front view looks along +y).
#[derive(Clone, Copy, Debug, PartialEq)]
struct ModelAxes {
    side: DVec3,
    up: DVec3,
    front: DVec3,
}

const Y_UP: ModelAxes = ModelAxes {
    side: DVec3::X,
    up: DVec3::Y,
    front: DVec3::Z,
};
const Z_UP: ModelAxes = ModelAxes {
    side: DVec3::X,
    up: DVec3::Z,
    front: DVec3::NEG_Y,
};

/// Whether the exporter a header comment names writes +y up by default:
/// Blender's OBJ exporter (up Y, forward -Z unless changed), 3ds Max's
/// (guruware's, which flips to y-up), Maya, Cinema 4D and Wings 3D, whose
/// own axes are y-up. Their files are read y-up whatever their content
/// suggests (a fence's flat back is no base).
fn exporter_writes_y_up(header: &str) -> bool {
    let header = header.to_ascii_lowercase();
    [
        "blender",
        "guruware",
        "3ds max wavefront obj exporter",
        "maya",
        "cinema 4d",
        "wings 3d",
    ]
    .iter()
    .any(|name| header.contains(name))
}

/// The up axis the model's content suggests: +z when the model stands on
/// a flat base at its lowest z (faces perpendicular to z there covering at
/// least 2 % of its footprint) that has no match at its top (a box or a
/// slab is flat at both ends and says nothing) and no comparable base at
/// its lowest y; +y, OBJ's convention, otherwise. A statue's plinth, a
/// 3D-print's bed face or a building's ground slab is such a base; the
/// flat butt of a rifle lying along z is not, its muzzle end being as flat.
fn model_axes(shapes: &[Shape], bounds: Aabb) -> ModelAxes {
    let extent = bounds.max - bounds.min;
    // Area of faces perpendicular to `axis` lying at its low and high end,
    // as fractions of the model's footprint across that axis.
    let flat_ends = |axis: usize| {
        let across = extent[(axis + 1) % 3] * extent[(axis + 2) % 3];
        let tolerance = 0.01 * extent[axis];
        let (mut low, mut high) = (0.0, 0.0);
        if !(across > 0.0 && across.is_finite()) {
            return (0.0, 0.0);
        }
        for shape in shapes {
            let Shape::Triangle(t) = shape else { continue };
            let [a, b, c] = t.vertices;
            let normal = (b - a).cross(c - a);
            let area = 0.5 * normal.length();
            if !(area.is_finite() && normal[axis].abs() > 0.99 * 2.0 * area) {
                continue;
            }
            let (lo, hi) = (
                a[axis].min(b[axis]).min(c[axis]),
                a[axis].max(b[axis]).max(c[axis]),
            );
            // A flat model's faces lie at both ends: no base.
            if hi <= bounds.min[axis] + tolerance {
                low += area;
            }
            if lo >= bounds.max[axis] - tolerance {
                high += area;
            }
        }
        (low / across, high / across)
    };
    let (base_z, top_z) = flat_ends(2);
    let (base_y, _) = flat_ends(1);
    if base_z >= 0.02 && base_z > 2.0 * top_z && base_z > 2.0 * base_y {
        Z_UP
    } else {
        Y_UP
    }
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

/// How much of a model's structure a view shows: the number of distinct
/// directions (to a fifth of a radian or so) the surfaces seen in a 32x32
/// thumbnail face. A flat face, the closed back of a box or the back of a
/// head shows few; a model's features, the inside of a box, many. The
/// thumbnail's rays take a shallow octree of their own (no deeper than 6
/// levels, a fraction of the render's build).
struct StructureSeen<'a> {
    shapes: &'a [Shape],
    vertex_normals: &'a [[DVec3; 3]],
    octree: Octree,
}

impl<'a> StructureSeen<'a> {
    const SIDE: u32 = 32;
    /// Models with more shapes than this keep the conventional side: the
    /// thumbnails' octree would cost a noticeable part of the load.
    const MAX_SHAPES: usize = 200_000;

    fn new(shapes: &'a [Shape], vertex_normals: &'a [[DVec3; 3]]) -> Option<Self> {
        if shapes.len() > Self::MAX_SHAPES {
            return None;
        }
        let params = OctreeParams {
            max_depth: 6,
            ..OctreeParams::default()
        };
        let octree = Octree::build(shapes, params).ok()?;
        Some(Self {
            shapes,
            vertex_normals,
            octree,
        })
    }

    /// The distinct facing directions seen from `camera`.
    fn of(&self, camera: &CameraSpec) -> u32 {
        let Ok(camera) = Camera::new(camera, Self::SIDE, Self::SIDE) else {
            return 0;
        };
        let prims = Primitives::opaque(self.shapes);
        let mut stack = WalkStack::default();
        // 5 steps per component: 125 bins of directions.
        let mut seen = [false; 125];
        for j in 0..Self::SIDE {
            for i in 0..Self::SIDE {
                let ray = camera.ray(i, j, 0.5, 0.5);
                let prepared = PreparedRay::new(ray);
                let Some(hit) = self.octree.closest(
                    &prims,
                    &prepared,
                    f64::INFINITY,
                    &mut stack,
                    &mut NoCounts,
                ) else {
                    continue;
                };
                let shape = &self.shapes[hit.shape as usize];
                let normal = shape
                    .surface(&ray, &hit.hit, self.vertex_normals)
                    .geometric_normal;
                let facing = if normal.dot(ray.dir) < 0.0 {
                    normal
                } else {
                    -normal
                };
                if !facing.is_finite() {
                    continue;
                }
                let bin = |x: f64| ((x + 1.0) * 2.0).round().clamp(0.0, 4.0) as usize;
                seen[bin(facing.x) + 5 * bin(facing.y) + 25 * bin(facing.z)] = true;
            }
        }
        seen.iter().filter(|&&s| s).count() as u32
    }
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
        // The z-up statue's shape under Blender's header: Blender writes
        // +y up, so +y is up whatever base the content suggests (a wall's
        // flat back, a fence's), and the eye stays above the ground.
        for header in [
            "# Blender v2.79 (sub 0) OBJ File: ''\n# www.blender.org\n",
            "####\n#\n# 3ds Max Wavefront OBJ Exporter v0.97b - (c)2007 guruware\n",
        ] {
            let camera = framed(format!("{header}{z_up}"));
            assert_eq!(camera.up, DVec3::Y, "{header}");
            assert!(camera.eye.y > camera.lookat.y, "{header}");
        }
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
        let pyramid = "v 1 0 0.2\nv 1.4 0 0.5\nv 1 0 0.8\nv 0.6 0 0.5\nv 1 1 0.5\n\
                       f 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\n";
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
}
