//! The camera path in the viewer: recording while orbiting, saving it into
//! the scene file, undo, and playing it back.
#![cfg(feature = "gui")]

use crate::common::viewer::{WAIT, app_at, harness, press, scene_in_temp_folder, settle};

use egui::{Key, Modifiers};
use egui_kittest::kittest::Queryable;
use std::time::Duration;

#[test]
fn a_path_recorded_while_orbiting_saves_undoes_and_plays_back() {
    let (_dir, path) = scene_in_temp_folder();
    let mut h = harness(app_at(&path));
    settle(&mut h);
    let camera = *h.state().camera();
    assert!(h.state().camera_path().is_none());

    press(&mut h, Modifiers::COMMAND, Key::R);
    assert!(h.state().is_recording_path());
    let start = h.state().image_rect().unwrap().center();
    h.hover_at(start);
    h.run_steps(1);
    h.drag_at(start);
    for k in 1..=12 {
        h.hover_at(start + egui::vec2(6.0 * k as f32, 0.0));
        h.run_steps(1);
        // Keys come at most every quarter second of the UI's clock.
        std::thread::sleep(Duration::from_millis(60));
    }
    h.drop_at(start + egui::vec2(72.0, 0.0));
    h.run_steps(1);
    press(&mut h, Modifiers::COMMAND, Key::R);
    assert!(!h.state().is_recording_path());
    let recorded = h.state().camera_path().expect("a recorded path").clone();
    assert!(recorded.keys().len() >= 2, "{} keys", recorded.keys().len());
    assert_eq!(
        recorded.keys()[0].camera,
        camera,
        "the path starts where the camera was"
    );
    assert_eq!(recorded.keys().last().unwrap().camera, *h.state().camera());
    assert!(h.state().unsaved());
    let title = h.state().title();
    assert!(
        title.starts_with('●') && !title.contains("camera moved"),
        "{title}"
    );

    // K adds the camera as it is one second after the last key.
    press(&mut h, Modifiers::NONE, Key::K);
    let with_key = h.state().camera_path().unwrap().clone();
    assert_eq!(with_key.keys().len(), recorded.keys().len() + 1);
    assert_eq!(with_key.duration(), recorded.duration() + 1.0);

    // Saved into the scene file, it loads back the same.
    press(&mut h, Modifiers::COMMAND, Key::S);
    assert!(!h.state().unsaved(), "{:?}", h.state().messages());
    let text = std::fs::read_to_string(&path).unwrap();
    assert!(text.contains("[[camera.keyframes]]"), "{text}");
    let loaded = glint::scene::load(&path).unwrap();
    assert_eq!(loaded.camera_path.as_ref(), Some(&with_key));

    // Play: the camera follows the path, then goes back.
    let before_play = *h.state().camera();
    press(&mut h, Modifiers::NONE, Key::P);
    assert!(h.state().is_playing_path());
    // Recording is not started while playing (the camera is the path's).
    press(&mut h, Modifiers::COMMAND, Key::R);
    assert!(h.state().is_playing_path() && !h.state().is_recording_path());
    let mut followed = false;
    let waited = std::time::Instant::now();
    while h.state().is_playing_path() {
        assert!(waited.elapsed() < WAIT, "playback never ended");
        h.run_steps(1);
        followed |= *h.state().camera() != before_play;
        std::thread::sleep(Duration::from_millis(20));
    }
    assert!(followed, "the camera moved along the path");
    assert_eq!(*h.state().camera(), before_play);
    assert!(!h.state().unsaved(), "playing is not an edit");

    // Deleting the path is an edit that undo takes back.
    std::thread::sleep(Duration::from_millis(1100));
    h.run_steps(1);
    h.get_by_label("Delete path").click();
    h.run_steps(2);
    assert!(h.state().camera_path().is_none());
    assert!(h.state().unsaved());
    std::thread::sleep(Duration::from_millis(1100));
    h.run_steps(1);
    press(&mut h, Modifiers::COMMAND, Key::Z);
    assert_eq!(h.state().camera_path(), Some(&with_key));
}
