//! glint's own scene format; every key is documented in `scenes/README.md`.

use std::collections::BTreeMap;
use std::ops::Range;
use std::path::Path;

use serde::Deserialize;
use toml::Spanned;

use super::file_source::FileSource;
use super::mesh::{Placement, parse_obj};
use super::model::{ImageSettings, Scene, SceneError};
use crate::accel::OctreeParams;
use crate::camera::CameraSpec;
use crate::limits::{
    INTENSITY_RANGE, IOR_RANGE, MAX_IMAGE_SIDE, MAX_RAY_DEPTH, SHININESS_RANGE, UNIT_RANGE,
};
use crate::material::{Light, Material};
use crate::math::{Aabb, DVec3};
use crate::settings::AntiAliasing;
use crate::shapes::{Plane, Quadric, Shape, Sphere, Triangle};

mod context;
mod keyframes;

use context::{Context, Vec3, deserialize};
pub use keyframes::parse_camera_path;
use keyframes::{KeyframeFile, camera_path};

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct SceneFile {
    camera: CameraFile,
    #[serde(default)]
    image: ImageFile,
    #[serde(default)]
    octree: OctreeFile,
    #[serde(default)]
    materials: BTreeMap<String, MaterialFile>,
    #[serde(default)]
    lights: Vec<LightFile>,
    #[serde(default)]
    objects: Vec<ObjectFile>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CameraFile {
    eye: Vec3,
    lookat: Vec3,
    up: Vec3,
    fov: Spanned<f64>,
    /// The camera path, in increasing time.
    #[serde(default)]
    keyframes: Vec<Spanned<KeyframeFile>>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct ImageFile {
    width: Option<Spanned<i64>>,
    height: Option<Spanned<i64>>,
    samples: Option<Spanned<i64>>,
    max_depth: Option<Spanned<i64>>,
    background: Option<Vec3>,
    ambient: Option<Vec3>,
    colors: Option<Spanned<String>>,
    sides: Option<Spanned<String>>,
    aa: Option<Spanned<String>>,
}

#[derive(Deserialize, Default)]
#[serde(deny_unknown_fields)]
struct OctreeFile {
    enabled: Option<bool>,
    max_depth: Option<Spanned<i64>>,
    leaf_size: Option<Spanned<i64>>,
    max_duplication: Option<Spanned<i64>>,
    memory_budget_mib: Option<Spanned<i64>>,
    cost_driven: Option<bool>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct MaterialFile {
    color: Option<Vec3>,
    kd: Option<Spanned<f64>>,
    ks: Option<Spanned<f64>>,
    shininess: Option<Spanned<f64>>,
    reflectivity: Option<Spanned<f64>>,
    transparency: Option<Spanned<f64>>,
    ior: Option<Spanned<f64>>,
    /// An image file (relative to the scene file) whose colour multiplies
    /// `color` on triangles with texture coordinates, and whose alpha, if it
    /// has one, cuts them out.
    texture: Option<Spanned<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct LightFile {
    position: Vec3,
    color: Option<Vec3>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ClipFile {
    min: Vec3,
    max: Vec3,
}

/// Every key any object kind may have; which ones a kind takes is checked
/// after parsing so that errors keep their place in the file.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ObjectFile {
    kind: Spanned<String>,
    material: Option<Spanned<String>>,
    center: Option<Vec3>,
    radius: Option<Spanned<f64>>,
    point: Option<Vec3>,
    normal: Option<Vec3>,
    vertices: Option<Spanned<[[f64; 3]; 3]>>,
    /// A triangle's texture coordinates, one `[u, v]` per vertex.
    uvs: Option<Spanned<[[f64; 2]; 3]>>,
    coefficients: Option<Spanned<[f64; 10]>>,
    clip: Option<Spanned<ClipFile>>,
    path: Option<Spanned<String>>,
    scale: Option<Spanned<f64>>,
    rotate: Option<Vec3>,
    translate: Option<Vec3>,
    smooth: Option<Spanned<bool>>,
    /// A mesh's own (MTL) materials changed key by key, by their MTL names:
    /// what the viewer's "Save scene" writes for edits to them.
    materials: Option<Spanned<BTreeMap<Spanned<String>, MaterialFile>>>,
}

/// Materials are read with the names and ranges of this format.
impl Context<'_> {
    /// `base` with the keys `m` gives; `prefix` names the table in errors.
    fn material(
        &self,
        mut mat: Material,
        m: &MaterialFile,
        prefix: &str,
    ) -> Result<Material, SceneError> {
        let key = |k: &str| format!("{prefix}.{k}");
        if let Some(v) = &m.color {
            mat.color = self.color(v, &key("color"), &UNIT_RANGE)?;
        }
        for (slot, value, k, range) in [
            (&mut mat.kd, &m.kd, "kd", &UNIT_RANGE),
            (&mut mat.ks, &m.ks, "ks", &UNIT_RANGE),
            (
                &mut mat.shininess,
                &m.shininess,
                "shininess",
                &SHININESS_RANGE,
            ),
            (
                &mut mat.reflectivity,
                &m.reflectivity,
                "reflectivity",
                &UNIT_RANGE,
            ),
            (
                &mut mat.transparency,
                &m.transparency,
                "transparency",
                &UNIT_RANGE,
            ),
            (&mut mat.ior, &m.ior, "ior", &IOR_RANGE),
        ] {
            if let Some(v) = value {
                *slot = self.in_range(v, &key(k), range)?;
            }
        }
        Ok(mat)
    }

    /// Puts the texture `m` names, if any, on the scene's material
    /// `index`: read relative to the scene file, an error at its key if it
    /// cannot be read or decoded.
    fn texture(
        &self,
        scene: &mut Scene,
        index: usize,
        m: &MaterialFile,
        prefix: &str,
        files: &dyn FileSource,
    ) -> Result<(), SceneError> {
        let Some(name) = &m.texture else {
            return Ok(());
        };
        let folder = self.path.parent().unwrap_or(Path::new(""));
        let namer = super::textures::Namer::Scene;
        let texture = super::textures::texture_index(scene, folder, name.get_ref(), namer, files)
            .map_err(|e| self.error(name.span(), &format!("{prefix}.texture"), e))?;
        let map = crate::texture::TextureMap::new(texture, name.get_ref().clone());
        let material = &mut scene.materials[index];
        material.cutout_map = scene.textures[texture as usize]
            .has_alpha
            .then(|| map.clone());
        material.color_map = Some(map);
        Ok(())
    }
}

pub fn parse(text: &str, path: &Path, files: &dyn FileSource) -> Result<Scene, SceneError> {
    let mut cx = Context {
        text,
        path,
        defined_materials: 0,
    };
    let file: SceneFile = deserialize(&cx)?;
    parse_file(&mut cx, &file, path, files)
}

fn parse_file(
    cx: &mut Context,
    file: &SceneFile,
    path: &Path,
    files: &dyn FileSource,
) -> Result<Scene, SceneError> {
    let camera = CameraSpec {
        eye: cx.vec3(&file.camera.eye, "camera.eye")?,
        lookat: cx.vec3(&file.camera.lookat, "camera.lookat")?,
        up: cx.vec3(&file.camera.up, "camera.up")?,
        fov: cx.finite(&file.camera.fov, "camera.fov")?,
    };
    if let Err((key, message)) = camera.check() {
        let span = match key {
            "up" => file.camera.up.span(),
            "fov" => file.camera.fov.span(),
            _ => file.camera.eye.span(),
        };
        return Err(cx.error(span, &format!("camera.{key}"), message));
    }
    let camera_path = camera_path(cx, &file.camera.keyframes, &camera, "camera.keyframes")?;

    let mut image = ImageSettings::default();
    let im = &file.image;
    if let Some(v) = &im.width {
        image.width = cx.integer(v, "image.width", 1..MAX_IMAGE_SIDE as i64 + 1)?;
    }
    if let Some(v) = &im.height {
        image.height = cx.integer(v, "image.height", 1..MAX_IMAGE_SIDE as i64 + 1)?;
    }
    if let Some(v) = &im.samples {
        image.samples = cx.integer(v, "image.samples", 1..17)?;
        if image.samples != 1 && image.samples != AntiAliasing::SAMPLES {
            return Err(cx.error(v.span(), "image.samples", "must be 1 or 16"));
        }
    }
    if let Some(v) = &im.max_depth {
        image.max_depth = cx.integer(v, "image.max_depth", 1..MAX_RAY_DEPTH as i64 + 1)?;
    }
    if let Some(v) = &im.background {
        image.background = cx.color(v, "image.background", &INTENSITY_RANGE)?;
    }
    if let Some(v) = &im.ambient {
        image.ambient = cx.color(v, "image.ambient", &INTENSITY_RANGE)?;
    }
    if let Some(v) = &im.colors {
        image.colors = v
            .get_ref()
            .parse()
            .map_err(|e: String| cx.error(v.span(), "image.colors", e))?;
    }
    if let Some(v) = &im.aa {
        if im.samples.is_some() {
            return Err(cx.error(v.span(), "image.aa", "give `samples` or `aa`, not both"));
        }
        let aa: AntiAliasing = v
            .get_ref()
            .parse()
            .map_err(|e: String| cx.error(v.span(), "image.aa", e))?;
        (image.samples, image.adaptive) = match aa {
            AntiAliasing::Off => (1, false),
            AntiAliasing::Adaptive => (16, true),
            AntiAliasing::Full => (16, false),
        };
    }
    if let Some(v) = &im.sides {
        image.sides = v
            .get_ref()
            .parse()
            .map_err(|e: String| cx.error(v.span(), "image.sides", e))?;
    }

    let mut octree_params = OctreeParams::default();
    if let Some(v) = &file.octree.max_depth {
        octree_params.max_depth = cx.integer(
            v,
            "octree.max_depth",
            0..crate::limits::MAX_OCTREE_DEPTH as i64 + 1,
        )?;
    }
    if let Some(v) = &file.octree.leaf_size {
        octree_params.leaf_size = cx.integer(
            v,
            "octree.leaf_size",
            1..crate::limits::MAX_LEAF_SIZE as i64 + 1,
        )?;
    }
    if let Some(v) = &file.octree.max_duplication {
        octree_params.max_duplication = cx.integer(v, "octree.max_duplication", 1..9)?;
    }
    if let Some(v) = &file.octree.memory_budget_mib {
        octree_params.memory_budget_mib = cx.integer(
            v,
            "octree.memory_budget_mib",
            1..crate::limits::MAX_MEMORY_BUDGET_MIB as i64 + 1,
        )?;
    }

    let mut materials = Vec::new();
    for (name, m) in &file.materials {
        let base = Material {
            name: name.clone(),
            ..Material::default()
        };
        materials.push(cx.material(base, m, &format!("materials.{name}"))?);
    }

    let mut lights = Vec::new();
    for (i, l) in file.lights.iter().enumerate() {
        lights.push(Light {
            position: cx.vec3(&l.position, &format!("lights[{i}].position"))?,
            color: match &l.color {
                Some(c) => cx.color(c, &format!("lights[{i}].color"), &INTENSITY_RANGE)?,
                None => DVec3::ONE,
            },
        });
    }

    let mut scene = Scene::empty(path.display().to_string(), camera, image);
    scene.camera_path = camera_path;
    scene.octree_enabled = file.octree.enabled.unwrap_or(true);
    if let Some(v) = file.octree.cost_driven {
        octree_params.cost_driven = v;
    }
    scene.octree_params = octree_params;
    cx.defined_materials = materials.len();
    scene.materials = materials;
    for (index, (name, m)) in file.materials.iter().enumerate() {
        cx.texture(&mut scene, index, m, &format!("materials.{name}"), files)?;
    }
    scene.lights = lights;
    for (i, obj) in file.objects.iter().enumerate() {
        add_object(cx, &mut scene, i, obj, files)?;
    }
    if file.octree.leaf_size.is_none() {
        scene.octree_params.leaf_size = OctreeParams::default_for(&scene.shapes).leaf_size;
    }
    Ok(scene)
}

fn add_object(
    cx: &Context,
    scene: &mut Scene,
    index: usize,
    obj: &ObjectFile,
    files: &dyn FileSource,
) -> Result<(), SceneError> {
    let key = |k: &str| format!("objects[{index}].{k}");
    let kind = obj.kind.get_ref().as_str();
    // Only the file's own materials: a mesh's MTL materials are appended
    // behind them as meshes load.
    let named = match &obj.material {
        Some(name) => Some(
            scene.materials[..cx.defined_materials]
                .iter()
                .position(|m| m.name == *name.get_ref())
                .ok_or_else(|| {
                    let known: Vec<&str> = scene.materials[..cx.defined_materials]
                        .iter()
                        .map(|m| m.name.as_str())
                        .collect();
                    let defined = if known.is_empty() {
                        format!(
                            "the scene defines no materials: add a `[materials.{}]` table",
                            name.get_ref()
                        )
                    } else {
                        format!("defined: {}", known.join(", "))
                    };
                    cx.error(
                        name.span(),
                        &key("material"),
                        format!("no material named `{}` ({defined})", name.get_ref()),
                    )
                })? as u32,
        ),
        None => None,
    };
    let material = match (named, kind) {
        (Some(m), _) => m,
        // A mesh without `material` uses its file's own materials.
        (None, "mesh") => u32::MAX,
        (None, _) => {
            return Err(cx.error(
                obj.kind.span(),
                &key("material"),
                format!("a {kind} needs `material` (only a mesh may use its file's materials)"),
            ));
        }
    };

    // Which keys each kind takes; anything else present is a mistake.
    let allowed: &[&str] = match kind {
        "sphere" => &["center", "radius"],
        "plane" => &["point", "normal"],
        "triangle" => &["vertices", "uvs"],
        "quadric" => &["coefficients", "clip"],
        "mesh" => &[
            "path",
            "scale",
            "rotate",
            "translate",
            "smooth",
            "materials",
        ],
        _ => {
            return Err(cx.error(
                obj.kind.span(),
                &key("kind"),
                format!(
                    "unknown kind `{kind}` (expected sphere, plane, triangle, quadric or mesh)"
                ),
            ));
        }
    };
    let present: [(&str, Option<Range<usize>>); 14] = [
        ("center", obj.center.as_ref().map(Spanned::span)),
        ("radius", obj.radius.as_ref().map(Spanned::span)),
        ("point", obj.point.as_ref().map(Spanned::span)),
        ("normal", obj.normal.as_ref().map(Spanned::span)),
        ("vertices", obj.vertices.as_ref().map(Spanned::span)),
        ("uvs", obj.uvs.as_ref().map(Spanned::span)),
        ("coefficients", obj.coefficients.as_ref().map(Spanned::span)),
        ("clip", obj.clip.as_ref().map(Spanned::span)),
        ("path", obj.path.as_ref().map(Spanned::span)),
        ("scale", obj.scale.as_ref().map(Spanned::span)),
        ("rotate", obj.rotate.as_ref().map(Spanned::span)),
        ("translate", obj.translate.as_ref().map(Spanned::span)),
        ("smooth", obj.smooth.as_ref().map(Spanned::span)),
        ("materials", obj.materials.as_ref().map(Spanned::span)),
    ];
    for (name, span) in &present {
        if let Some(span) = span
            && !allowed.contains(name)
        {
            return Err(cx.error(
                span.clone(),
                &key(name),
                format!("`{name}` does not apply to a {kind}"),
            ));
        }
    }
    let missing = |name: &str| {
        cx.error(
            obj.kind.span(),
            &key(name),
            format!("a {kind} needs `{name}`"),
        )
    };

    match kind {
        "sphere" => {
            let Some(c) = &obj.center else {
                return Err(missing("center"));
            };
            let Some(r) = &obj.radius else {
                return Err(missing("radius"));
            };
            let center = cx.vec3(c, &key("center"))?;
            let radius = cx.finite(r, &key("radius"))?;
            if radius <= 0.0 {
                return Err(cx.error(
                    r.span(),
                    &key("radius"),
                    format!("must be positive, got {radius}"),
                ));
            }
            scene.push(Shape::Sphere(Sphere::new(center, radius)), material);
        }
        "plane" => {
            let Some(point) = &obj.point else {
                return Err(missing("point"));
            };
            let Some(n) = &obj.normal else {
                return Err(missing("normal"));
            };
            let point = cx.vec3(point, &key("point"))?;
            let normal = cx.vec3(n, &key("normal"))?;
            if !(normal.length() > 0.0) {
                return Err(cx.error(n.span(), &key("normal"), "must not be the zero vector"));
            }
            scene.push(Shape::Plane(Plane::new(point, normal)), material);
        }
        "triangle" => {
            let Some(v) = &obj.vertices else {
                return Err(missing("vertices"));
            };
            let vertices = v.get_ref().map(DVec3::from);
            if !vertices.iter().all(|p| p.is_finite()) {
                return Err(cx.error(v.span(), &key("vertices"), "must be finite numbers"));
            }
            let uvs = match &obj.uvs {
                Some(t) if !t.get_ref().iter().flatten().all(|x| x.is_finite()) => {
                    return Err(cx.error(t.span(), &key("uvs"), "must be finite numbers"));
                }
                t => t.as_ref().map(|t| *t.get_ref()),
            };
            match Triangle::new(vertices) {
                Some(t) => {
                    scene.push(Shape::Triangle(t), material);
                    if let Some(uvs) = uvs {
                        scene.set_uvs(scene.shapes.len() - 1, uvs);
                    }
                }
                None => scene.dropped_triangles += 1,
            }
        }
        "quadric" => {
            let Some(c) = &obj.coefficients else {
                return Err(missing("coefficients"));
            };
            let coefficients = *c.get_ref();
            if !coefficients.iter().all(|x| x.is_finite()) {
                return Err(cx.error(c.span(), &key("coefficients"), "must be ten finite numbers"));
            }
            if coefficients[..9].iter().all(|&x| x == 0.0) {
                return Err(cx.error(
                    c.span(),
                    &key("coefficients"),
                    "A to I are all zero: no surface",
                ));
            }
            let clip = match &obj.clip {
                None => None,
                Some(clip) => {
                    let min = cx.vec3(&clip.get_ref().min, &key("clip.min"))?;
                    let max = cx.vec3(&clip.get_ref().max, &key("clip.max"))?;
                    let b = Aabb::new(min, max);
                    if b.is_empty() {
                        return Err(cx.error(
                            clip.span(),
                            &key("clip"),
                            "clip.min must not exceed clip.max",
                        ));
                    }
                    Some(b)
                }
            };
            scene.push(
                Shape::Quadric(Box::new(Quadric::new(coefficients, clip))),
                material,
            );
        }
        "mesh" => {
            let Some(p) = &obj.path else {
                return Err(missing("path"));
            };
            let mesh_path = cx.path.parent().unwrap_or(Path::new("")).join(p.get_ref());
            let scale = match &obj.scale {
                Some(s) => {
                    let x = cx.finite(s, &key("scale"))?;
                    if x <= 0.0 {
                        return Err(cx.error(s.span(), &key("scale"), "must be positive"));
                    }
                    x
                }
                None => 1.0,
            };
            let placement = Placement {
                scale,
                rotate_degrees: obj
                    .rotate
                    .as_ref()
                    .map_or(Ok(DVec3::ZERO), |v| cx.vec3(v, &key("rotate")))?,
                translate: obj
                    .translate
                    .as_ref()
                    .map_or(Ok(DVec3::ZERO), |v| cx.vec3(v, &key("translate")))?,
            };
            let mesh_error = |message: String| SceneError::Mesh {
                location: cx.location(p.span(), &key("path")),
                mesh: mesh_path.clone(),
                message,
            };
            let bytes = files
                .read(&mesh_path)
                .map_err(|e| mesh_error(format!("cannot read: {e}")))?;
            let mesh = parse_obj(
                &bytes,
                obj.smooth.as_ref().map(|s| *s.get_ref()),
                &placement,
            )
            .map_err(mesh_error)?;
            scene.dropped_polygons.zero_area += mesh.dropped_polygons.zero_area;
            scene.dropped_polygons.not_simple += mesh.dropped_polygons.not_simple;
            if !mesh.dropped_lines.is_empty() {
                let lines: Vec<String> = mesh.dropped_lines.iter().map(u32::to_string).collect();
                let total = mesh.dropped_polygons.total();
                scene.load_notes.push(format!(
                    "{}: faces dropped at line{} {}{}",
                    mesh_path.display(),
                    if total == 1 { "" } else { "s" },
                    lines.join(", "),
                    if total > lines.len() {
                        format!(" and {} more", total - lines.len())
                    } else {
                        String::new()
                    }
                ));
            }
            scene.meshes.push(super::model::MeshCounts {
                path: mesh_path.display().to_string(),
                triangles: mesh.triangles.len(),
                folded_quads: mesh.folded_quads,
                dropped_polygons: mesh.dropped_polygons,
                skipped_elements: mesh.skipped.clone(),
                header: mesh.header.clone(),
            });
            if mesh.folded_quads > 0 {
                scene.load_notes.push(format!(
                    "{}: {} folded (self-crossing) quads split into their two triangles",
                    mesh_path.display(),
                    mesh.folded_quads
                ));
            }
            scene.skipped_elements.add(&mesh.skipped);
            if named.is_some() {
                if let Some(m) = &obj.materials {
                    return Err(cx.error(
                        m.span(),
                        &key("materials"),
                        "`materials` changes a mesh's own materials; with `material` it has none",
                    ));
                }
                scene.push_mesh(
                    mesh.triangles,
                    mesh.normals,
                    &mesh.colors,
                    &mesh.uvs,
                    |_| material,
                );
            } else {
                let (slots, default) =
                    super::mesh_materials::mesh_materials(scene, &mesh, &mesh_path, files);
                let origins = super::mesh_materials::slot_names(&mesh, &slots, default);
                if let Some(overrides) = &obj.materials {
                    for (name, m) in overrides.get_ref() {
                        let targets: Vec<u32> = origins
                            .iter()
                            .filter(|(_, n)| n == name.get_ref())
                            .map(|&(i, _)| i)
                            .collect();
                        if targets.is_empty() {
                            let known: Vec<&str> =
                                origins.iter().map(|(_, n)| n.as_str()).collect();
                            return Err(cx.error(
                                name.span(),
                                &key("materials"),
                                format!(
                                    "the mesh's faces use no material `{}` (they use: {})",
                                    name.get_ref(),
                                    known.join(", ")
                                ),
                            ));
                        }
                        let prefix = key(&format!("materials.{}", name.get_ref()));
                        for i in targets {
                            let base = scene.materials[i as usize].clone();
                            scene.materials[i as usize] = cx.material(base, m, &prefix)?;
                            cx.texture(scene, i as usize, m, &prefix, files)?;
                        }
                    }
                }
                scene
                    .mesh_material_origins
                    .extend(origins.into_iter().map(|(material, name)| {
                        super::model::MeshMaterialOrigin {
                            material,
                            object: index,
                            name,
                        }
                    }));
                let per_triangle = &mesh.triangle_materials;
                scene.push_mesh(mesh.triangles, mesh.normals, &mesh.colors, &mesh.uvs, |i| {
                    slots[per_triangle[i] as usize]
                });
            }
        }
        _ => unreachable!("kinds were checked above"),
    }
    Ok(())
}

#[cfg(test)]
mod tests;
