//! What the user edits in the viewer: the scene, its camera and the render
//! settings. Plain data, no runtime handles: panels edit it directly, and
//! any change to it restarts the passes.

use std::path::PathBuf;
use std::sync::Arc;

use crate::accel::OctreeParams;
use crate::camera::CameraSpec;
use crate::camera_path::CameraPath;
use crate::material::{Light, Material};
use crate::scene::Scene;
use crate::settings::{Accel, RenderSettings};

/// A setting `--compare` flips for the A image.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CompareSetting {
    Octree,
    AntiAliasing,
}

/// How the image is scaled into its panel (display only: never a render).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Magnification {
    /// The largest whole number of screen pixels per image pixel that
    /// fits, so every pixel is an even, crisp block (fit when the image is
    /// larger than the panel).
    #[default]
    WholePixels,
    /// As large as fits, at any scale (blocks of uneven size).
    Fit,
    /// One image pixel per screen pixel, centred, cut at the panel's edges.
    Actual,
}

impl Magnification {
    pub const ALL: [Magnification; 3] = [
        Magnification::WholePixels,
        Magnification::Fit,
        Magnification::Actual,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Magnification::WholePixels => "Fit, whole pixels",
            Magnification::Fit => "Fit",
            Magnification::Actual => "1:1",
        }
    }

    /// Points per image pixel for an image `image` pixels in a panel
    /// `available` points, at `pixels_per_point` screen pixels per point.
    pub fn scale(self, image: (u32, u32), available: egui::Vec2, pixels_per_point: f32) -> f32 {
        let (w, h) = (image.0.max(1) as f32, image.1.max(1) as f32);
        let fit = (available.x / w).min(available.y / h);
        match self {
            Magnification::Fit => fit,
            Magnification::WholePixels => {
                let screen_pixels = fit * pixels_per_point;
                if screen_pixels >= 1.0 {
                    screen_pixels.floor() / pixels_per_point
                } else {
                    fit
                }
            }
            Magnification::Actual => 1.0 / pixels_per_point,
        }
    }
}

/// Where the current scene came from.
#[derive(Clone, Debug, PartialEq)]
pub enum SceneSource {
    BuiltIn,
    File(PathBuf),
}

impl SceneSource {
    pub fn load(&self) -> anyhow::Result<Scene> {
        Ok(match self {
            SceneSource::BuiltIn => crate::scene::builtin::default_scene()?,
            SceneSource::File(p) => crate::scene::load(p)?,
        })
    }

    /// The scene file, if there is one.
    pub fn path(&self) -> Option<&std::path::Path> {
        match self {
            SceneSource::BuiltIn => None,
            SceneSource::File(p) => Some(p),
        }
    }

    /// A short name for file names: the scene file's stem.
    pub fn stem(&self) -> String {
        match self {
            SceneSource::BuiltIn => "default".into(),
            SceneSource::File(p) => p
                .file_stem()
                .map_or("scene".into(), |s| s.to_string_lossy().into_owned()),
        }
    }

    /// The scene's name as the window shows it.
    pub fn display_name(&self) -> String {
        match self {
            SceneSource::BuiltIn => crate::scene::builtin::NAME.to_string(),
            SceneSource::File(p) => p.display().to_string(),
        }
    }
}

/// The scene, camera and settings the user edits.
#[derive(Clone, Debug)]
pub struct EditState {
    pub source: SceneSource,
    /// Shared with the render worker; edits copy lights and materials only
    /// (the geometry sits behind its own `Arc`).
    pub scene: Arc<Scene>,
    /// The scene as its file describes it, before any edit: what "Save
    /// scene" compares against (values equal to it stay as the file writes
    /// them).
    pub loaded: Arc<Scene>,
    /// Bumped whenever the scene changes, so the app can tell.
    pub scene_version: u64,
    pub camera: CameraSpec,
    /// The scene's camera path as edited (keyframes added, recorded,
    /// deleted); saved into the scene file's `[[camera.keyframes]]`.
    pub camera_path: Option<CameraPath>,
    /// What to render; with anti-aliasing, the 16-sample pass follows the
    /// 1-sample one.
    pub settings: RenderSettings,
    /// Target time of a preview pass while the user drags (milliseconds).
    pub frame_budget_ms: f64,
    /// While moving, colour the render cache's previews by where each
    /// pixel came from (fresh ray, reused point by age, filled).
    pub show_sources: bool,
}

/// Everything the user can edit, as one value: what undo and redo step
/// through, and (in part) what a saved scene holds.
#[derive(Clone, Debug, PartialEq)]
pub struct Snapshot {
    pub camera: CameraSpec,
    pub camera_path: Option<CameraPath>,
    pub settings: RenderSettings,
    pub lights: Vec<Light>,
    pub materials: Vec<Material>,
    /// The octree's parameters (the app rebuilds the tree to match).
    pub octree: OctreeParams,
}

impl Snapshot {
    /// Whether `self` and `other` differ in what "Save scene" writes: the
    /// camera, lights, materials, image size, samples, depth, colours,
    /// sides, the octree switch and its parameters (not the view or the
    /// protocol, which are ways of looking at the scene).
    pub fn differs_in_saved_values(&self, other: &Snapshot) -> bool {
        let saved = |s: &Snapshot| {
            let r = &s.settings;
            (
                r.width,
                r.height,
                r.samples,
                r.adaptive,
                r.max_depth,
                r.colors,
                r.sides,
                r.accel,
            )
        };
        self.camera != other.camera
            || self.camera_path != other.camera_path
            || self.lights != other.lights
            || self.materials != other.materials
            || self.octree != other.octree
            || saved(self) != saved(other)
    }

    /// Whether the camera is the only saved value `self` and `other`
    /// differ in (an orbit, nothing else edited).
    pub fn differs_only_in_camera(&self, other: &Snapshot) -> bool {
        let same_camera = Snapshot {
            camera: other.camera,
            ..self.clone()
        };
        self.camera != other.camera && !same_camera.differs_in_saved_values(other)
    }
}

impl EditState {
    /// Everything the user has edited, as one value.
    pub fn snapshot(&self) -> Snapshot {
        Snapshot {
            camera: self.camera,
            camera_path: self.camera_path.clone(),
            settings: self.settings,
            lights: self.scene.lights.clone(),
            materials: self.scene.materials.clone(),
            octree: self.scene.octree_params,
        }
    }

    /// Puts back an earlier [`Snapshot`] (undo, redo).
    pub fn restore(&mut self, s: &Snapshot) {
        self.camera = s.camera;
        self.camera_path.clone_from(&s.camera_path);
        self.settings = s.settings;
        if self.scene.lights != s.lights || self.scene.materials != s.materials {
            let scene = self.scene_mut();
            scene.lights.clone_from(&s.lights);
            scene.materials.clone_from(&s.materials);
        }
        // Not a scene edit: the geometry and the picture stay; the app
        // rebuilds the tree and renders again for its times.
        if self.scene.octree_params != s.octree {
            Arc::make_mut(&mut self.scene).octree_params = s.octree;
        }
    }

    /// Mutable access to lights and materials; marks the image stale.
    pub fn scene_mut(&mut self) -> &mut Scene {
        self.scene_version += 1;
        Arc::make_mut(&mut self.scene)
    }

    /// Flips a setting the A/B comparison compares: the octree on/off, or
    /// anti-aliasing on/off (keeping whether it is adaptive).
    pub fn flip(&mut self, setting: CompareSetting) {
        let s = &mut self.settings;
        match setting {
            CompareSetting::Octree => {
                s.accel = if s.accel == Accel::Octree {
                    Accel::BruteForce
                } else {
                    Accel::Octree
                }
            }
            CompareSetting::AntiAliasing => {
                s.samples = if s.samples > 1 {
                    1
                } else {
                    crate::settings::AntiAliasing::SAMPLES
                };
            }
        }
    }

    /// The settings in one line, as the A/B comparison labels its images.
    pub fn settings_label(&self) -> String {
        let s = &self.settings;
        format!(
            "{}, AA {}, {}, depth {}, {}x{}",
            s.view.name(),
            s.anti_aliasing().name(),
            match s.accel {
                Accel::Octree => "octree on",
                Accel::Bvh => "BVH",
                Accel::BruteForce => "octree off",
            },
            s.max_depth,
            s.width,
            s.height
        )
    }
}
