//! Eric Haines's Neutral File Format (NFF), the language of the Standard
//! Procedural Databases (SPD). Entities may span lines, so the file is read
//! as a stream of whitespace-separated tokens, each remembering its place.

mod tokens;

use std::path::Path;

use std::ops::Range;

use tokens::Tokens;

use super::model::{ImageSettings, Scene, SceneError};
use crate::accel::OctreeParams;
use crate::camera::CameraSpec;
use crate::color::ColorConvention;
use crate::limits::{
    INTENSITY_RANGE, IOR_RANGE, MAX_IMAGE_SIDE, SHININESS_RANGE, UNIT_RANGE, check_range,
};
use crate::material::{Light, Material};
use crate::math::DVec3;
use crate::shapes::{Cone, Shape, Sphere};

/// More vertices than any sane polygon has; guards against `p 999999999`.
const MAX_POLYGON_VERTICES: usize = 1 << 16;

/// Vertical field of view (edge to edge of the image) from NFF's angle,
/// which is measured between the centres of the first and last pixel rows.
pub fn fov_from_nff_angle(angle_degrees: f64, rows: u32) -> f64 {
    if rows <= 1 {
        return angle_degrees;
    }
    let half = (angle_degrees.to_radians() * 0.5).tan() * rows as f64 / (rows - 1) as f64;
    2.0 * half.atan().to_degrees()
}

/// Where the numbers the viewer edits stand in an NFF file (byte ranges of
/// its text), so that "Save scene" rewrites those and keeps the rest.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct NffLayout {
    /// The viewpoint's `from`, `at` and `up` vectors, `angle` and
    /// `resolution`.
    pub view: Option<ViewLayout>,
    /// Each light's position, and its colour if the file gives one
    /// (otherwise where one would go: right after the position).
    pub lights: Vec<LightLayout>,
    /// For each scene material, every `f` entity that gives it: colour,
    /// Kd, Ks, Shine, T and index of refraction.
    pub materials: Vec<Vec<[Range<usize>; 8]>>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct ViewLayout {
    pub from: [Range<usize>; 3],
    pub at: [Range<usize>; 3],
    pub up: [Range<usize>; 3],
    pub angle: Range<usize>,
    pub resolution: [Range<usize>; 2],
}

#[derive(Clone, Debug, PartialEq)]
pub struct LightLayout {
    pub position: [Range<usize>; 3],
    pub color: Option<[Range<usize>; 3]>,
}

/// The NFF file's layout; errors as [`parse`] gives them.
pub fn layout(text: &str, path: &Path) -> Result<NffLayout, SceneError> {
    let mut layout = NffLayout::default();
    parse_into(text, path, Some(&mut layout))?;
    Ok(layout)
}

/// NFF's `angle` (between the centres of the first and last of `rows`
/// pixel rows) for a vertical field of view: the inverse of
/// [`fov_from_nff_angle`].
pub fn nff_angle_from_fov(fov_degrees: f64, rows: u32) -> f64 {
    if rows <= 1 {
        return fov_degrees;
    }
    let half = (fov_degrees.to_radians() * 0.5).tan() * (rows - 1) as f64 / rows as f64;
    2.0 * half.atan().to_degrees()
}

pub fn parse(text: &str, path: &Path) -> Result<Scene, SceneError> {
    parse_into(text, path, None)
}

fn parse_into(
    text: &str,
    path: &Path,
    mut layout: Option<&mut NffLayout>,
) -> Result<Scene, SceneError> {
    let mut tokens = Tokens::new(text, path);
    let mut camera: Option<CameraSpec> = None;
    // NFF colours are display values: the SPD's pictures were shaded and
    // shown with no transfer function, and glint does the same by default.
    let mut image = ImageSettings {
        samples: 1,
        max_depth: 5,
        background: DVec3::ZERO,
        colors: ColorConvention::Display,
        ..ImageSettings::default()
    };
    // Lights given without a colour; their intensity depends on the final count.
    let mut uncoloured_lights = Vec::new();
    let mut scene = Scene::empty(
        path.display().to_string(),
        CameraSpec {
            eye: DVec3::ZERO,
            lookat: DVec3::NEG_Z,
            up: DVec3::Y,
            fov: 45.0,
        },
        image.clone(),
    );
    scene.color_values = ColorConvention::Display;
    let mut material: Option<u32> = None;
    let mut default_material: Option<u32> = None;
    // NFF materials are named by their `f`'s order: f1, f2, ...
    let mut f_materials = 0;

    while let Some(t) = tokens.advance() {
        let (keyword, line, column) = (t.text, t.line, t.column);
        tokens.entity = (line, column, keyword);
        // NFF gives each object the last `f` before it; objects before any
        // (as course files write them) get a default grey, said once.
        let mut needs_material = |m: Option<u32>, scene: &mut Scene| -> u32 {
            m.unwrap_or_else(|| {
                *default_material.get_or_insert_with(|| {
                    scene.materials.push(Material {
                        name: "default".into(),
                        ..Material::default()
                    });
                    scene.load_notes.push(format!(
                        "{}:{line}:{column}: `{keyword}` comes before any `f` material: the \
                         objects before the first `f` use a default grey",
                        path.display()
                    ));
                    scene.materials.len() as u32 - 1
                })
            })
        };
        match keyword {
            "v" => {
                tokens.label("from")?;
                let eye = tokens.vec3("from")?;
                let from_at = tokens.last();
                tokens.label("at")?;
                let lookat_place = tokens.peek_place();
                let lookat = tokens.vec3("at")?;
                let at_at = tokens.last();
                tokens.label("up")?;
                let up_place = tokens.peek_place();
                let up = tokens.vec3("up")?;
                let up_at = tokens.last();
                tokens.label("angle")?;
                let angle = tokens.number("angle")?;
                let [angle_at] = tokens.last();
                let angle_place = tokens.last_place();
                tokens.label("hither")?;
                let _hither = tokens.number("hither")?;
                tokens.label("resolution")?;
                let limit = MAX_IMAGE_SIDE as usize;
                let resolution_place = tokens.peek_place();
                let w = tokens.count("resolution", limit)?;
                let h = tokens.count("resolution", limit)?;
                if let Some(layout) = layout.as_deref_mut() {
                    layout.view = Some(ViewLayout {
                        from: from_at,
                        at: at_at,
                        up: up_at,
                        angle: angle_at,
                        resolution: tokens.last(),
                    });
                }
                // Errors point at the bad value, not at the `v` line.
                if w == 0 || h == 0 {
                    let (line, column) = resolution_place;
                    return Err(tokens.error_at(
                        line,
                        column,
                        "v",
                        "resolution must be at least 1x1",
                    ));
                }
                if !(angle > 0.0 && angle < 180.0) {
                    let (line, column) = angle_place;
                    return Err(tokens.error_at(
                        line,
                        column,
                        "v",
                        format!("angle must lie between 0 and 180, got {angle}"),
                    ));
                }
                image.width = w as u32;
                image.height = h as u32;
                let spec = CameraSpec {
                    eye,
                    lookat,
                    up,
                    fov: fov_from_nff_angle(angle, h as u32),
                };
                if let Err((key, message)) = spec.check() {
                    let (line, column) = match key {
                        "up" => up_place,
                        "fov" => angle_place,
                        _ => lookat_place,
                    };
                    return Err(tokens.error_at(line, column, "v", message));
                }
                camera = Some(spec);
            }
            "b" => image.background = tokens.color_in("background colour", &UNIT_RANGE)?,
            "l" => {
                let position = tokens.vec3("light position")?;
                let position_at = tokens.last();
                // The colour is optional: it is present if the next token is a number.
                let has_colour = tokens.peek().is_some_and(|t| t.text.parse::<f64>().is_ok());
                if let Some(layout) = layout.as_deref_mut() {
                    layout.lights.push(LightLayout {
                        position: position_at,
                        color: None,
                    });
                }
                if has_colour {
                    let color = tokens.color_in("light colour", &INTENSITY_RANGE)?;
                    if let Some(light) = layout.as_deref_mut().and_then(|l| l.lights.last_mut()) {
                        light.color = Some(tokens.last());
                    }
                    scene.lights.push(Light { position, color });
                } else {
                    uncoloured_lights.push(scene.lights.len());
                    scene.lights.push(Light {
                        position,
                        color: DVec3::ONE,
                    });
                }
            }
            "f" => {
                let f_line = line;
                let color = tokens.color_in("colour", &UNIT_RANGE)?;
                let kd = tokens.number_in("Kd", &UNIT_RANGE)?;
                let ks = tokens.number_in("Ks", &UNIT_RANGE)?;
                let shininess = tokens.number_in("Shine", &SHININESS_RANGE)?;
                let transparency = tokens.number_in("T", &UNIT_RANGE)?;
                let (line, column) = tokens.peek_place();
                let ior = tokens.number("index of refraction")?;
                // assimp's extension: a texture name after the numbers.
                let (extra_line, extra_column) = tokens.peek_place();
                if extra_line == f_line
                    && let Some(extra) = tokens.peek()
                {
                    return Err(tokens.error_at(
                        extra_line,
                        extra_column,
                        "f",
                        format!(
                            "an extra field `{}` after the eight numbers (a texture name, as \
                             assimp writes one): glint's NFF has no textures; remove it",
                            extra.text
                        ),
                    ));
                }
                // Opaque materials often give 0 (the SPD's gears do): it is unused.
                let ior = if transparency > 0.0 {
                    check_range(ior, &IOR_RANGE).map_err(|e| {
                        tokens.error_at(line, column, "f", format!("index of refraction {e}"))
                    })?
                } else {
                    1.0
                };
                let m = Material {
                    name: format!("f{}", f_materials + 1),
                    color,
                    ka: kd,
                    kd,
                    ks,
                    shininess,
                    // NFF's Ks weights both the highlight and the mirror ray.
                    reflectivity: ks,
                    transparency,
                    ior,
                    color_map: None,
                    cutout_map: None,
                };
                let same = |o: &Material| {
                    (o.color, o.kd, o.ks, o.shininess, o.transparency, o.ior)
                        == (m.color, m.kd, m.ks, m.shininess, m.transparency, m.ior)
                };
                let index = match scene.materials.iter().position(same) {
                    Some(i) => i,
                    None => {
                        scene.materials.push(m);
                        f_materials += 1;
                        scene.materials.len() - 1
                    }
                };
                if let Some(layout) = layout.as_deref_mut() {
                    layout.materials.resize(scene.materials.len(), Vec::new());
                    layout.materials[index].push(tokens.last());
                }
                material = Some(index as u32);
            }
            "s" => {
                let center = tokens.vec3("sphere centre")?;
                let radius = tokens.number("sphere radius")?.abs();
                let m = needs_material(material, &mut scene);
                if radius == 0.0 {
                    return Err(tokens.error_at(
                        line,
                        column,
                        "s",
                        "sphere radius must not be zero",
                    ));
                }
                scene.push(Shape::Sphere(Sphere::new(center, radius)), m);
            }
            "c" => {
                let base = tokens.vec3("cone base")?;
                let base_radius = tokens.number("cone base radius")?;
                let apex = tokens.vec3("cone apex")?;
                let apex_radius = tokens.number("cone apex radius")?;
                let m = needs_material(material, &mut scene);
                // Like a sphere of radius zero: a segment, with no surface.
                if base_radius == 0.0 && apex_radius == 0.0 {
                    return Err(tokens.error_at(
                        line,
                        column,
                        "c",
                        "cone radii must not both be zero",
                    ));
                }
                let cone = Cone::new(base, base_radius, apex, apex_radius).ok_or_else(|| {
                    tokens.error_at(line, column, "c", "cone base and apex coincide")
                })?;
                scene.push(Shape::Cone(Box::new(cone)), m);
            }
            "p" | "pp" => {
                let with_normals = keyword == "pp";
                let n = tokens.count("vertex count", MAX_POLYGON_VERTICES)?;
                if n < 3 {
                    return Err(tokens.error_at(
                        line,
                        column,
                        keyword,
                        format!("a polygon needs at least 3 vertices, got {n}"),
                    ));
                }
                let mut vertices = Vec::with_capacity(n);
                let mut normals = Vec::with_capacity(if with_normals { n } else { 0 });
                for _ in 0..n {
                    vertices.push(tokens.vec3("vertex")?);
                    if with_normals {
                        normals.push(tokens.vec3("vertex normal")?);
                    }
                }
                let m = needs_material(material, &mut scene);
                let normals: Vec<DVec3> = normals.iter().map(|v| v.normalize_or_zero()).collect();
                // Concave outlines are common (gear faces): ear clipping, not a fan.
                scene.push_polygon(&vertices, with_normals.then_some(&normals[..]), m);
            }
            "nff" if line == 1 => {
                return Err(tokens.error_at(
                    line,
                    column,
                    "nff",
                    "this is Sense8's WorldToolKit NFF (it starts with `nff` and a version), \
                     another format than the Standard Procedural Databases' NFF glint reads",
                ));
            }
            other => {
                return Err(tokens.error_at(
                    line,
                    column,
                    other,
                    format!("unknown NFF entity `{other}`"),
                ));
            }
        }
    }

    scene.camera =
        camera.ok_or_else(|| tokens.error_at(1, 1, "v", "the file has no `v` viewpoint"))?;
    // NFF leaves light intensity open; SPD's convention is sqrt(n)/(2n) for
    // n lights, and the ambient gets the same.
    let n = scene.lights.len().max(1) as f64;
    let intensity = n.sqrt() / (2.0 * n);
    for i in uncoloured_lights {
        scene.lights[i].color = DVec3::splat(intensity);
    }
    image.ambient = DVec3::splat(intensity);
    scene.image = image;
    scene.octree_params = OctreeParams::default_for(&scene.shapes);
    Ok(scene)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_long_line_is_read_in_linear_time_and_its_errors_placed() {
        // 200,000 spheres on one line: counting each token's column from
        // the line's start would take ~10^11 steps.
        let mut text = String::from(
            "v from 0 0 5 at 0 0 0 up 0 1 0 angle 40 hither 1 resolution 8 8\nf 1 1 1 1 0 0 0 1\n",
        );
        for _ in 0..200_000 {
            text.push_str("s 0 0 0 1 ");
        }
        let column = text.lines().nth(2).map_or(0, |l| l.chars().count()) + 1;
        text.push_str("s 0 0 x 1");
        let message = parse(&text, Path::new("long.nff"))
            .err()
            .map(|e| e.to_string());
        assert!(
            message
                .as_deref()
                .is_some_and(|m| m.contains(&format!("long.nff:3:{}", column + 6))),
            "{message:?}"
        );
    }

    const SCENE: &str = "\
# a comment
v
from 0 0 5
at 0 0 0
up 0 1 0
angle 40
hither 0.01
resolution 64 48
b 0.1 0.2 0.3
l 5 5 5
l -5 5 5 1 0 0
f 1 0.5 0.2 0.7 0.3 20 0 1
s 0 0 0 1
c 0 0 0 1 0 1 0 0.5
p 4
-1 -1 -2
1 -1 -2
1 1 -2
-1 1 -2
pp 3
0 0 -3 0 0 1
1 0 -3 0 0 1
0 1 -3 0 0 1
";

    fn parse_str(text: &str) -> Result<Scene, SceneError> {
        parse(text, Path::new("t.nff"))
    }

    #[test]
    fn entities_become_shapes_lights_and_materials() {
        let s = parse_str(SCENE).unwrap();
        assert_eq!(
            s.shape_counts(),
            vec![("sphere", 1), ("cone", 1), ("triangle", 3)]
        );
        assert_eq!((s.image.width, s.image.height), (64, 48));
        assert_eq!(s.lights.len(), 2);
        let expected = 2f64.sqrt() / 4.0;
        assert!((s.lights[0].color - DVec3::splat(expected)).length() < 1e-15);
        assert_eq!(s.lights[1].color, DVec3::X);
        // Display values, kept as written.
        assert_eq!(s.image.background, DVec3::new(0.1, 0.2, 0.3));
        assert_eq!(s.image.colors, ColorConvention::Display);
        assert_eq!(s.materials.len(), 1);
        assert_eq!(s.materials[0].reflectivity, 0.3);
        assert_eq!(s.vertex_normals.len(), 1);
        // A sphere and a cone beside three triangles: not a mesh's leaves.
        assert_eq!(s.octree_params, OctreeParams::default());
        // Three triangles are not a large mesh; 20,000 are.
        let view = "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 40\nhither 0.01\nresolution 8 8\n\
                    f 1 1 1 1 0 0 0 1\n";
        let triangles = |n: usize| {
            let mut text = view.to_string();
            for i in 0..n {
                let x = i as f64 * 1e-3;
                text += &format!("p 3\n{x} 0 0\n{} 0 0\n{x} 1 0\n", x + 1.0);
            }
            parse_str(&text).unwrap().octree_params.leaf_size
        };
        assert_eq!(triangles(3), 4);
        assert_eq!(triangles(20_000), 8);
    }

    #[test]
    fn the_angle_spans_the_centres_of_the_first_and_last_rows() {
        // NFF.TXT: the angle is "from the center of top pixel row to bottom
        // pixel row". Measured on the camera glint builds: the rays through
        // those centres (in the middle of the image across) are 45° apart.
        for (w, h) in [(512, 512), (64, 48), (2, 3)] {
            let text = format!(
                "v\nfrom 1 2 3\nat 0 0 0\nup 0 0 1\nangle 45\nhither 1\nresolution {w} {h}\nf 1 1 1 1 0 1 0 1\ns 0 0 0 1\n"
            );
            let scene = parse_str(&text).unwrap();
            let camera = crate::camera::Camera::new(&scene.camera, w, h).unwrap();
            // Pixel i's left edge plus dx: the image's vertical centre line.
            let (i, dx) = (w / 2, if w % 2 == 0 { 0.0 } else { 0.5 });
            let top = camera.ray(i, 0, dx, 0.5).dir;
            let bottom = camera.ray(i, h - 1, dx, 0.5).dir;
            let angle = top.dot(bottom).clamp(-1.0, 1.0).acos().to_degrees();
            assert!((angle - 45.0).abs() < 1e-9, "{w}x{h}: {angle}°");
        }
        // One row has no row-to-row angle: it is taken as the full field.
        assert_eq!(fov_from_nff_angle(45.0, 1), 45.0);
    }

    #[test]
    fn errors_name_line_column_and_entity() {
        let cases = [
            (
                "s 0 0 0 1",
                "s 0 0 zero 1",
                "t.nff:13:7: `s`: expected a number for sphere centre, got `zero`",
            ),
            (
                "s 0 0 0 1",
                "s 0 0 0 nan",
                "t.nff:13:9: `s`: sphere radius must be finite",
            ),
            (
                "p 4",
                "p 99999999999",
                "t.nff:15:3: `p`: vertex count must be a whole number",
            ),
            (
                "p 4",
                "p 2",
                "t.nff:15:1: `p`: a polygon needs at least 3 vertices",
            ),
            (
                "s 0 0 0 1",
                "sphere 0 0 0 1",
                "t.nff:13:1: `sphere`: unknown NFF entity",
            ),
            (
                "angle 40",
                "angle 400",
                "t.nff:6:7: `v`: angle must lie between 0 and 180",
            ),
            (
                "angle 40",
                "angle 0",
                "t.nff:6:7: `v`: angle must lie between 0 and 180, got 0",
            ),
            (
                "resolution 64 48",
                "resolution 0 0",
                "t.nff:8:12: `v`: resolution must be at least 1x1",
            ),
            (
                "from 0 0 5",
                "fro 0 0 5",
                "t.nff:3:1: `v`: expected `from`, got `fro`",
            ),
            (
                "at 0 0 0",
                "at 0 0 5",
                "t.nff:4:4: `v`: eye and lookat coincide",
            ),
            (
                "0.3 20 0 1\n",
                "0.3 20 0 1 wood.tga\n",
                "t.nff:12:28: `f`: an extra field `wood.tga` after the eight numbers",
            ),
            (
                "# a comment\nv\n",
                "nff\nversion 2.0\nv\n",
                "t.nff:1:1: `nff`: this is Sense8's WorldToolKit NFF",
            ),
            (
                "c 0 0 0 1 0 1 0 0.5",
                "c 0 0 0 1 0 0 0 0.5",
                "t.nff:14:1: `c`: cone base and apex coincide",
            ),
            (
                "f 1 0.5 0.2 0.7",
                "f 1 0.5 0.2 1e300",
                "t.nff:12:13: `f`: Kd must lie in [0, 1], got 1e300",
            ),
            (
                "f 1 0.5 0.2 0.7",
                "f 1 -0.5 0.2 0.7",
                "t.nff:12:3: `f`: colour: each component must lie in [0, 1]",
            ),
            (
                "0.3 20 0 1",
                "0.3 20 0.5 0",
                "t.nff:12:28: `f`: index of refraction must lie in [0.01, 100], got 0",
            ),
            (
                "l -5 5 5 1 0 0",
                "l -5 5 5 3.4e38 0 0",
                "t.nff:11:10: `l`: light colour: each component must lie in [0, 1000]",
            ),
        ];
        for (from, to, expected) in cases {
            let message = parse_str(&SCENE.replacen(from, to, 1))
                .unwrap_err()
                .to_string();
            assert!(
                message.contains(expected),
                "for {to:?}:\n  got      {message}\n  expected {expected}"
            );
        }
    }

    #[test]
    fn truncated_files_and_missing_pieces_are_errors() {
        let cut = &SCENE[..SCENE.find("-1 1 -2").unwrap()];
        let message = parse_str(cut).unwrap_err().to_string();
        assert!(
            message.contains("t.nff:15:1: `p`: file ends at line 18 while reading vertex"),
            "{message}"
        );
        // A viewpoint cut short names the line it still needed.
        let message = parse_str("v\nfrom 0 0 5\n").unwrap_err().to_string();
        assert!(
            message.contains("t.nff:1:1: `v`: file ends at line 2 while reading its `at` line"),
            "{message}"
        );
        // An object before any `f` gets a default grey, with a note.
        let early = parse_str(
            "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 45\nhither 1\n\
             resolution 8 8\ns 0 0 0 1\nf 1 0 0 1 0 0 0 0\ns 2 0 0 1\n",
        )
        .unwrap();
        assert_eq!(early.shapes.len(), 2);
        assert_eq!(early.materials[0].name, "default");
        assert_eq!(early.materials[1].name, "f1");
        assert_eq!(*early.shape_materials, [0, 1]);
        assert!(
            early
                .load_notes
                .iter()
                .any(|n| n.contains("t.nff:8:1: `s` comes before any `f`")),
            "{:?}",
            early.load_notes
        );
        assert!(
            parse_str("b 0 0 0\n")
                .unwrap_err()
                .to_string()
                .contains("no `v` viewpoint")
        );
    }
}
