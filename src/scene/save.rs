//! Writing a scene back as TOML: the viewer's "Save scene". The scene's own
//! text is edited in place (`toml_edit`), so its comments, its order and
//! every number nobody changed stay as they were; only values that differ
//! from the scene as loaded are written.

use std::ops::Range;
use std::path::{Path, PathBuf};

use toml_edit::{Array, DocumentMut, Item, TableLike, Value};

use super::{MeshMaterialOrigin, Scene};
use crate::camera::CameraSpec;
use crate::material::{Light, Material};
use crate::math::DVec3;
use crate::settings::{Protocol, RenderSettings};

/// Why a scene cannot be written as TOML.
#[derive(Debug, thiserror::Error)]
pub enum SaveError {
    #[error(
        "{path} is an NFF scene: it is saved as NFF (name the file .nff); TOML has no cones or polygons"
    )]
    NotToml { path: PathBuf },
    #[error("{path} is not an NFF scene: it is saved as TOML (name the file .toml)")]
    NotNff { path: PathBuf },
    #[error("the scene text of {path} is not TOML glint can edit: {message}")]
    Unreadable { path: PathBuf, message: String },
    #[error("the edited scene has {edited} lights where its file has {loaded}")]
    LightCount { loaded: usize, edited: usize },
}

/// Where the saved file's meshes are found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MeshPaths {
    /// As the scene file says, anchored at the folder it was loaded from:
    /// kept when saving into that folder, made absolute elsewhere.
    Anchored,
    /// Beside the saved file, under their own file names (the built-in
    /// scene, whose mesh the caller writes there).
    Beside,
}

/// What to save: the scene as loaded and as edited.
pub struct SaveRequest<'a> {
    /// The scene as its file describes it: values equal to these are left
    /// as the file writes them.
    pub loaded: &'a Scene,
    /// The file it was loaded from (anchors relative mesh paths).
    pub loaded_path: &'a Path,
    /// The camera to save.
    pub camera: &'a CameraSpec,
    /// Lights as edited (as many as the scene has).
    pub lights: &'a [Light],
    /// Materials as edited (the scene's, in its order).
    pub materials: &'a [Material],
    /// Image size, samples, depth, colours, sides and the octree switch.
    /// Under the SPD protocol the image settings are the protocol's, not
    /// the scene's, so only the octree switch is written.
    pub settings: &'a RenderSettings,
    pub mesh_paths: MeshPaths,
}

/// A saved scene's text, and what it could not hold.
#[derive(Clone, Debug, PartialEq)]
pub struct SavedText {
    pub text: String,
    /// Edits the format has no place for, each said in a few words (e.g.
    /// "samples", "the reflectivity of f2"): they are not in `text`.
    pub left_out: Vec<String>,
}

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
    write_settings(&mut doc, loaded, request.settings);
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
            .map(|name| format!("material {name}"))
            .collect(),
    })
}

/// The NFF text of `request`: the loaded file with the numbers the viewer
/// edits (viewpoint, resolution, lights, `f` materials) rewritten and
/// everything else, comments included, as it was. What NFF cannot say
/// (samples, depth, colours, sides, the octree switch, a reflectivity
/// apart from Ks) is listed in `left_out`.
pub fn scene_nff(request: &SaveRequest) -> Result<SavedText, SaveError> {
    let loaded = request.loaded;
    let path = request.loaded_path;
    let is_nff = path
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("nff"));
    if !is_nff {
        return Err(SaveError::NotNff {
            path: path.to_owned(),
        });
    }
    let text = &*loaded.source_text;
    let layout = super::nff::layout(text, path).map_err(|e| SaveError::Unreadable {
        path: path.to_owned(),
        message: e.to_string(),
    })?;
    if request.lights.len() != loaded.lights.len() {
        return Err(SaveError::LightCount {
            loaded: loaded.lights.len(),
            edited: request.lights.len(),
        });
    }
    let number = |x: f64| format!("{x:?}");
    let mut edits: Vec<(Range<usize>, String)> = Vec::new();
    let mut put = |ranges: &[Range<usize>], values: &[f64]| {
        for (r, &x) in ranges.iter().zip(values) {
            edits.push((r.clone(), number(x)));
        }
    };
    let mut left_out = Vec::new();

    let s = request.settings;
    let im = &loaded.image;
    let resize = s.protocol == Protocol::Glint && (s.width, s.height) != (im.width, im.height);
    let rows = if resize { s.height } else { im.height };
    if let Some(view) = &layout.view {
        let (old, new) = (&loaded.camera, request.camera);
        for (ranges, a, b) in [
            (&view.from, old.eye, new.eye),
            (&view.at, old.lookat, new.lookat),
            (&view.up, old.up, new.up),
        ] {
            if a != b {
                put(ranges, &b.to_array());
            }
        }
        // NFF's angle depends on the row count; the field of view is kept.
        if old.fov != new.fov || resize {
            put(
                std::slice::from_ref(&view.angle),
                &[super::nff::nff_angle_from_fov(new.fov, rows)],
            );
        }
        if resize {
            edits.push((view.resolution[0].clone(), s.width.to_string()));
            edits.push((view.resolution[1].clone(), s.height.to_string()));
        }
    }
    if s.protocol == Protocol::Glint {
        for (what, differs) in [
            (
                "samples",
                (s.samples, s.adaptive) != (im.samples, im.adaptive),
            ),
            ("max depth", s.max_depth != im.max_depth),
            ("colours", s.colors != im.colors),
            ("sides", s.sides != im.sides),
        ] {
            if differs {
                left_out.push(what.to_owned());
            }
        }
    }
    if s.use_octree != loaded.octree_enabled {
        left_out.push("the octree switch".to_owned());
    }

    for ((place, old), new) in layout.lights.iter().zip(&loaded.lights).zip(request.lights) {
        let mut put = |ranges: &[Range<usize>], values: &[f64]| {
            for (r, &x) in ranges.iter().zip(values) {
                edits.push((r.clone(), number(x)));
            }
        };
        if old.position != new.position {
            put(&place.position, &new.position.to_array());
        }
        if old.color != new.color {
            match &place.color {
                Some(ranges) => put(ranges, &new.color.to_array()),
                None => {
                    let end = place.position[2].end;
                    let c = new.color;
                    edits.push((
                        end..end,
                        format!(" {} {} {}", number(c.x), number(c.y), number(c.z)),
                    ));
                }
            }
        }
    }

    for (i, (old, new)) in loaded.materials.iter().zip(request.materials).enumerate() {
        if old == new {
            continue;
        }
        // NFF has one coefficient for the highlight and the mirror ray, and
        // weights the ambient term by Kd.
        if new.reflectivity != new.ks {
            left_out.push(format!("the reflectivity of {} (NFF uses Ks)", old.name));
        }
        // Every number of the material's `f` lines is written: the file's
        // own may differ from the loaded value (an opaque material's index
        // of refraction is often written 0 and loaded as 1).
        let values = [
            new.color.x,
            new.color.y,
            new.color.z,
            new.kd,
            new.ks,
            new.shininess,
            new.transparency,
            new.ior,
        ];
        for entity in layout.materials.get(i).into_iter().flatten() {
            for (r, &x) in entity.iter().zip(&values) {
                edits.push((r.clone(), number(x)));
            }
        }
    }
    // NFF gives one material to equal `f` lines: materials edited to be
    // equal are one material when the file is read again.
    let nff_key = |m: &Material| {
        [
            m.color.x,
            m.color.y,
            m.color.z,
            m.kd,
            m.ks,
            m.shininess,
            m.transparency,
            m.ior,
        ]
    };
    for (i, a) in request.materials.iter().enumerate() {
        if let Some(b) = request.materials[..i]
            .iter()
            .find(|b| nff_key(b) == nff_key(a))
        {
            left_out.push(format!(
                "{} apart from {} (equal materials are one in NFF)",
                a.name, b.name
            ));
        }
    }

    edits.sort_by_key(|(r, _)| (r.start, r.end));
    let mut out = String::with_capacity(text.len() + 64 * edits.len());
    let mut at = 0;
    for (r, new) in edits {
        out.push_str(&text[at..r.start]);
        out.push_str(&new);
        at = r.end;
    }
    out.push_str(&text[at..]);
    Ok(SavedText {
        text: out,
        left_out,
    })
}

/// Sets `key` in `table` to `new`, keeping the old value's surrounding
/// whitespace and trailing comment.
fn set(table: &mut dyn TableLike, key: &str, mut new: Value) {
    match table.get_mut(key) {
        Some(Item::Value(old)) => {
            *new.decor_mut() = old.decor().clone();
            *old = new;
        }
        _ => {
            table.insert(key, Item::Value(new));
        }
    }
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
            set(t, key, vec3(new));
        }
    }
    if loaded.fov != camera.fov {
        set(t, "fov", Value::from(camera.fov));
    }
}

fn write_settings(doc: &mut DocumentMut, loaded: &Scene, s: &RenderSettings) {
    if s.use_octree != loaded.octree_enabled
        && let Some(t) = table(doc, "octree")
    {
        set(t, "enabled", Value::from(s.use_octree));
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

/// The tables of an array of tables (`[[lights]]`) or of an inline array
/// of tables (`lights = [{ ... }]`).
fn tables_of(item: &mut Item) -> Vec<&mut dyn TableLike> {
    match item {
        Item::ArrayOfTables(a) => a.iter_mut().map(|t| t as &mut dyn TableLike).collect(),
        Item::Value(Value::Array(a)) => a
            .iter_mut()
            .filter_map(|v| v.as_inline_table_mut().map(|t| t as &mut dyn TableLike))
            .collect(),
        _ => Vec::new(),
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
            set(t, "position", vec3(new.position));
        }
        if old.color != new.color {
            set(t, "color", vec3(new.color));
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
        set(t, "color", vec3(new.color));
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

/// Rewrites relative mesh paths so the saved file finds the same meshes.
fn write_mesh_paths(doc: &mut DocumentMut, loaded_path: &Path, destination: &Path, how: MeshPaths) {
    let from = folder(loaded_path);
    let to = folder(destination);
    let same_folder = match (std::fs::canonicalize(&from), std::fs::canonicalize(&to)) {
        (Ok(a), Ok(b)) => a == b,
        _ => std::path::absolute(&from).ok() == std::path::absolute(&to).ok(),
    };
    if how == MeshPaths::Anchored && same_folder {
        return;
    }
    let Some(item) = doc.get_mut("objects") else {
        return;
    };
    for t in tables_of(item) {
        let Some(old) = t.get("path").and_then(Item::as_str).map(PathBuf::from) else {
            continue;
        };
        let new = match how {
            MeshPaths::Beside => match old.file_name() {
                Some(name) => PathBuf::from(name),
                None => continue,
            },
            MeshPaths::Anchored if old.is_absolute() => continue,
            MeshPaths::Anchored => {
                let joined = from.join(&old);
                std::fs::canonicalize(&joined)
                    .or_else(|_| std::path::absolute(&joined))
                    .unwrap_or(joined)
            }
        };
        // A path that is not UTF-8 cannot be written in TOML; it stays.
        if let Some(s) = new.to_str() {
            set(t, "path", Value::from(s));
        }
    }
}

/// The folder a file is in (`.` for a bare name).
fn folder(file: &Path) -> PathBuf {
    match file.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_owned(),
        _ => PathBuf::from("."),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::Light;
    use crate::scene::{MeshSource, load_str};

    struct NoMeshes;
    impl MeshSource for NoMeshes {
        fn read(&self, _: &Path) -> std::io::Result<Vec<u8>> {
            Err(std::io::ErrorKind::NotFound.into())
        }
    }

    const TEXT: &str = "# A test scene.\n[camera]\neye = [0, 1, 5] # over the floor\nlookat = [0, 0, 0]\n\
        up = [0, 1, 0]\nfov = 40\n\n[image]\nwidth = 64\nheight = 48\n\n\
        [materials.red]\ncolor = [0.8, 0.1, 0.1] # brick\nkd = 0.7\n\n\
        [[lights]]\nposition = [1, 5, 1]\n\n\
        [[objects]]\nkind = \"sphere\"\nmaterial = \"red\"\ncenter = [0, 0, 0]\nradius = 1\n";

    fn scene(text: &str) -> Scene {
        load_str(text, Path::new("dir/scene.toml"), &NoMeshes).unwrap()
    }

    fn request<'a>(
        loaded: &'a Scene,
        camera: &'a CameraSpec,
        settings: &'a RenderSettings,
    ) -> SaveRequest<'a> {
        SaveRequest {
            loaded,
            loaded_path: Path::new("dir/scene.toml"),
            camera,
            lights: &loaded.lights,
            materials: &loaded.materials,
            settings,
            mesh_paths: MeshPaths::Anchored,
        }
    }

    #[test]
    fn an_unedited_scene_is_saved_byte_for_byte() {
        let loaded = scene(TEXT);
        let settings = loaded.render_settings();
        let saved = scene_toml(
            &request(&loaded, &loaded.camera, &settings),
            Path::new("dir/scene.toml"),
        )
        .unwrap();
        assert_eq!(saved.text, TEXT);
        assert!(saved.left_out.is_empty());
    }

    #[test]
    fn edits_are_written_and_comments_and_untouched_numbers_kept() {
        let loaded = scene(TEXT);
        let mut camera = loaded.camera;
        camera.eye = DVec3::new(1e100, -2.5e-300, 0.1);
        camera.fov = 12.5;
        let mut settings = loaded.render_settings();
        settings.width = 640;
        settings.samples = 16;
        settings.adaptive = true;
        settings.use_octree = false;
        let mut lights = loaded.lights.clone();
        lights[0].color = DVec3::new(0.5, 0.25, 1.0);
        let mut materials = loaded.materials.clone();
        materials[0].kd = 0.123456789;
        let req = SaveRequest {
            lights: &lights,
            materials: &materials,
            ..request(&loaded, &camera, &settings)
        };
        let saved = scene_toml(&req, Path::new("dir/scene.toml")).unwrap();
        let text = &saved.text;
        for kept in [
            "# A test scene.\n",
            "# over the floor\n",
            "color = [0.8, 0.1, 0.1] # brick\n",
            "lookat = [0, 0, 0]\n",
            "height = 48\n",
            "position = [1, 5, 1]\n",
        ] {
            assert!(text.contains(kept), "lost {kept:?} in\n{text}");
        }
        let again = scene(text);
        assert_eq!(again.camera, camera);
        assert_eq!(again.lights, lights);
        assert_eq!(again.materials, materials);
        assert_eq!(again.render_settings(), settings);
        assert!(!again.octree_enabled);
        assert_eq!((again.image.samples, again.image.adaptive), (16, true));
    }

    /// Files by name, from memory.
    struct Files(&'static [(&'static str, &'static str)]);
    impl MeshSource for Files {
        fn read(&self, path: &Path) -> std::io::Result<Vec<u8>> {
            let name = path.file_name().and_then(|n| n.to_str());
            match self.0.iter().find(|(file, _)| Some(*file) == name) {
                Some((_, text)) => Ok(text.as_bytes().to_vec()),
                None => Err(std::io::ErrorKind::NotFound.into()),
            }
        }
    }

    /// An OBJ and its MTL.
    const MODEL: Files = Files(&[
        (
            "m.obj",
            "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n\
             usemtl red\nf 1 2 3\nusemtl white\nf 2 4 3\nusemtl nowhere\nf 1 2 4\n",
        ),
        (
            "m.mtl",
            "newmtl red\nKd 0.8 0.1 0.1\nnewmtl white\nKd 0.9 0.9 0.9\n",
        ),
    ]);

    #[test]
    fn edits_to_a_meshs_own_materials_are_written_into_its_object() {
        // One object in an array of tables, one in an inline array, so both
        // TOML forms are covered; the second mesh's materials get new names.
        for objects in [
            "[[objects]]\nkind = \"mesh\"\npath = \"m.obj\" # the model\n\n\
             [[objects]]\nkind = \"mesh\"\npath = \"m.obj\"\ntranslate = [2, 0, 0]\n",
            "objects = [{ kind = \"mesh\", path = \"m.obj\" }, \
             { kind = \"mesh\", path = \"m.obj\", translate = [2, 0, 0] }]\n",
        ] {
            // An inline array must come before the first table header.
            let camera =
                "[camera]\neye = [0, 0, 5]\nlookat = [0, 0, 0]\nup = [0, 1, 0]\nfov = 40\n";
            let text = if objects.starts_with("[[") {
                format!("{camera}{objects}")
            } else {
                format!("{objects}{camera}")
            };
            let path = Path::new("dir/scene.toml");
            let loaded = load_str(&text, path, &MODEL).unwrap();
            let names: Vec<&str> = loaded.materials.iter().map(|m| m.name.as_str()).collect();
            assert_eq!(
                names,
                [
                    "red",
                    "white",
                    "default",
                    "red (2)",
                    "white (2)",
                    "default (2)"
                ]
            );
            let settings = loaded.render_settings();
            let mut materials = loaded.materials.clone();
            // The second mesh's white, and the first mesh's default.
            materials[4].color = DVec3::new(0.25, 0.5, 0.75);
            materials[4].reflectivity = 0.5;
            materials[2].kd = 0.125;
            let req = SaveRequest {
                materials: &materials,
                ..request(&loaded, &loaded.camera, &settings)
            };
            let saved = scene_toml(&req, path).unwrap();
            assert!(saved.left_out.is_empty(), "{saved:?}");
            let again = load_str(&saved.text, path, &MODEL).unwrap_or_else(|e| {
                panic!("{e}\n{}", saved.text);
            });
            assert_eq!(again.materials, materials, "{}", saved.text);
            assert_eq!(again.shape_materials, loaded.shape_materials);
            if objects.starts_with("[[") {
                assert!(saved.text.contains("# the model"), "{}", saved.text);
                assert!(
                    saved.text.contains("[objects.materials.white]"),
                    "{}",
                    saved.text
                );
            }
            // Saving the saved scene unchanged changes nothing.
            let req = SaveRequest {
                materials: &again.materials,
                ..request(&again, &again.camera, &settings)
            };
            assert_eq!(scene_toml(&req, path).unwrap().text, saved.text);
        }
    }

    /// An OBJ whose MTL names a material `default`, with faces that name
    /// a material no library defines.
    const DEFAULT_CLASH: Files = Files(&[
        (
            "m.obj",
            "mtllib m.mtl\nv 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\n\
             usemtl default\nf 1 2 3\nusemtl nowhere\nf 2 4 3\n",
        ),
        ("m.mtl", "newmtl default\nKd 0.8 0.1 0.1\n"),
    ]);

    #[test]
    fn a_material_named_default_and_the_fallback_keep_apart_keys() {
        let text = "[camera]\neye = [0, 0, 5]\nlookat = [0, 0, 0]\nup = [0, 1, 0]\nfov = 40\n\
                    [[objects]]\nkind = \"mesh\"\npath = \"m.obj\"\n";
        let path = Path::new("dir/scene.toml");
        let loaded = load_str(text, path, &DEFAULT_CLASH).unwrap();
        assert_eq!(loaded.materials.len(), 2);
        let settings = loaded.render_settings();
        // Each edited on its own: neither edit may reach the other.
        for edited in 0..2 {
            let mut materials = loaded.materials.clone();
            materials[edited].kd = 0.125;
            let req = SaveRequest {
                materials: &materials,
                ..request(&loaded, &loaded.camera, &settings)
            };
            let saved = scene_toml(&req, path).unwrap();
            assert!(saved.left_out.is_empty(), "{saved:?}");
            let again = load_str(&saved.text, path, &DEFAULT_CLASH)
                .unwrap_or_else(|e| panic!("{e}\n{}", saved.text));
            assert_eq!(again.materials, materials, "{}", saved.text);
        }
    }

    #[test]
    fn mesh_material_keys_are_checked() {
        let head = "[camera]\neye = [0, 0, 5]\nlookat = [0, 0, 0]\nup = [0, 1, 0]\nfov = 40\n\
                    [[objects]]\nkind = \"mesh\"\npath = \"m.obj\"\n";
        let error = |tail: &str| {
            load_str(&format!("{head}{tail}"), Path::new("s.toml"), &MODEL)
                .unwrap_err()
                .to_string()
        };
        let e = error("[objects.materials.blue]\nkd = 0.5\n");
        assert!(
            e.contains("s.toml:9:20: `objects[0].materials`: the mesh's faces use no material `blue` (they use: red, white, default)"),
            "{e}"
        );
        let e = error("[objects.materials.red]\nkd = 2\n");
        assert!(
            e.contains("s.toml:10:6: `objects[0].materials.red.kd`"),
            "{e}"
        );
        let e = error("material = \"x\"\n");
        assert!(e.contains("no material named `x`"), "{e}");
    }

    const NFF: &str = "# balls, cut down\nv\nfrom 2.1 1.3 1.7\nat 0 0 0.2\nup 0 0 1\n\
        angle 45\nhither 0.01\nresolution 512 512\nb 0.078 0.361 0.753\n\
        l 4 3 2   # key\nl 1 -4 4 0.5 0.5 0.5\n\
        f 1 0.75 0.33 0.8 0 100000 0 1\ns 0 0 0 0.5\n\
        f 1 0.9 0.7 0 0.5 45.2776 0 0\ns 0.27 0.27 0.27 0.16\n\
        f 1 0.75 0.33 0.8 0 100000 0 1\ns 0 0.5 0 0.1\n";

    fn nff_request<'a>(
        loaded: &'a Scene,
        camera: &'a CameraSpec,
        settings: &'a RenderSettings,
        lights: &'a [Light],
        materials: &'a [Material],
    ) -> SaveRequest<'a> {
        SaveRequest {
            loaded,
            loaded_path: Path::new("dir/balls.nff"),
            camera,
            lights,
            materials,
            settings,
            mesh_paths: MeshPaths::Anchored,
        }
    }

    #[test]
    fn an_nff_scene_is_saved_as_nff_with_its_edits_and_comments() {
        let path = Path::new("dir/balls.nff");
        let loaded = load_str(NFF, path, &NoMeshes).unwrap();
        let settings = loaded.render_settings();
        let unedited = scene_toml(
            &request(&loaded, &loaded.camera, &settings),
            Path::new("x.toml"),
        );
        assert!(unedited.is_err(), "an NFF scene saved as TOML");
        let same = scene_nff(&nff_request(
            &loaded,
            &loaded.camera,
            &settings,
            &loaded.lights,
            &loaded.materials,
        ))
        .unwrap();
        assert_eq!(same.text, NFF);
        assert!(same.left_out.is_empty());

        let mut camera = loaded.camera;
        camera.eye = DVec3::new(1e100, -2.5e-300, 0.1);
        camera.fov = 12.5;
        let mut settings = loaded.render_settings();
        (settings.width, settings.height) = (300, 200);
        settings.samples = 16;
        let mut lights = loaded.lights.clone();
        lights[0].color = DVec3::new(0.25, 0.5, 2.0);
        lights[1].position = DVec3::new(-1.0, 0.0, 7.5);
        let mut materials = loaded.materials.clone();
        materials[0].color = DVec3::new(0.1, 0.2, 0.3);
        materials[0].kd = 0.5;
        materials[0].ka = 0.5;
        materials[1].reflectivity = 0.25;
        let saved = scene_nff(&nff_request(
            &loaded, &camera, &settings, &lights, &materials,
        ))
        .unwrap();
        let text = &saved.text;
        for kept in [
            "# balls, cut down\n",
            "at 0 0 0.2\n",
            "l 4 3 2 0.25 0.5 2.0   # key\n",
            "hither 0.01\n",
            "resolution 300 200\n",
        ] {
            assert!(text.contains(kept), "lost {kept:?} in\n{text}");
        }
        assert_eq!(
            saved.left_out,
            ["samples", "the reflectivity of f2 (NFF uses Ks)"]
        );
        let again = load_str(text, path, &NoMeshes).unwrap();
        assert_eq!(again.camera.eye, camera.eye);
        assert!(
            (again.camera.fov - camera.fov).abs() < 1e-12,
            "{}",
            again.camera.fov
        );
        assert_eq!((again.image.width, again.image.height), (300, 200));
        assert_eq!(again.lights, lights);
        // Both `f` lines of the first material changed.
        assert_eq!(again.materials.len(), 2);
        assert_eq!(again.materials[0], materials[0]);
        assert_eq!(again.materials[1], loaded.materials[1]);
        assert_eq!(again.shape_materials, loaded.shape_materials);
    }

    #[test]
    fn an_nff_material_made_transparent_gets_an_index_the_file_can_load() {
        // Opaque SPD materials write their index of refraction as 0.
        let text = "v\nfrom 0 -4 1\nat 0 0 0\nup 0 0 1\nangle 40\nhither 0.01\n\
                    resolution 8 6\nl 4 -3 5\nf 1 1 1 0.5 0.5 45 0 0\ns 0 0 0 1\n\
                    f 0 1 0 0.5 0.5 45 0 0\ns 2 0 0 1\n";
        let path = Path::new("dir/balls.nff");
        let loaded = load_str(text, path, &NoMeshes).unwrap();
        let settings = loaded.render_settings();
        let mut materials = loaded.materials.clone();
        materials[0].transparency = 0.5;
        let saved = scene_nff(&nff_request(
            &loaded,
            &loaded.camera,
            &settings,
            &loaded.lights,
            &materials,
        ))
        .unwrap();
        let again = load_str(&saved.text, path, &NoMeshes)
            .unwrap_or_else(|e| panic!("{e}\n{}", saved.text));
        assert_eq!(again.materials, materials);
        assert!(saved.left_out.is_empty(), "{:?}", saved.left_out);

        // Made equal, the two are one material when the file is read.
        let mut equal = loaded.materials.clone();
        equal[1].color = equal[0].color;
        let saved = scene_nff(&nff_request(
            &loaded,
            &loaded.camera,
            &settings,
            &loaded.lights,
            &equal,
        ))
        .unwrap();
        assert_eq!(
            saved.left_out,
            ["f2 apart from f1 (equal materials are one in NFF)"]
        );
    }

    #[test]
    fn nff_angles_and_fields_of_view_convert_both_ways() {
        for rows in [1, 2, 3, 48, 512, 32768] {
            for fov in [0.001, 1.0, 45.0, 90.0, 150.0, 179.9] {
                let angle = crate::scene::nff::nff_angle_from_fov(fov, rows);
                let back = crate::scene::nff::fov_from_nff_angle(angle, rows);
                assert!((back - fov).abs() <= 1e-12 * fov, "{rows} {fov} {back}");
            }
        }
    }

    #[test]
    fn nff_scenes_are_not_saved_as_toml() {
        let loaded = scene(TEXT);
        let settings = loaded.render_settings();
        let req = SaveRequest {
            loaded_path: Path::new("balls.nff"),
            ..request(&loaded, &loaded.camera, &settings)
        };
        let e = scene_toml(&req, Path::new("balls.toml")).unwrap_err();
        assert!(matches!(e, SaveError::NotToml { .. }), "{e}");
        assert!(e.to_string().contains("name the file .nff"), "{e}");
    }

    #[test]
    fn mesh_paths_follow_the_file_to_another_folder() {
        let text = "[camera]\neye = [0, 0, 5]\nlookat = [0, 0, 0]\nup = [0, 1, 0]\nfov = 40\n\
                    [[objects]]\nkind = \"mesh\"\npath = \"../models/m.obj\"\n";
        let doc = |how, dest: &str| {
            let mut d: DocumentMut = text.parse().unwrap();
            write_mesh_paths(
                &mut d,
                Path::new("/nonexistent/a/scene.toml"),
                Path::new(dest),
                how,
            );
            d["objects"][0]["path"].as_str().unwrap().to_owned()
        };
        assert_eq!(
            doc(MeshPaths::Anchored, "/nonexistent/a/copy.toml"),
            "../models/m.obj"
        );
        assert_eq!(
            doc(MeshPaths::Anchored, "/nonexistent/b/copy.toml"),
            "/nonexistent/a/../models/m.obj"
        );
        assert_eq!(doc(MeshPaths::Beside, "/nonexistent/a/copy.toml"), "m.obj");
    }
}
