//! The inspected pixel: the tree of rays its centre ray spawns, traced in
//! the library, drawn over the image and listed in the timing panel.

use egui::{Color32, Pos2, Rect, Stroke};

use super::state::EditState;
use crate::camera::Camera;
use crate::math::DVec3;
use crate::render::ray_tree::{RayKind, RayNode, ShadowVerdict};
use crate::render::{RenderError, Renderer};
use crate::settings::{RenderSettings, ViewMode};

/// Which ray's walk is shown: the children's indices from the eye ray
/// down, and a light's index for that ray's shadow ray.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct WalkTarget {
    pub path: Vec<usize>,
    pub shadow: Option<usize>,
}

impl WalkTarget {
    /// The target as `--walk` writes it: `eye/0/shadow/1`.
    pub fn name(&self) -> String {
        let mut name = String::from("eye");
        for k in &self.path {
            name += &format!("/{k}");
        }
        if let Some(light) = self.shadow {
            name += &format!("/shadow/{light}");
        }
        name
    }
}

/// The inspected pixel and the tree of rays its centre ray spawned.
#[derive(Clone, Debug)]
pub struct Inspection {
    pub pixel: (u32, u32),
    pub tree: RayNode,
    pub lights: Vec<DVec3>,
}

impl Inspection {
    /// Picks pixel `(i, j)` of the image `edit` describes and traces its
    /// centre ray's tree on this thread: one pixel is microseconds of work.
    /// A pixel outside the image picks nothing.
    pub fn trace(
        edit: &EditState,
        reuse: crate::render::Reuse,
        (i, j): (u32, u32),
    ) -> Result<Option<Self>, RenderError> {
        let settings = RenderSettings {
            samples: 1,
            view: ViewMode::Shaded,
            ..edit.settings
        };
        if i >= settings.width || j >= settings.height {
            return Ok(None);
        }
        let accel = crate::render::Accelerator::build(&edit.scene, &settings, reuse)?;
        let renderer = Renderer::with_camera(&edit.scene, &accel, settings, &edit.camera)?;
        Ok(Some(Inspection {
            pixel: (i, j),
            tree: renderer.ray_tree(i, j),
            lights: edit.scene.lights.iter().map(|l| l.position).collect(),
        }))
    }

    /// The pixel's rays drawn over the image (projected through `camera`,
    /// rays that leave the scene cut at `extent`), and a ring on the pixel.
    pub fn draw(&self, painter: &egui::Painter, camera: &Camera, image_rect: Rect, extent: f64) {
        draw_tree(
            painter,
            camera,
            image_rect,
            &self.tree,
            &self.lights,
            extent,
        );
        let (i, j) = self.pixel;
        let (w, h) = (camera.width(), camera.height());
        let p = to_screen(image_rect, w, h, (i as f64 + 0.5, j as f64 + 0.5));
        painter.circle_stroke(p, 6.0, Stroke::new(2.0, Color32::from_rgb(255, 80, 200)));
    }
}

/// Screen position of image coordinates `(x, y)` (pixels from the top left).
pub fn to_screen(image_rect: Rect, width: u32, height: u32, (x, y): (f64, f64)) -> Pos2 {
    Pos2::new(
        image_rect.min.x + (x / width as f64) as f32 * image_rect.width(),
        image_rect.min.y + (y / height as f64) as f32 * image_rect.height(),
    )
}

fn kind_color(kind: RayKind) -> Color32 {
    match kind {
        RayKind::Eye => Color32::WHITE,
        RayKind::Reflection => Color32::from_rgb(80, 220, 255),
        RayKind::Refraction => Color32::from_rgb(255, 170, 60),
    }
}

/// Projects and draws a world-space segment, cut at the near plane.
fn segment(
    painter: &egui::Painter,
    camera: &Camera,
    image_rect: Rect,
    a: DVec3,
    b: DVec3,
    stroke: Stroke,
) {
    if let Some((p, q)) = crate::image::overlay::project_segment(camera, a, b) {
        let (w, h) = (camera.width(), camera.height());
        painter.line_segment(
            [
                to_screen(image_rect, w, h, p),
                to_screen(image_rect, w, h, q),
            ],
            stroke,
        );
    }
}

fn draw_tree(
    painter: &egui::Painter,
    camera: &Camera,
    image_rect: Rect,
    node: &RayNode,
    lights: &[DVec3],
    extent: f64,
) {
    let origin = DVec3::from_array(node.origin);
    let dir = DVec3::from_array(node.direction);
    let end = node
        .hit
        .as_ref()
        .map_or(origin + dir * extent, |h| DVec3::from_array(h.point));
    segment(
        painter,
        camera,
        image_rect,
        origin,
        end,
        Stroke::new(2.0, kind_color(node.kind)),
    );
    if node.hit.is_some() {
        for s in &node.shadows {
            let Some(&light) = lights.get(s.light) else {
                continue;
            };
            let color = match s.verdict {
                ShadowVerdict::Lit => Color32::from_rgb(255, 230, 80),
                ShadowVerdict::Attenuated => Color32::from_rgb(200, 160, 60),
                ShadowVerdict::Blocked => Color32::from_rgb(200, 40, 40),
                ShadowVerdict::FacesAway => continue,
            };
            segment(
                painter,
                camera,
                image_rect,
                end,
                light,
                Stroke::new(1.0, color),
            );
        }
    }
    for c in &node.children {
        draw_tree(painter, camera, image_rect, c, lights, extent);
    }
}

fn rgb_text(c: [f64; 3]) -> String {
    format!("({:.3}, {:.3}, {:.3})", c[0], c[1], c[2])
}

/// The inspected pixel's ray tree as nested, collapsible rows; the ray
/// whose "walk" button was clicked, if one was.
pub fn ray_tree_ui(inspection: Option<&Inspection>, ui: &mut egui::Ui) -> Option<WalkTarget> {
    let Some(ins) = inspection else {
        ui.label("Ctrl+click the image (or turn on Inspect and click) to see a pixel's rays.");
        return None;
    };
    ui.label(format!(
        "pixel {},{} — colour {}",
        ins.pixel.0,
        ins.pixel.1,
        rgb_text(ins.tree.color)
    ));
    let mut picked = None;
    node_ui(ui, &ins.tree, &mut Vec::new(), &mut picked);
    picked
}

fn node_ui(
    ui: &mut egui::Ui,
    node: &RayNode,
    path: &mut Vec<usize>,
    picked: &mut Option<WalkTarget>,
) {
    let kind = match node.kind {
        RayKind::Eye => "eye",
        RayKind::Reflection => "reflection",
        RayKind::Refraction => "refraction",
    };
    let what = match &node.hit {
        Some(h) => format!(
            "{} #{} ({}) at {:.4}",
            h.kind.name(),
            h.object,
            h.material,
            h.distance
        ),
        None => "background".into(),
    };
    // A header of its own rather than `CollapsingHeader`, whose title never
    // wraps: the right panel is fixed-width, and a deep hit's line is long.
    let header = egui::RichText::new(format!("{kind} ray, depth {}: {what}", node.depth))
        .color(kind_color(node.kind));
    let id = ui.make_persistent_id(("ray", path.clone()));
    egui::collapsing_header::CollapsingState::load_with_default_open(ui.ctx(), id, node.depth <= 2)
        .show_header(ui, |ui| ui.add(egui::Label::new(header).wrap()))
        .body(|ui| {
            if ui
                .small_button("walk")
                .on_hover_text("step through this ray's octree walk")
                .clicked()
            {
                *picked = Some(WalkTarget {
                    path: path.clone(),
                    shadow: None,
                });
            }
            let v = |v: [f64; 3]| format!("({:.4}, {:.4}, {:.4})", v[0], v[1], v[2]);
            ui.label(format!("origin {}", v(node.origin)));
            ui.label(format!("direction {}", v(node.direction)));
            if let Some(h) = &node.hit {
                ui.label(format!("point {}", v(h.point)));
                ui.label(format!(
                    "normal {} ({})",
                    v(h.normal),
                    if h.entering { "entering" } else { "leaving" }
                ));
            }
            for s in &node.shadows {
                // The button first: a wrapped label takes the row's width.
                ui.horizontal(|ui| {
                    if s.query.is_some()
                        && ui
                            .small_button("walk")
                            .on_hover_text("step through this shadow ray's octree walk")
                            .clicked()
                    {
                        *picked = Some(WalkTarget {
                            path: path.clone(),
                            shadow: Some(s.light),
                        });
                    }
                    ui.add(
                        egui::Label::new(format!(
                            "light {}: {} (transmittance {:.3}) adds {}",
                            s.light,
                            s.verdict.name(),
                            s.transmittance,
                            rgb_text(s.color)
                        ))
                        .wrap(),
                    );
                });
            }
            ui.label(format!("local {}", rgb_text(node.local_color)));
            ui.label(format!(
                "colour {} × weight {:.3} = {}",
                rgb_text(node.color),
                node.weight,
                rgb_text(node.contribution)
            ));
            for (k, c) in node.children.iter().enumerate() {
                path.push(k);
                node_ui(ui, c, path, picked);
                path.pop();
            }
        });
}
