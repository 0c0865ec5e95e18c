//! The viewer's panels, driven headless: fields, the octree panel, the
//! pixel's ray tree and its walk, and what fits the fixed-width panels.
#![cfg(feature = "gui")]

use crate::common;

use std::time::Duration;

use common::viewer::*;
use egui_kittest::kittest::Queryable;
use glint::viewer::GlintApp;

#[test]
fn a_deep_ray_tree_leaves_the_panels_and_the_image_apart() {
    // The glass pixel's tree nests four levels of headers, which do not
    // wrap; once they widened the timing panel and the image slid under it.
    let mut h = harness(app_for("scenes/glass.toml", 480, 360));
    let before = h.state().image_rect().unwrap();
    h.state_mut().inspect_pixel(250, 200);
    h.run_steps(4);
    assert_eq!(h.state().inspection().unwrap().tree.depth, 1);
    let after = h.state().image_rect().unwrap();
    assert_eq!(after, before, "the image keeps its place");
    // The fixed-width panels: 330 points each side of a 1200-point window.
    assert!(after.max.x <= 1200.0 - 330.0, "{after:?}");
    assert!(after.min.x >= 330.0, "{after:?}");
}

/// A number typed into a field is taken on Enter, not key by key: typing
/// 200 into the width does not first render widths 2 and 20.
#[test]
fn a_typed_number_is_taken_on_enter() {
    let mut h = harness(app_for("scenes/sphere.toml", 77, 48));
    let generation = h.state().worker().generation();
    h.get_by_value("77").focus();
    h.run_steps(1);
    // Focused, the field is a text edit with the whole number selected.
    for key in ["2", "0", "0"] {
        h.get_by(|n| n.is_focused()).type_text(key);
        h.run_steps(1);
    }
    h.run_steps(2);
    assert_eq!(h.state().settings().width, 77, "taken while typing");
    assert_eq!(
        h.state().worker().generation(),
        generation,
        "restarted while typing"
    );
    h.key_press(egui::Key::Enter);
    h.run_steps(2);
    assert_eq!(h.state().settings().width, 200);
    assert!(h.state().worker().generation() > generation);
}

/// New octree parameters rebuild the tree and its prediction, and the
/// passes render again with it, so the times shown are the new tree's.
#[test]
fn octree_parameters_rebuild_the_tree_and_its_prediction_and_render_again() {
    let mut h = harness(app_for("scenes/spd/teapot.nff", 96, 96));
    settle(&mut h);
    h.run_steps(2);
    assert!(
        h.state().unit_costs().is_some(),
        "measured once the scene rendered"
    );
    let generation = h.state().worker().generation();
    let coarse = h.state().octree().stats();
    let coarse_cost = h.state().octree().predicted_cost();
    let mut params = h.state().scene().octree_params;
    params.leaf_size = 1;
    params.max_depth = 8;
    h.state_mut().set_octree_params(params);
    h.run_steps(3);
    assert_eq!(h.state().scene().octree_params, params);
    assert_ne!(h.state().octree().stats().nodes, coarse.nodes, "rebuilt");
    assert_ne!(h.state().octree().predicted_cost(), coarse_cost);
    assert!(
        h.state().worker().generation() > generation,
        "the new tree renders"
    );
    settle(&mut h);
    // The panel shows the prediction for the last pass's rays.
    h.get_by_label("Octree parameters").click();
    h.run_steps(2);
    let shown = h
        .get_all_by(|n| {
            n.label()
                .or(n.value())
                .is_some_and(|t| t.starts_with("Predicted 1-sample pass"))
        })
        .count();
    assert!(shown > 0, "the predicted render time is shown");
    // And, once its thread has traced a thumbnail of the view through the
    // new tree, the prediction from a sample of the view's rays.
    let start = std::time::Instant::now();
    while ray_sample_lines(&h) == 0 {
        assert!(start.elapsed() < WAIT, "no prediction from the view's rays");
        std::thread::sleep(Duration::from_millis(20));
        h.run_steps(1);
    }
}

#[test]
fn a_rays_walk_steps_through_the_octree_in_the_panel() {
    let mut h = harness(app_for("scenes/spd/teapot.nff", 96, 96));
    settle(&mut h);
    h.state_mut().inspect_pixel(48, 46);
    h.run_steps(3);
    let tree = &h.state().inspection().unwrap().tree;
    let steps = tree.query.as_ref().unwrap().walk.as_ref().unwrap().len();
    assert!(steps > 2, "{steps} steps");
    // The eye ray's "walk" button is the first.
    h.get_all_by_label("walk").next().unwrap().click();
    h.run_steps(2);
    assert_eq!(h.state().walk().0.map(|t| t.path.len()), Some(0));
    assert_eq!(h.state().walk().1, 0);
    h.get_by_label(">").click();
    h.run_steps(1);
    h.get_by_label(">").click();
    h.run_steps(1);
    assert_eq!(h.state().walk().1, 2, "two steps taken");
    h.get_by_label("|<").click();
    h.run_steps(1);
    assert_eq!(h.state().walk().1, 0);
}

/// A side past the viewer's limit typed into the size field is refused
/// where it was typed, with the reason; the size stays as it was.
#[test]
fn an_image_side_past_the_viewers_limit_is_refused_in_place() {
    let mut h = harness(small_app());
    // A width no other field shows, to find the field by its value.
    h.state_mut().settings_mut().width = 77;
    h.run_steps(2);
    let generation = h.state().worker().generation();
    h.get_by_value("77").focus();
    h.run_steps(1);
    // The focused field is a text edit with its text selected: typing
    // replaces it.
    h.event(egui::Event::Text("77000".into()));
    h.key_press(egui::Key::Enter);
    h.run_steps(3);
    assert_eq!(
        (h.state().settings().width, h.state().settings().height),
        (77, 48),
        "the size was not applied"
    );
    h.get_by_label_contains("77000x48 refused: the viewer renders sides up to 8192");
    assert_eq!(
        h.state().worker().generation(),
        generation,
        "nothing rendered"
    );
    // A size within the limit is taken, and the message goes.
    h.get_by_value("77").focus();
    h.run_steps(1);
    h.event(egui::Event::Text("770".into()));
    h.key_press(egui::Key::Enter);
    h.run_steps(3);
    assert_eq!(h.state().settings().width, 770);
    assert!(h.query_by_label_contains("refused").is_none());
}

/// `--walk` to a ray the inspected pixel does not have is refused, with
/// the rays it has; one it has is taken; `--walk-step` past its walk is
/// refused too.
#[test]
fn a_walk_to_a_ray_the_pixel_lacks_is_refused_with_its_rays() {
    let open_at = |walk: &str, step: Option<usize>| {
        let path: Vec<&str> = walk.split('/').skip(1).collect();
        let mut target = glint::viewer::WalkTarget::default();
        let mut parts = path.iter();
        while let Some(p) = parts.next() {
            if *p == "shadow" {
                target.shadow = parts.next().and_then(|l| l.parse().ok());
            } else {
                target.path.push(p.parse().unwrap());
            }
        }
        GlintApp::new(
            glint::viewer::SceneSource::File(common::repo_path("scenes/sphere.toml")),
            glint::viewer::ViewerOptions {
                inspect: Some((320, 240)),
                walk: Some((target, step)),
                ..Default::default()
            },
            || {},
        )
    };
    let open = |walk: &str| open_at(walk, None);
    // The centre pixel sees the sphere: an eye ray and its shadow ray.
    assert!(open("eye").is_ok());
    assert!(open("eye/shadow/0").is_ok());
    let error = open("eye/7/shadow/3").err().expect("refused").to_string();
    assert!(
        error.starts_with(
            "--walk eye/7/shadow/3: pixel 320,240 has no such ray; its rays: eye, eye/shadow/0"
        ),
        "{error}"
    );
    // A step past the walk's end is refused with the walk's length.
    assert!(open_at("eye", Some(1)).is_ok());
    let error = open_at("eye", Some(999))
        .err()
        .expect("refused")
        .to_string();
    assert!(
        error.starts_with("--walk-step 999: the walk of eye has "),
        "{error}"
    );
}

/// The suggestion's Apply button is whole inside the left panel (it was
/// clipped to a sliver beside its label).
#[test]
fn the_suggestions_apply_button_is_whole() {
    let mut h = harness(app_for("scenes/bunny.toml", 64, 48));
    settle(&mut h);
    h.get_by_label("Octree parameters").click();
    h.run_steps(3);
    // The panel's lines settle once the view's ray sample is in.
    let start = std::time::Instant::now();
    while ray_sample_lines(&h) == 0 {
        assert!(start.elapsed() < WAIT, "no prediction from the view's rays");
        std::thread::sleep(Duration::from_millis(20));
        h.run_steps(1);
    }
    h.get_by_label("Suggest a setting").click();
    let start = std::time::Instant::now();
    while h.query_by_label("Apply").is_none() {
        assert!(start.elapsed() < WAIT, "no suggestion came");
        std::thread::sleep(Duration::from_millis(20));
        h.run_steps(1);
    }
    let apply = h.get_by_label("Apply").rect();
    assert!(apply.width() >= 30.0, "the button is {apply:?}");
    // The left panel is 330 points wide.
    assert!(apply.max.x <= 330.0, "the button reaches {apply:?}");
}

/// Every line of a deep ray tree fits the right panel (x 870 to 1200 in
/// a 1200-point window): long lines wrap instead of running off its edge.
#[test]
fn the_ray_tree_fits_the_right_panel() {
    let mut h = harness(app_for("scenes/glass.toml", 64, 48));
    settle(&mut h);
    h.state_mut().inspect_pixel(32, 24);
    h.run_steps(3);
    let tree = h.state().inspection().unwrap().tree.clone();
    assert!(!tree.children.is_empty(), "the pixel sees glass");
    let lines: Vec<(String, egui::Rect)> = h
        .get_all_by(|n| {
            n.label().or(n.value()).is_some_and(|t| {
                t.contains("ray, depth") || t.starts_with("light ") || t.starts_with("colour (")
            })
        })
        .map(|n| (format!("{n:?}").chars().take(120).collect(), n.rect()))
        .collect();
    assert!(lines.len() > 4, "{lines:?}");
    assert!(
        h.query_all_by(|n| n.bounding_box().is_some_and(|r| r.x1 > 1200.0))
            .next()
            .is_none(),
        "nothing in the window runs past its right edge"
    );
    for (text, rect) in lines {
        assert!(
            rect.min.x >= 865.0 && rect.max.x <= 1200.0,
            "{text:?} at {rect:?}"
        );
    }
}

/// Lines of the octree panel that show the view's ray sample, measured.
fn ray_sample_lines(h: &egui_kittest::Harness<'static, GlintApp>) -> usize {
    h.query_all_by(|n| {
        n.label().or(n.value()).is_some_and(|t| {
            t.starts_with("From a sample of the view's rays: ") && t.contains("tests")
        })
    })
    .count()
}

/// A textured scene's render settings have a Textures box: unticked, the
/// scene renders again with each material in its own colour. The
/// materials panel names each material's image and its size.
#[test]
fn the_textures_box_switches_textures_and_materials_name_their_images() {
    let mut h = harness(app_for("scenes/garden.toml", 64, 48));
    settle(&mut h);
    assert!(h.state().settings().textures);
    let generation = h.state().worker().generation();
    h.get_by_label("Textures (3 images)").click();
    h.run_steps(3);
    assert!(!h.state().settings().textures);
    assert!(
        h.state().worker().generation() > generation,
        "renders again without textures"
    );
    // The open sections closed, so the materials fit the panel.
    for section in [
        "Render settings",
        "Inspect and compare",
        "Camera",
        "Camera path",
        "Lights",
    ] {
        h.get_by_label(section).click();
        h.run_steps(1);
    }
    h.get_by_label("Materials").click();
    h.run_steps(2);
    h.get_by_label("fence").click();
    h.run_steps(2);
    h.get_by_label_contains("texture (and cut-out): fence.png (256x128)");
}
