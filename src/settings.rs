//! Everything that decides an image besides the scene: what it shows, how
//! many rays, by which rules. Scene files set defaults; the command line
//! and the viewer override them.

use crate::color::ColorConvention;
use crate::scene::Scene;
pub use crate::scene::{AntiAliasing, Sides};

/// What the image shows.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ViewMode {
    /// Whitted shading (sRGB encoded on output).
    #[default]
    Shaded,
    /// Geometric normal facing the camera as `(n + 1) / 2`, not sRGB encoded.
    Normals,
    /// Distance along the eye ray as `nearest / distance`: the nearest
    /// visible point white, falling off towards black at the horizon.
    Depth,
    /// Intersection tests summed over every ray a pixel spawned (eye,
    /// shadow, reflection, refraction), on the viridis colour map.
    Cost,
    /// Like [`ViewMode::Cost`], counting octree traversal steps.
    CostSteps,
    /// |1 sample − 16 samples| per pixel in sRGB, gain 4: where
    /// anti-aliasing changes the picture. Built from two shaded renders.
    AaNeed,
}

impl ViewMode {
    pub const ALL: [ViewMode; 6] = [
        ViewMode::Shaded,
        ViewMode::Normals,
        ViewMode::Depth,
        ViewMode::Cost,
        ViewMode::CostSteps,
        ViewMode::AaNeed,
    ];

    pub fn name(self) -> &'static str {
        match self {
            ViewMode::Shaded => "shaded",
            ViewMode::Normals => "normals",
            ViewMode::Depth => "depth",
            ViewMode::Cost => "cost",
            ViewMode::CostSteps => "cost-steps",
            ViewMode::AaNeed => "aa-need",
        }
    }

    /// Whether pixels count the work of their rays.
    pub fn is_cost(self) -> bool {
        matches!(self, ViewMode::Cost | ViewMode::CostSteps)
    }

    /// Whether each eye ray is shaded (the full Whitted recursion runs).
    pub(crate) fn traces_shading(self) -> bool {
        matches!(
            self,
            ViewMode::Shaded | ViewMode::Cost | ViewMode::CostSteps | ViewMode::AaNeed
        )
    }
}

impl std::str::FromStr for ViewMode {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL.into_iter().find(|v| v.name() == s).ok_or_else(|| {
            format!(
                "unknown view `{s}` (expected shaded, normals, depth, cost, cost-steps or aa-need)"
            )
        })
    }
}

/// The rules rays are cast by.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Protocol {
    /// glint's own: rays through pixel centres (or a regular grid in
    /// each pixel), a mirror ray only from surfaces with reflectivity.
    #[default]
    Glint,
    /// The SPD's test protocol (Haines, SPD Readme; `spd_protocol.md`):
    /// rays through the pixel corners, each pixel the mean of its four
    /// corners; every ray that hits a reflective or transmitting surface
    /// spawns a reflection ray; depth 5 (set by the callers that select it).
    Spd,
}

impl Protocol {
    pub const ALL: [Protocol; 2] = [Protocol::Glint, Protocol::Spd];

    pub fn name(self) -> &'static str {
        match self {
            Protocol::Glint => "glint",
            Protocol::Spd => "spd",
        }
    }

    /// The recursion depth the protocol prescribes, if any.
    pub fn max_depth(self) -> Option<u32> {
        match self {
            Protocol::Glint => None,
            Protocol::Spd => Some(5),
        }
    }

    /// The sidedness the protocol prescribes, if any.
    pub fn sides(self) -> Option<Sides> {
        match self {
            Protocol::Glint => None,
            Protocol::Spd => Some(Sides::One),
        }
    }
}

impl std::str::FromStr for Protocol {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|p| p.name() == s)
            .ok_or_else(|| format!("unknown protocol `{s}` (expected glint or spd)"))
    }
}

/// Everything that decides the image besides the scene; the command line
/// and the viewer override the scene's own values.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    /// Rays per pixel on a regular grid (ignored by [`Protocol::Spd`],
    /// which shoots the pixel corners).
    pub samples: u32,
    pub max_depth: u32,
    pub use_octree: bool,
    pub view: ViewMode,
    /// Records written before these settings existed were rendered with
    /// their defaults.
    #[serde(default)]
    pub protocol: Protocol,
    #[serde(default)]
    pub colors: ColorConvention,
    #[serde(default)]
    pub sides: Sides,
    /// With `samples > 1`: trace every pixel's centre, then the full grid
    /// only where the picture shows an edge (see [`crate::adaptive`]).
    #[serde(default)]
    pub adaptive: bool,
    /// Cast shadow rays (off only in the viewer's previews while moving:
    /// every light then reaches every point that faces it).
    #[serde(default = "yes", skip_serializing_if = "Clone::clone")]
    pub shadows: bool,
}

fn yes() -> bool {
    true
}

impl RenderSettings {
    pub fn from_scene(scene: &Scene) -> Self {
        Self {
            width: scene.image.width,
            height: scene.image.height,
            samples: scene.image.samples,
            max_depth: scene.image.max_depth,
            use_octree: scene.octree_enabled,
            view: ViewMode::Shaded,
            protocol: Protocol::Glint,
            colors: scene.image.colors,
            sides: scene.image.sides,
            adaptive: scene.image.adaptive,
            shadows: true,
        }
    }

    /// The anti-aliasing these settings ask for.
    pub fn anti_aliasing(&self) -> AntiAliasing {
        match (self.samples, self.adaptive) {
            (1, _) => AntiAliasing::Off,
            (_, true) => AntiAliasing::Adaptive,
            _ => AntiAliasing::Full,
        }
    }

    /// Sets the anti-aliasing: off is 1 sample, full the 4x4 grid, adaptive
    /// the 4x4 grid where the picture needs it.
    pub fn set_anti_aliasing(&mut self, aa: AntiAliasing) {
        (self.samples, self.adaptive) = match aa {
            AntiAliasing::Off => (1, false),
            AntiAliasing::Adaptive => (16, true),
            AntiAliasing::Full => (16, false),
        };
    }

    /// Switches to `protocol`, taking the depth and sidedness it prescribes.
    pub fn with_protocol(self, protocol: Protocol) -> Self {
        Self {
            protocol,
            max_depth: protocol.max_depth().unwrap_or(self.max_depth),
            sides: protocol.sides().unwrap_or(self.sides),
            ..self
        }
    }

    /// Whether eye rays go through pixel corners (the SPD protocol).
    pub fn corner_rays(&self) -> bool {
        self.protocol == Protocol::Spd
    }
}
