//! Saving a TOML scene: its own text edited in place with `toml_edit`.

use crate::settings::Accel;
use std::path::Path;

use toml_edit::{Array, DocumentMut, Item, TableLike, Value};

use super::mesh_paths::write_mesh_paths;
use super::{LeftOut, SaveError, SaveRequest, SavedText, set, tables_of};
use crate::accel::OctreeParams;
use crate::camera::CameraSpec;
use crate::camera_path::CameraPath;
use crate::material::{Light, Material};
use crate::math::DVec3;
use crate::scene::{MeshMaterialOrigin, Scene};
use crate::settings::{Protocol, RenderSettings};

/// The TOML text of `request` to be written at `destination`.
pub fn scene_toml(request: &SaveRequest, destination: &Path) -> Result<SavedText, SaveError> {
    let loaded = request.loaded;
    let path = request.loaded_path;
    let is_nff = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("nff"));
    if is_nff {
        return Err(SaveError::NotToml {
            path: path.to_owned(),
        });
    }
    let mut doc: DocumentMut = loaded
        .source_text
        .parse()
        .map_err(|e: toml_edit::TomlError| SaveError::Unreadable {
            path: path.to_owned(),
            message: e.message().to_owned(),
        })?;

    write_camera(&mut doc, &loaded.camera, request.camera);
    write_camera_path(&mut doc, loaded.camera_path.as_ref(), request.camera_path);
    write_settings(&mut doc, loaded, request.settings);
    write_octree(&mut doc, &loaded.octree_params, request.octree);
    if request.lights.len() != loaded.lights.len() {
        return Err(SaveError::LightCount {
            loaded: loaded.lights.len(),
            edited: request.lights.len(),
        });
    }
    write_lights(&mut doc, &loaded.lights, request.lights);
    let left_out = write_materials(
        &mut doc,
        &loaded.materials,
        request.materials,
        &loaded.mesh_material_origins,
    );
    write_mesh_paths(&mut doc, path, destination, request.mesh_paths);
    Ok(SavedText {
        text: doc.to_string(),
        left_out: left_out
            .into_iter()
            .map(|name| LeftOut::Material { name })
            .collect(),
    })
}

/// Sets the three numbers at `key` to `new`, rewriting only those that
/// differ from `old`: the others keep the file's spelling (`-3` stays `-3`,
/// not `-3.0`), each its spacing. Anything else at `key` is replaced by
/// the whole triple.
fn set_vec3(t: &mut dyn TableLike, key: &str, old: DVec3, new: DVec3) {
    if let Some(Item::Value(Value::Array(a))) = t.get_mut(key)
        && a.len() == 3
    {
        for (i, (o, n)) in old.to_array().into_iter().zip(new.to_array()).enumerate() {
            if o != n
                && let Some(slot) = a.get_mut(i)
            {
                let mut v = Value::from(n);
                *v.decor_mut() = slot.decor().clone();
                *slot = v;
            }
        }
        return;
    }
    set(t, key, vec3(new));
}

fn vec3(v: DVec3) -> Value {
    Value::Array(Array::from_iter([v.x, v.y, v.z]))
}

/// The table `key` of the document, made if the file has none.
fn table<'d>(doc: &'d mut DocumentMut, key: &str) -> Option<&'d mut dyn TableLike> {
    doc.entry(key)
        .or_insert_with(toml_edit::table)
        .as_table_like_mut()
}

fn write_camera(doc: &mut DocumentMut, loaded: &CameraSpec, camera: &CameraSpec) {
    if loaded == camera {
        return;
    }
    let Some(t) = table(doc, "camera") else {
        return;
    };
    for (key, old, new) in [
        ("eye", loaded.eye, camera.eye),
        ("lookat", loaded.lookat, camera.lookat),
        ("up", loaded.up, camera.up),
    ] {
        if old != new {
            set_vec3(t, key, old, new);
        }
    }
    if loaded.fov != camera.fov {
        set(t, "fov", Value::from(camera.fov));
    }
}

/// The camera path as `[[camera.keyframes]]`, written whole when it
/// differs from the file's (each key with its time, eye, lookat, up, fov).
fn write_camera_path(
    doc: &mut DocumentMut,
    loaded: Option<&CameraPath>,
    path: Option<&CameraPath>,
) {
    if loaded == path {
        return;
    }
    let Some(t) = table(doc, "camera") else {
        return;
    };
    let Some(path) = path else {
        t.remove("keyframes");
        return;
    };
    let mut keys = toml_edit::ArrayOfTables::new();
    for k in path.keys() {
        let mut key = toml_edit::Table::new();
        key.insert("time", toml_edit::value(k.time));
        key.insert("eye", Item::Value(vec3(k.camera.eye)));
        key.insert("lookat", Item::Value(vec3(k.camera.lookat)));
        key.insert("up", Item::Value(vec3(k.camera.up)));
        key.insert("fov", toml_edit::value(k.camera.fov));
        keys.push(key);
    }
    t.insert("keyframes", Item::ArrayOfTables(keys));
}

/// The `[octree]` keys whose values were edited.
fn write_octree(doc: &mut DocumentMut, loaded: &OctreeParams, edited: &OctreeParams) {
    if loaded == edited {
        return;
    }
    let Some(t) = table(doc, "octree") else {
        return;
    };
    for (key, old, new) in [
        ("max_depth", loaded.max_depth, edited.max_depth),
        ("leaf_size", loaded.leaf_size, edited.leaf_size),
        (
            "max_duplication",
            loaded.max_duplication,
            edited.max_duplication,
        ),
        (
            "memory_budget_mib",
            loaded.memory_budget_mib,
            edited.memory_budget_mib,
        ),
    ] {
        if old != new {
            set(t, key, Value::from(i64::from(new)));
        }
    }
    if loaded.cost_driven != edited.cost_driven {
        set(t, "cost_driven", Value::from(edited.cost_driven));
    }
}

fn write_settings(doc: &mut DocumentMut, loaded: &Scene, s: &RenderSettings) {
    if (s.accel == Accel::Octree) != loaded.octree_enabled
        && let Some(t) = table(doc, "octree")
    {
        set(t, "enabled", Value::from(s.accel == Accel::Octree));
    }
    if s.protocol != Protocol::Glint {
        return;
    }
    let im = &loaded.image;
    let changed = (
        s.width,
        s.height,
        s.samples,
        s.adaptive,
        s.max_depth,
        s.colors,
        s.sides,
    ) != (
        im.width,
        im.height,
        im.samples,
        im.adaptive,
        im.max_depth,
        im.colors,
        im.sides,
    );
    if !changed {
        return;
    }
    let Some(t) = table(doc, "image") else {
        return;
    };
    for (key, old, new) in [
        ("width", im.width, s.width),
        ("height", im.height, s.height),
        ("max_depth", im.max_depth, s.max_depth),
    ] {
        if old != new {
            set(t, key, Value::from(i64::from(new)));
        }
    }
    if (im.samples, im.adaptive) != (s.samples, s.adaptive) {
        // `aa` says all three settings; `samples` only off or full.
        if (s.adaptive && s.samples > 1) || t.contains_key("aa") {
            t.remove("samples");
            set(t, "aa", Value::from(s.anti_aliasing().name()));
        } else {
            set(t, "samples", Value::from(i64::from(s.samples)));
        }
    }
    if im.colors != s.colors {
        set(t, "colors", Value::from(s.colors.name()));
    }
    if im.sides != s.sides {
        set(t, "sides", Value::from(s.sides.name()));
    }
}

fn write_lights(doc: &mut DocumentMut, loaded: &[Light], lights: &[Light]) {
    if loaded == lights {
        return;
    }
    let Some(item) = doc.get_mut("lights") else {
        return;
    };
    for ((t, old), new) in tables_of(item).into_iter().zip(loaded).zip(lights) {
        if old.position != new.position {
            set_vec3(t, "position", old.position, new.position);
        }
        if old.color != new.color {
            set_vec3(t, "color", old.color, new.color);
        }
    }
}

/// Writes edited materials: the file's own into `[materials]`, a mesh's
/// MTL materials into its object's `materials`. Returns the names of any
/// it has no place for.
fn write_materials(
    doc: &mut DocumentMut,
    loaded: &[Material],
    materials: &[Material],
    origins: &[MeshMaterialOrigin],
) -> Vec<String> {
    let mut left_out = Vec::new();
    for (index, (old, new)) in loaded.iter().zip(materials).enumerate() {
        if old == new {
            continue;
        }
        let origin = origins.iter().find(|o| o.material as usize == index);
        let written = match origin {
            Some(o) => mesh_material_table(doc, o).map(|t| write_material(t, old, new)),
            None => doc
                .get_mut("materials")
                .and_then(Item::as_table_like_mut)
                .and_then(|t| t.get_mut(&old.name))
                .and_then(Item::as_table_like_mut)
                .map(|t| write_material(t, old, new)),
        };
        if written.is_none() {
            left_out.push(old.name.clone());
        }
    }
    left_out
}

/// The table `objects[k].materials.NAME` of a mesh material, made if the
/// file has none.
fn mesh_material_table<'d>(
    doc: &'d mut DocumentMut,
    origin: &MeshMaterialOrigin,
) -> Option<&'d mut dyn TableLike> {
    let object = tables_of(doc.get_mut("objects")?)
        .into_iter()
        .nth(origin.object)?;
    let materials = object.entry("materials").or_insert_with(|| {
        let mut t = toml_edit::Table::new();
        // Only `[objects.materials.NAME]` headers are written.
        t.set_implicit(true);
        Item::Table(t)
    });
    materials
        .as_table_like_mut()?
        .entry(&origin.name)
        .or_insert_with(toml_edit::table)
        .as_table_like_mut()
}

fn write_material(t: &mut dyn TableLike, old: &Material, new: &Material) {
    if old.color != new.color {
        set_vec3(t, "color", old.color, new.color);
    }
    for (key, a, b) in [
        ("kd", old.kd, new.kd),
        ("ks", old.ks, new.ks),
        ("shininess", old.shininess, new.shininess),
        ("reflectivity", old.reflectivity, new.reflectivity),
        ("transparency", old.transparency, new.transparency),
        ("ior", old.ior, new.ior),
    ] {
        if a != b {
            set(t, key, Value::from(b));
        }
    }
}
