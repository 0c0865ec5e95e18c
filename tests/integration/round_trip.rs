//! Every scene text glint writes loads back to the same scene: the scene
//! inside an export's record (with the viewer's light and material edits),
//! the scene glint writes around an OBJ model opened on its own, and a
//! scene saved with the viewer's edits.

use glint::settings::Accel;
use std::path::Path;

use glint::export::RenderRecord;
use glint::export::{SceneEdits, load_recorded_scene_with, png_bytes, read_record_bytes};
use glint::material::{Light, Material};
use glint::math::DVec3;
use glint::scene::{FileSource, Scene};
use proptest::prelude::*;

/// Scene and model files held in memory, by extension.
struct Files {
    scene: String,
    obj: Vec<u8>,
    mtl: Vec<u8>,
}

impl FileSource for Files {
    fn read(&self, path: &Path) -> std::io::Result<Vec<u8>> {
        match path.extension().and_then(|e| e.to_str()) {
            Some("toml") => Ok(self.scene.clone().into_bytes()),
            Some("obj") => Ok(self.obj.clone()),
            Some("mtl") => Ok(self.mtl.clone()),
            _ => Err(std::io::ErrorKind::NotFound.into()),
        }
    }
}

/// What a scene file says, compared field by field (the text itself and
/// the notes about loading may differ).
fn assert_same(a: &Scene, b: &Scene) -> Result<(), TestCaseError> {
    prop_assert_eq!(a.camera, b.camera);
    prop_assert_eq!(&a.image, &b.image);
    prop_assert_eq!(a.octree_enabled, b.octree_enabled);
    prop_assert_eq!(a.octree_params, b.octree_params);
    prop_assert_eq!(&a.materials, &b.materials);
    prop_assert_eq!(&a.lights, &b.lights);
    prop_assert_eq!(&a.shapes, &b.shapes);
    prop_assert_eq!(&a.shape_materials, &b.shape_materials);
    prop_assert_eq!(&a.vertex_normals, &b.vertex_normals);
    Ok(())
}

/// Numbers as a user writes them, over many magnitudes and signs.
fn number() -> impl Strategy<Value = f64> + Clone {
    prop_oneof![
        -10.0..10.0f64,
        (-300i32..300, -1.0..1.0f64).prop_map(|(e, m)| m * 10f64.powi(e)),
        Just(0.0),
        Just(-0.0),
    ]
}

fn unit() -> impl Strategy<Value = f64> + Clone {
    prop_oneof![0.0..=1.0f64, Just(0.0), Just(1.0)]
}

fn vec3(s: impl Strategy<Value = f64> + Clone) -> impl Strategy<Value = [f64; 3]> {
    [s.clone(), s.clone(), s]
}

fn text3(v: [f64; 3]) -> String {
    // `{:?}` writes the shortest text that reads back as the same f64.
    format!("[{:?}, {:?}, {:?}]", v[0], v[1], v[2])
}

/// A TOML scene with materials, lights, a sphere, a triangle, a plane, a
/// clipped quadric and a mesh, its numbers drawn from [`number`].
fn scene_text() -> impl Strategy<Value = String> {
    let material = (
        vec3(unit()),
        unit(),
        unit(),
        0.0..1e4f64,
        unit(),
        unit(),
        0.5..3.0f64,
    );
    (
        vec3(number()),
        1.0..170.0f64,
        prop::collection::vec(material, 1..4),
        prop::collection::vec((vec3(number()), vec3(0.0..10.0f64)), 0..3),
        (vec3(number()), 1e-3..1e3f64),
        [vec3(number()), vec3(number()), vec3(number())],
        prop::array::uniform10(-5.0..5.0f64),
        (0.01..100.0f64, vec3(-180.0..180.0f64), vec3(number())),
        (0u32..=21, 1u32..64, 1u32..=8),
    )
        .prop_map(|(eye, fov, materials, lights, sphere, triangle, quadric, mesh, octree)| {
            let mut t = format!(
                "[camera]\neye = {}\nlookat = [0.5, 0.25, 0]\nup = [0, 1, 0]\nfov = {fov:?}\n\n\
                 [image]\nwidth = 64\nheight = 48\nsamples = 1\n\n\
                 [octree]\nmax_depth = {}\nleaf_size = {}\nmax_duplication = {}\n\n",
                text3(eye),
                octree.0,
                octree.1,
                octree.2
            );
            for (i, (color, kd, ks, shininess, reflectivity, transparency, ior)) in
                materials.iter().enumerate()
            {
                t += &format!(
                    "[materials.m{i}]\ncolor = {}\nkd = {kd:?}\nks = {ks:?}\nshininess = {shininess:?}\n\
                     reflectivity = {reflectivity:?}\ntransparency = {transparency:?}\nior = {ior:?}\n\n",
                    text3(*color)
                );
            }
            for (position, color) in &lights {
                t += &format!(
                    "[[lights]]\nposition = {}\ncolor = {}\n\n",
                    text3(*position),
                    text3(*color)
                );
            }
            let last = materials.len() - 1;
            t += &format!(
                "[[objects]]\nkind = \"sphere\"\nmaterial = \"m0\"\ncenter = {}\nradius = {:?}\n\n",
                text3(sphere.0),
                sphere.1
            );
            t += &format!(
                "[[objects]]\nkind = \"triangle\"\nmaterial = \"m{last}\"\nvertices = [{}, {}, {}]\n\n",
                text3(triangle[0]),
                text3(triangle[1]),
                text3(triangle[2])
            );
            t += "[[objects]]\nkind = \"plane\"\nmaterial = \"m0\"\npoint = [0, -1, 0]\nnormal = [0, 1, 0.25]\n\n";
            let q: Vec<String> = quadric.iter().map(|c| format!("{c:?}")).collect();
            t += &format!(
                "[[objects]]\nkind = \"quadric\"\nmaterial = \"m{last}\"\ncoefficients = [{}]\n\
                 clip = {{ min = [-1, -1, -1], max = [1, 1, 1] }}\n\n",
                q.join(", ")
            );
            t += &format!(
                "[[objects]]\nkind = \"mesh\"\npath = \"model.obj\"\nscale = {:?}\nrotate = {}\ntranslate = {}\n",
                mesh.0,
                text3(mesh.1),
                text3(mesh.2)
            );
            t
        })
}

const MODEL: &[u8] = b"mtllib model.mtl\nv -1 0 -1\nv 1 0 -1\nv 1 0.5 1\nv -1 0 1\nvn 0 1 0\n\
usemtl red\nf 1//1 2//1 3//1\nusemtl blue\nf 1 3 4\n";
const LIBRARY: &[u8] = b"newmtl red\nKd 0.8 0.1 0.1\nnewmtl blue\nKd 0.1 0.1 0.8\nNi 1.4\nd 0.5\n";

/// Edited lights (position, colour) and materials (colour, kd, shininess).
type Edits = (Vec<(DVec3, DVec3)>, Vec<(DVec3, f64, f64)>);

fn edits_strategy() -> impl Strategy<Value = Edits> {
    let v = |s: std::ops::RangeInclusive<f64>| {
        (s.clone(), s.clone(), s).prop_map(|(x, y, z)| DVec3::new(x, y, z))
    };
    (
        prop::collection::vec((v(-50.0..=50.0), v(0.0..=5.0)), 4),
        prop::collection::vec((v(0.0..=1.0), 0.0..=1.0f64, 1.0..=1e5f64), 4),
    )
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// An export's record (written to PNG bytes and read back) loads the
    /// scene it was made from, with the viewer's edits in place of the
    /// file's lights and materials.
    #[test]
    fn the_scene_in_an_export_record_loads_back(text in scene_text(), edits in edits_strategy(), edit in any::<bool>()) {
        let files = Files { scene: text.clone(), obj: MODEL.to_vec(), mtl: LIBRARY.to_vec() };
        let path = Path::new("dir/scene.toml");
        let scene = match glint::scene::load_with(path, &files) {
            Ok(s) => s,
            // Random numbers may make a degenerate triangle or an empty
            // quadric: only scenes that load are this test's subject.
            Err(e) => return Err(TestCaseError::reject(e.to_string())),
        };
        let mut expected = scene.clone();
        let mut record = RenderRecord::new(&scene, "dir/scene.toml", &scene.camera, scene.render_settings());
        if edit {
            let lights: Vec<Light> = scene.lights.iter().zip(&edits.0).map(|(_, (p, c))| Light { position: *p, color: *c }).collect();
            let materials: Vec<Material> = scene.materials.iter().zip(edits.1.iter().cycle()).map(|(m, (c, kd, n))| Material { color: *c, kd: *kd, shininess: *n, ..m.clone() }).collect();
            expected.lights = lights.clone();
            expected.materials = materials.clone();
            record.settings.edits = Some(SceneEdits { lights, materials });
        }
        let png = png_bytes(Path::new("out.png"), 1, 1, &[1, 2, 3], Some(&record)).unwrap();
        let read = read_record_bytes(&png, Path::new("out.png")).unwrap();
        prop_assert_eq!(&read, &record);
        let again = load_recorded_scene_with(&read, &files).unwrap();
        assert_same(&expected, &again)?;
    }

    /// An OBJ opened on its own is framed in a scene glint writes; that
    /// text loads the same scene again (what `--from-png` relies on).
    #[test]
    fn the_scene_written_around_an_obj_loads_back(
        vertices in prop::collection::vec(vec3(number()), 3..12),
        faces in prop::collection::vec((0usize..12, 0usize..12, 0usize..12, 0usize..3), 1..12),
    ) {
        let mut obj = String::from("mtllib model.mtl\n");
        for v in &vertices {
            obj += &format!("v {:?} {:?} {:?}\n", v[0], v[1], v[2]);
        }
        for (a, b, c, m) in &faces {
            let n = vertices.len();
            obj += &format!("usemtl {}\nf {} {} {}\n", ["red", "blue", ""][*m], a % n + 1, b % n + 1, c % n + 1);
        }
        let files = Files { scene: String::new(), obj: obj.into_bytes(), mtl: LIBRARY.to_vec() };
        let path = Path::new("models/model.obj");
        let scene = match glint::scene::load_with(path, &files) {
            Ok(s) => s,
            Err(e) => return Err(TestCaseError::reject(e.to_string())),
        };
        let again = glint::scene::load_str(&scene.source_text, path, &files)
            .map_err(|e| TestCaseError::fail(format!("{e}\n{}", scene.source_text)))?;
        assert_same(&scene, &again)?;
    }

    /// A scene saved with edits (camera, image settings, the octree switch,
    /// lights, the file's materials and a mesh's MTL materials) loads back
    /// with exactly those values, in its own folder or another.
    #[test]
    fn a_scene_saved_with_edits_loads_back_with_them(
        text in scene_text(),
        edits in edits_strategy(),
        eye in vec3(number()),
        fov in 0.5..179.0f64,
        size in (1u32..4096, 1u32..4096),
        aa in 0usize..3,
        max_depth in 1u32..=64,
        octree in any::<bool>(),
        tree in (0u32..=21, 1u32..=64, 1u32..=8, any::<bool>()),
        other_folder in any::<bool>(),
    ) {
        let files = Files { scene: text.clone(), obj: MODEL.to_vec(), mtl: LIBRARY.to_vec() };
        let path = Path::new("dir/scene.toml");
        let loaded = match glint::scene::load_with(path, &files) {
            Ok(s) => s,
            Err(e) => return Err(TestCaseError::reject(e.to_string())),
        };
        let mut camera = loaded.camera;
        camera.eye = DVec3::from(eye);
        camera.fov = fov;
        if camera.check().is_err() {
            return Err(TestCaseError::reject("camera"));
        }
        let mut settings = loaded.render_settings();
        (settings.width, settings.height) = size;
        (settings.samples, settings.adaptive) = [(1, false), (16, false), (16, true)][aa];
        settings.max_depth = max_depth;
        settings.accel = Accel::from_octree_switch(octree);
        let lights: Vec<Light> = loaded.lights.iter().zip(&edits.0).map(|(_, (p, c))| Light { position: *p, color: *c }).collect();
        let materials: Vec<Material> = loaded.materials.iter().zip(edits.1.iter().cycle()).map(|(m, (c, kd, n))| Material { color: *c, kd: *kd, shininess: *n, ..m.clone() }).collect();
        let octree_params = glint::accel::OctreeParams {
            max_depth: tree.0,
            leaf_size: tree.1,
            max_duplication: tree.2,
            cost_driven: tree.3,
            ..loaded.octree_params
        };
        let request = glint::scene::save::SaveRequest {
            loaded: &loaded,
            loaded_path: path,
            camera: &camera,
            camera_path: None,
            lights: &lights,
            materials: &materials,
            settings: &settings,
            octree: &octree_params,
            mesh_paths: glint::scene::save::MeshPaths::Anchored,
        };
        let destination = if other_folder { Path::new("elsewhere/saved.toml") } else { Path::new("dir/saved.toml") };
        let saved = glint::scene::save::scene_toml(&request, destination).unwrap();
        let again = glint::scene::load_str(&saved.text, destination, &files)
            .map_err(|e| TestCaseError::fail(format!("{e}\n{}", saved.text)))?;
        let mut expected = loaded.clone();
        expected.camera = camera;
        expected.lights = lights;
        (expected.image.width, expected.image.height) = size;
        (expected.image.samples, expected.image.adaptive) = (settings.samples, settings.adaptive);
        expected.image.max_depth = max_depth;
        expected.octree_enabled = octree;
        expected.octree_params = octree_params;
        // The file's own materials and the mesh's MTL ones alike.
        expected.materials.clone_from(&materials);
        prop_assert!(saved.left_out.is_empty(), "{:?}", saved.left_out);
        assert_same(&expected, &again)?;
        prop_assert_eq!(again.render_settings(), settings);
    }

    /// An NFF scene saved with edits (camera, image size, lights with and
    /// without a colour in the file, materials given by several `f`
    /// lines) loads back with those values; the field of view to within
    /// rounding of NFF's angle.
    #[test]
    fn an_nff_scene_saved_with_edits_loads_back_with_them(
        edits in edits_strategy(),
        eye in vec3(number()),
        fov in 0.5..179.0f64,
        size in (1u32..4096, 1u32..4096),
        ks in prop::collection::vec(0.0..=1.0f64, 2),
    ) {
        let text = "# SPD-like\nv\nfrom 2 1 1.5\nat 0 0 0\nup 0 0 1\nangle 45\nhither 0.01\n\
            resolution 512 512\nb 0.1 0.3 0.7\nl 4 3 2 # uncoloured\nl 1 -4 4 0.5 0.5 0.5\n\
            f 1 0.75 0.33 0.8 0 100 0 1\ns 0 0 0 0.5\nf 0.9 0.9 0.9 0.5 0.5 45 0.5 1.5\n\
            c 0 0 0 1 0 0 1 0.5\nf 1 0.75 0.33 0.8 0 100 0 1\np 3\n0 0 0\n1 0 0\n0 1 0\n";
        let path = Path::new("spd/scene.nff");
        let files = Files { scene: String::new(), obj: Vec::new(), mtl: Vec::new() };
        let loaded = glint::scene::load_str(text, path, &files).unwrap();
        let mut camera = loaded.camera;
        camera.eye = DVec3::from(eye);
        camera.fov = fov;
        if camera.check().is_err() {
            return Err(TestCaseError::reject("camera"));
        }
        let mut settings = loaded.render_settings();
        (settings.width, settings.height) = size;
        let lights: Vec<Light> = edits.0.iter().take(2).map(|(p, c)| Light { position: *p, color: *c }).collect();
        // What NFF can say: ka follows kd, reflectivity follows ks.
        let materials: Vec<Material> = loaded.materials.iter().zip(&edits.1).zip(&ks).map(|((m, (c, kd, n)), ks)| Material {
            color: *c, kd: *kd, ka: *kd, ks: *ks, reflectivity: *ks, shininess: *n, ..m.clone()
        }).collect();
        if materials[0] == materials[1] {
            return Err(TestCaseError::reject("materials made equal merge"));
        }
        let request = glint::scene::save::SaveRequest {
            loaded: &loaded,
            loaded_path: path,
            camera: &camera,
            camera_path: None,
            lights: &lights,
            materials: &materials,
            settings: &settings,
            octree: &loaded.octree_params,
            mesh_paths: glint::scene::save::MeshPaths::Anchored,
        };
        let saved = glint::scene::save::scene_nff(&request).unwrap();
        prop_assert!(saved.left_out.is_empty(), "{:?}", saved.left_out);
        prop_assert!(saved.text.contains("# uncoloured"));
        let again = glint::scene::load_str(&saved.text, path, &files)
            .map_err(|e| TestCaseError::fail(format!("{e}\n{}", saved.text)))?;
        prop_assert!((again.camera.fov - fov).abs() <= 1e-9 * fov, "{} {}", again.camera.fov, fov);
        let mut expected = loaded.clone();
        expected.camera = camera;
        expected.camera.fov = again.camera.fov;
        expected.lights = lights;
        expected.materials = materials;
        (expected.image.width, expected.image.height) = size;
        assert_same(&expected, &again)?;
    }
}
