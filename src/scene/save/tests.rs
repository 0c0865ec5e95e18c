//! Tests of `save`.

use super::mesh_paths::write_mesh_paths;
use super::*;
use crate::material::Light;
use crate::math::DVec3;
use crate::scene::{FileSource, load_str};
use crate::settings::Accel;
use toml_edit::DocumentMut;

struct NoMeshes;
impl FileSource for NoMeshes {
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
        camera_path: loaded.camera_path.as_ref(),
        lights: &loaded.lights,
        materials: &loaded.materials,
        settings,
        octree: &loaded.octree_params,
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
    settings.accel = Accel::BruteForce;
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
impl FileSource for Files {
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
        let camera = "[camera]\neye = [0, 0, 5]\nlookat = [0, 0, 0]\nup = [0, 1, 0]\nfov = 40\n";
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
        camera_path: loaded.camera_path.as_ref(),
        lights,
        materials,
        settings,
        octree: &loaded.octree_params,
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
    let tree = crate::accel::OctreeParams {
        leaf_size: 9,
        ..loaded.octree_params
    };
    let saved = scene_nff(&SaveRequest {
        octree: &tree,
        ..nff_request(&loaded, &camera, &settings, &lights, &materials)
    })
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
        [
            LeftOut::Samples,
            LeftOut::OctreeParams,
            LeftOut::Reflectivity {
                material: "f2".into()
            }
        ]
    );
    assert_eq!(
        saved.left_out[2].to_string(),
        "the reflectivity of f2 (NFF uses Ks)"
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
    let again =
        load_str(&saved.text, path, &NoMeshes).unwrap_or_else(|e| panic!("{e}\n{}", saved.text));
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
        [LeftOut::EqualMaterial {
            material: "f2".into(),
            equal_to: "f1".into()
        }]
    );
    assert_eq!(
        saved.left_out[0].to_string(),
        "f2 apart from f1 (equal materials are one in NFF)"
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

/// Only edited numbers are rewritten, each in its token's style: moving a
/// light along x leaves its other coordinates as written and keeps whole
/// numbers whole; a width change (same rows) keeps `angle 45`, which
/// still gives the field of view.
#[test]
fn nff_saves_rewrite_only_edited_numbers_in_the_files_style() {
    let text = "v\nfrom 0 -4 1\nat 0 0 0\nup 0 0 1\nangle 45\nhither 0.01\n\
                resolution 64 48\nb 0.1 0.2 0.3\nl 2 -18 -5\nl 1.50 2 3 1 1 1\n\
                f 1 0.5 0.2 0.7 0.3 20 0 0\ns 0 0 0 1\n";
    let path = Path::new("dir/balls.nff");
    let loaded = load_str(text, path, &NoMeshes).unwrap();
    let mut lights = loaded.lights.clone();
    lights[0].position.x = 3.0;
    lights[1].position.y = 2.25;
    let mut materials = loaded.materials.clone();
    materials[0].kd = 0.25;
    let mut settings = loaded.render_settings();
    settings.width = 80;
    let saved = scene_nff(&nff_request(
        &loaded,
        &loaded.camera,
        &settings,
        &lights,
        &materials,
    ))
    .unwrap();
    let expected = text
        .replace("l 2 -18 -5", "l 3 -18 -5")
        .replace("l 1.50 2 3", "l 1.50 2.25 3")
        .replace("0.2 0.7 0.3", "0.2 0.25 0.3")
        .replace("resolution 64 48", "resolution 80 48");
    assert_eq!(saved.text, expected);
    // A changed field of view is written as an angle that reads back as it.
    let mut camera = loaded.camera;
    camera.fov = 30.0;
    let saved = scene_nff(&nff_request(
        &loaded,
        &camera,
        &loaded.render_settings(),
        &loaded.lights,
        &loaded.materials,
    ))
    .unwrap();
    assert!(!saved.text.contains("angle 45"), "{}", saved.text);
    let again = load_str(&saved.text, path, &NoMeshes).unwrap();
    assert!((again.camera.fov - 30.0).abs() < 1e-12);
}

#[test]
fn a_camera_path_is_written_as_keyframes_and_reads_back_the_same() {
    use crate::camera_path::{CameraPath, Keyframe};
    let path = Path::new("dir/scene.toml");
    let loaded = scene(TEXT);
    let settings = loaded.render_settings();
    let key = |time: f64, x: f64| Keyframe {
        time,
        camera: CameraSpec {
            eye: DVec3::new(x, 1.0 / 3.0, 5.0),
            ..loaded.camera
        },
    };
    let edited = CameraPath::new(vec![key(0.0, 0.1), key(1.25, 2.0 / 7.0)]).unwrap();
    let req = SaveRequest {
        camera_path: Some(&edited),
        ..request(&loaded, &loaded.camera, &settings)
    };
    let saved = scene_toml(&req, path).unwrap();
    let again = load_str(&saved.text, path, &NoMeshes).unwrap();
    assert_eq!(again.camera_path.as_ref(), Some(&edited), "{}", saved.text);
    // Removing it removes the keyframes.
    let req = SaveRequest {
        loaded: &again,
        camera_path: None,
        ..request(&again, &again.camera, &settings)
    };
    let text = scene_toml(&req, path).unwrap().text;
    assert!(!text.contains("keyframes"), "{text}");
    // NFF has no place for one: it is said, not lost silently.
    let nff = load_str(NFF, Path::new("dir/balls.nff"), &NoMeshes).unwrap();
    let lights = nff.lights.clone();
    let materials = nff.materials.clone();
    let nff_settings = nff.render_settings();
    let saved = scene_nff(&SaveRequest {
        camera_path: Some(&edited),
        ..nff_request(&nff, &nff.camera, &nff_settings, &lights, &materials)
    })
    .unwrap();
    assert!(saved.left_out.contains(&LeftOut::CameraPath));
}

#[test]
fn an_edited_component_leaves_the_others_as_the_file_wrote_them() {
    let loaded = scene(TEXT);
    let settings = loaded.render_settings();
    let mut lights = loaded.lights.clone();
    lights[0].position.x = 2.5;
    let mut materials = loaded.materials.clone();
    materials[0].color.y = 0.25;
    let mut camera = loaded.camera;
    camera.eye.y = 1.5;
    let req = SaveRequest {
        lights: &lights,
        materials: &materials,
        ..request(&loaded, &camera, &settings)
    };
    let text = scene_toml(&req, Path::new("dir/scene.toml")).unwrap().text;
    for written in [
        "position = [2.5, 5, 1]\n",
        "color = [0.8, 0.25, 0.1] # brick\n",
        "eye = [0, 1.5, 5] # over the floor\n",
    ] {
        assert!(text.contains(written), "no {written:?} in\n{text}");
    }
    let again = scene(&text);
    assert_eq!(
        (again.lights, again.materials, again.camera),
        (lights, materials, camera)
    );
}
