//! The viewer's scene files, driven headless: undo, save (TOML, NFF, an
//! OBJ's materials, the built-in scene) and the paths exports record.
#![cfg(feature = "gui")]

use crate::common;

use common::viewer::*;
use egui_kittest::kittest::Queryable;
use glint::viewer::{GlintApp, SceneSource, ViewerOptions};

/// Edits can be undone and redone, are marked in the title until saved,
/// and Save writes them into the scene file, comments kept; a reload over
/// unsaved edits asks first.
#[test]
fn edits_undo_redo_save_and_a_reload_that_asks() {
    use egui::{Key, Modifiers};
    let (_dir, path) = scene_in_temp_folder();
    let app = app_at(&path);
    let mut h = harness(app);
    assert!(!h.state().unsaved());
    assert!(!h.state().title().starts_with('●'), "{}", h.state().title());
    // An orbit alone is an edit the title names.
    let camera = *h.state().camera();
    h.state_mut().camera_mut().eye.x += 1.0;
    h.run_steps(2);
    assert!(h.state().title().starts_with('●'), "{}", h.state().title());
    assert!(
        h.state().title().contains("(camera moved)"),
        "{}",
        h.state().title()
    );
    *h.state_mut().camera_mut() = camera;
    h.run_steps(2);
    assert!(!h.state().unsaved(), "{}", h.state().title());
    let original = h.state().scene().lights.clone();
    let edited = glint::math::DVec3::new(0.25, 0.5, 0.75);
    h.state_mut().scene_mut().lights[0].color = edited;
    h.state_mut().settings_mut().max_depth = 7;
    h.run_steps(2);
    assert!(h.state().unsaved());
    assert!(h.state().title().starts_with('●'), "{}", h.state().title());
    assert!(
        !h.state().title().contains("camera"),
        "{}",
        h.state().title()
    );

    press(&mut h, Modifiers::COMMAND, Key::Z);
    assert_eq!(
        h.state().scene().lights,
        original,
        "undo restores the light"
    );
    assert_eq!(
        h.state().settings().max_depth,
        3,
        "and the depth, changed in the same moment"
    );
    assert!(!h.state().unsaved());
    press(&mut h, Modifiers::COMMAND | Modifiers::SHIFT, Key::Z);
    assert_eq!(
        h.state().scene().lights[0].color,
        edited,
        "redo puts it back"
    );
    assert_eq!(h.state().settings().max_depth, 7);

    press(&mut h, Modifiers::COMMAND, Key::S);
    assert!(!h.state().unsaved(), "{:?}", h.state().messages().last());
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(
        text.starts_with("# One sphere on a plane"),
        "comments kept:\n{text}"
    );
    let saved = glint::scene::load(&path).unwrap();
    assert_eq!(saved.lights[0].color, edited);
    assert_eq!(saved.image.max_depth, 7);
    assert!(
        h.state()
            .messages()
            .last()
            .unwrap()
            .text
            .starts_with("saved ")
    );

    // Unsaved again: F5 asks, Cancel keeps the edit, Discard reloads the file.
    h.state_mut().scene_mut().lights[0].color = original[0].color;
    h.run_steps(2);
    press(&mut h, Modifiers::NONE, Key::F5);
    h.get_by_label("Unsaved edits");
    h.get_by_label("Cancel").click();
    h.run_steps(2);
    assert_eq!(h.state().scene().lights, original, "cancel keeps the edit");
    press(&mut h, Modifiers::NONE, Key::F5);
    h.get_by_label("Discard").click();
    h.run_steps(2);
    assert_eq!(
        h.state().scene().lights[0].color,
        edited,
        "the saved file was reloaded"
    );
    assert!(!h.state().unsaved());
}

/// An NFF scene is saved in place as NFF: its comments kept, the edits
/// in; what NFF cannot say (a reflectivity apart from Ks) is named and
/// stays marked unsaved.
#[test]
fn an_nff_scene_is_saved_as_nff_and_what_it_cannot_hold_stays_unsaved() {
    use egui::{Key, Modifiers};
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("balls.nff");
    let text = "# two balls\nv\nfrom 0 -4 1\nat 0 0 0\nup 0 0 1\nangle 40\nhither 0.01\n\
                resolution 64 48\nb 0.1 0.2 0.3\nl 4 -3 5\n\
                f 1 0.5 0.2 0.7 0.3 20 0 1\ns 0 0 0 1\ns 1 0 0 0.5\n";
    std::fs::write(&path, text).unwrap();
    let mut h = harness(app_at(&path));
    settle(&mut h);
    h.state_mut().camera_mut().fov = 35.0;
    h.state_mut().scene_mut().lights[0].color = glint::math::DVec3::new(0.9, 0.8, 0.7);
    h.state_mut().scene_mut().materials[0].color = glint::math::DVec3::new(0.2, 0.4, 0.6);
    h.run_steps(2);
    assert!(h.state().unsaved());
    press(&mut h, Modifiers::COMMAND, Key::S);
    assert!(!h.state().unsaved(), "{:?}", h.state().messages().last());
    let written = std::fs::read_to_string(&path).unwrap();
    assert!(written.starts_with("# two balls\n"), "{written}");
    assert!(written.contains("l 4 -3 5 0.9 0.8 0.7\n"), "{written}");
    let saved = glint::scene::load(&path).unwrap();
    assert!((saved.camera.fov - 35.0).abs() < 1e-12);
    assert_eq!(saved.materials, h.state().scene().materials);

    h.state_mut().scene_mut().materials[0].reflectivity = 0.05;
    h.run_steps(2);
    press(&mut h, Modifiers::COMMAND, Key::S);
    let message = &h.state().messages().last().unwrap().text;
    assert!(message.contains("the reflectivity of f1"), "{message}");
    assert!(h.state().unsaved(), "the reflectivity is not in the file");

    // Settings NFF has no place for stay marked too.
    h.state_mut().scene_mut().materials[0].reflectivity = h.state().scene().materials[0].ks;
    h.state_mut().settings_mut().samples = 16;
    h.run_steps(2);
    press(&mut h, Modifiers::COMMAND, Key::S);
    let message = &h.state().messages().last().unwrap().text;
    assert!(message.contains("samples"), "{message}");
    assert!(h.state().unsaved(), "the samples are not in the file");
}

/// An OBJ opened on its own, its MTL material edited: "Save as" writes
/// a TOML scene that holds the edit (in the mesh object's `materials`).
#[test]
fn edits_to_an_objs_mtl_materials_are_saved() {
    let dir = tempfile::tempdir().unwrap();
    let mut h = harness(app_for("assets/cornell_box/cornell_box.obj", 48, 48));
    settle(&mut h);
    let i = h
        .state()
        .scene()
        .materials
        .iter()
        .position(|m| m.name == "red")
        .expect("the Cornell box's red wall");
    h.state_mut().scene_mut().materials[i].color = glint::math::DVec3::new(0.1, 0.2, 0.9);
    h.run_steps(2);
    let path = dir.path().join("box.toml");
    h.state_mut().save_to(&path);
    assert!(!h.state().unsaved(), "{:?}", h.state().messages().last());
    let saved = glint::scene::load(&path).unwrap();
    assert_eq!(saved.materials, h.state().scene().materials);
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains("[objects.materials.red]"), "{text}");
}

/// The built-in scene has no file: Save writes a new TOML scene (with the
/// bunny beside it) that loads to the same scene.
#[test]
fn the_built_in_scene_is_saved_as_a_new_file_with_its_mesh() {
    let dir = tempfile::tempdir().unwrap();
    let app = GlintApp::new(SceneSource::BuiltIn, ViewerOptions::default(), || {}).unwrap();
    let mut h = harness(app);
    let mut camera = *h.state().camera();
    camera.fov = 33.0;
    *h.state_mut().camera_mut() = camera;
    h.run_steps(1);
    let path = dir.path().join("copy.toml");
    h.state_mut().save_to(&path);
    assert!(!h.state().unsaved(), "{:?}", h.state().messages().last());
    let copy = glint::scene::load(&path).unwrap();
    let builtin = glint::scene::builtin::default_scene().unwrap();
    assert_eq!(copy.camera, camera);
    assert_eq!(copy.shapes, builtin.shapes);
    assert_eq!(copy.materials, builtin.materials);
    assert!(dir.path().join("bunny.obj").is_file());
}

/// A scene opened by a relative name is recorded in exports by its
/// absolute path, so `--from-png` works from any folder.
#[test]
fn exports_record_the_scene_by_its_absolute_path() {
    let relative = std::path::PathBuf::from("scenes/sphere.toml");
    assert!(relative.is_file(), "tests run from the repository root");
    let app = app_at(&relative);
    let mut h = harness(app);
    h.state_mut().settings_mut().width = 32;
    h.state_mut().settings_mut().height = 24;
    h.run_steps(2);
    settle(&mut h);
    let tmp = common::temp_dir();
    let png = tmp.path().join("x.png");
    h.state().export_to(&png).unwrap();
    let record = glint::export::read_record(&png).unwrap();
    assert_eq!(
        std::path::PathBuf::from(&record.scene_path),
        std::fs::canonicalize(&relative).unwrap()
    );
}

/// Octree parameters edited in the panel are an edit like any other: the
/// title marks them, undo takes them back (and the tree with them), the
/// passes render again with the new tree, and Save writes `[octree]`.
#[test]
fn octree_parameters_are_edits() {
    use egui::{Key, Modifiers};
    let (_dir, path) = scene_in_temp_folder();
    let mut h = harness(app_at(&path));
    settle(&mut h);
    let loaded = h.state().scene().octree_params;
    let edited_depth = loaded.max_depth - 3;
    let renders = h.state().worker().history().len();
    h.get_by_label("Octree parameters").click();
    h.run_steps(3);
    h.get_by_value(&loaded.max_depth.to_string()).focus();
    h.run_steps(1);
    h.event(egui::Event::Text(edited_depth.to_string()));
    h.key_press(Key::Enter);
    h.run_steps(3);
    assert_eq!(h.state().scene().octree_params.max_depth, edited_depth);
    assert_eq!(
        h.state().octree().params().max_depth,
        edited_depth,
        "the tree was rebuilt"
    );
    assert!(h.state().unsaved());
    assert!(h.state().title().starts_with('●'), "{}", h.state().title());
    settle(&mut h);
    assert!(
        h.state().worker().history().len() > renders,
        "the new tree rendered, for its times"
    );

    // Undo a second later (edits within a second are one step): the
    // harness's clock advances a quarter second a step.
    h.run_steps(5);
    press(&mut h, Modifiers::COMMAND, Key::Z);
    assert_eq!(h.state().scene().octree_params, loaded);
    assert_eq!(h.state().octree().params(), loaded, "undo rebuilt the tree");
    assert!(!h.state().unsaved());
    press(&mut h, Modifiers::COMMAND | Modifiers::SHIFT, Key::Z);
    assert_eq!(h.state().octree().params().max_depth, edited_depth);

    press(&mut h, Modifiers::COMMAND, Key::S);
    assert!(!h.state().unsaved(), "{:?}", h.state().messages().last());
    let saved = glint::scene::load(&path).unwrap();
    assert_eq!(saved.octree_params.max_depth, edited_depth);
    assert_eq!(saved.octree_params.leaf_size, loaded.leaf_size);
}

/// Command-line settings (`--size`, octree flags) are ways of looking at
/// the scene, not edits: a save after editing a light writes the light
/// and leaves `resolution`, `angle` and `[octree]` as the files have them.
#[test]
fn command_line_settings_are_not_saved_as_edits() {
    use egui::{Key, Modifiers};
    use glint::settings::{OctreeOverrides, Overrides};
    let dir = tempfile::tempdir().unwrap();
    let overrides = Overrides {
        width: Some(90),
        height: Some(70),
        octree: OctreeOverrides {
            leaf_size: Some(2),
            ..Default::default()
        },
        ..Default::default()
    };
    let nff = dir.path().join("balls.nff");
    let nff_text = "v\nfrom 0 -4 1\nat 0 0 0\nup 0 0 1\nangle 45\nhither 0.01\n\
                    resolution 64 48\nb 0.1 0.2 0.3\nl 2 -18 -5\n\
                    f 1 0.5 0.2 0.7 0.3 20 0 1\ns 0 0 0 1\n";
    std::fs::write(&nff, nff_text).unwrap();
    let (_toml_dir, toml) = scene_in_temp_folder();
    let toml_text = std::fs::read_to_string(&toml).unwrap();
    for (path, text, edited) in [
        (
            &nff,
            nff_text.to_owned(),
            nff_text.replace("l 2 -18 -5", "l 3 -18 -5"),
        ),
        (&toml, toml_text.clone(), String::new()),
    ] {
        let options = ViewerOptions {
            overrides,
            ..Default::default()
        };
        let app = GlintApp::new(SceneSource::File(path.clone()), options, || {}).unwrap();
        let mut h = harness(app);
        assert!(!h.state().unsaved(), "the flags are not edits");
        assert_eq!(h.state().octree().params().leaf_size, 2);
        h.state_mut().scene_mut().lights[0].position.x = 3.0;
        h.run_steps(2);
        press(&mut h, Modifiers::COMMAND, Key::S);
        assert!(!h.state().unsaved(), "{:?}", h.state().messages().last());
        let written = std::fs::read_to_string(path).unwrap();
        if edited.is_empty() {
            assert!(!written.contains("width = 90"), "{written}");
            assert!(!written.contains("leaf_size"), "{written}");
            let saved = glint::scene::load(path).unwrap();
            assert_eq!(saved.lights[0].position.x, 3.0);
            assert_eq!(
                saved.image,
                glint::scene::load_str(&text, path, &glint::scene::FileSystem)
                    .unwrap()
                    .image
            );
        } else {
            assert_eq!(written, edited);
        }
    }
}

/// Without a file dialog (no desktop portal, as under Xvfb and in CI),
/// Ctrl+O offers a path field: a missing file is refused in it, an
/// existing one opens.
#[test]
fn ctrl_o_without_a_dialog_offers_a_path_field() {
    use egui::{Key, Modifiers};
    if glint::viewer::file_dialog_available() {
        eprintln!("a desktop portal is available here: the field is not shown");
        return;
    }
    let (_dir, path) = scene_in_temp_folder();
    let mut h = harness(app_at(&path));
    press(&mut h, Modifiers::COMMAND, Key::O);
    h.get_by_label_contains("No file dialog is available here");
    h.run_steps(2);
    h.event(egui::Event::Text("no/such/scene.toml".into()));
    h.key_press(Key::Enter);
    h.run_steps(3);
    h.get_by_label_contains("no/such/scene.toml: no such file");
    let glass = common::repo_path("scenes/glass.toml");
    // The refused path's field has the focus again: select all, retype.
    h.event(egui::Event::Key {
        key: Key::A,
        physical_key: None,
        pressed: true,
        repeat: false,
        modifiers: Modifiers::COMMAND,
    });
    h.event(egui::Event::Text(glass.display().to_string()));
    h.key_press(Key::Enter);
    h.run_steps(3);
    assert!(
        h.query_by_label_contains("No file dialog is available here")
            .is_none(),
        "the field closed"
    );
    assert!(
        h.state().scene().name.ends_with("glass.toml"),
        "{}",
        h.state().scene().name
    );
}

/// Without a file dialog, Save as and Export show a path field filled in
/// with the name glint would choose: Enter takes it, or another folder can
/// be typed (a built-in scene's copy need not go where a file is in the
/// way).
#[test]
fn save_as_and_export_without_a_dialog_offer_a_filled_in_path_field() {
    use egui::{Key, Modifiers};
    if glint::viewer::file_dialog_available() {
        eprintln!("a desktop portal is available here: the field is not shown");
        return;
    }
    let select_all = egui::Event::Key {
        key: Key::A,
        physical_key: None,
        pressed: true,
        repeat: false,
        modifiers: Modifiers::COMMAND,
    };
    let (dir, path) = scene_in_temp_folder();
    let mut h = harness(app_at(&path));
    h.state_mut().scene_mut().lights[0].position.x += 1.0;
    h.run_steps(2);
    press(&mut h, Modifiers::COMMAND | Modifiers::SHIFT, Key::S);
    h.get_by_label_contains("Save the scene as");
    // Another folder, typed over the name offered; one that does not
    // exist is refused first.
    let other = dir.path().join("elsewhere");
    h.run_steps(2);
    h.event(select_all.clone());
    h.event(egui::Event::Text(
        other.join("copy.toml").display().to_string(),
    ));
    h.key_press(Key::Enter);
    h.run_steps(3);
    h.get_by_label_contains("no such folder");
    std::fs::create_dir(&other).unwrap();
    h.event(select_all.clone());
    h.event(egui::Event::Text(
        other.join("copy.toml").display().to_string(),
    ));
    h.key_press(Key::Enter);
    h.run_steps(3);
    assert!(
        h.query_by_label_contains("Save the scene as").is_none(),
        "the field closed"
    );
    let copy = glint::scene::load(&other.join("copy.toml")).unwrap();
    assert_eq!(
        copy.lights[0].position,
        h.state().scene().lights[0].position
    );
    assert!(!h.state().unsaved(), "{:?}", h.state().messages().last());

    // Export: the same field, a name typed over the one offered.
    settle(&mut h);
    press(&mut h, Modifiers::COMMAND, Key::E);
    h.get_by_label_contains("Export the image");
    h.run_steps(2);
    h.event(select_all);
    let png = other.join("picture.png");
    h.event(egui::Event::Text(png.display().to_string()));
    h.key_press(Key::Enter);
    h.run_steps(3);
    assert!(std::fs::read(&png).unwrap().starts_with(b"\x89PNG"));
    let said = &h.state().messages().last().unwrap().text;
    assert!(
        said.starts_with("exported ") && said.contains("picture.png"),
        "{said}"
    );
}
