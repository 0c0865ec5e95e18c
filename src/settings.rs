//! Everything that decides an image besides the scene: what it shows, how
//! many rays, by which rules. Scene files set defaults; the command line
//! and the viewer override them.

use crate::accel::OctreeParams;
use crate::color::ColorConvention;
use crate::limits::LimitError;

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
    /// The SPD's test protocol (Haines, the SPD's README):
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

/// What ray queries go through. Each answers exactly alike (the image is
/// the same); build time, memory and render time differ.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Accel {
    /// The octree, glint's default.
    Octree,
    /// A bounding volume hierarchy ([`crate::accel::Bvh`]), to compare.
    Bvh,
    /// Every shape for every ray.
    BruteForce,
}

impl Accel {
    pub const ALL: [Accel; 3] = [Accel::Octree, Accel::Bvh, Accel::BruteForce];

    /// What `--octree on|off` (and a scene's `octree.enabled`) chooses.
    pub fn from_octree_switch(on: bool) -> Self {
        if on { Accel::Octree } else { Accel::BruteForce }
    }

    /// As `--accel` and the statistics name it.
    pub fn name(self) -> &'static str {
        match self {
            Accel::Octree => "octree",
            Accel::Bvh => "bvh",
            Accel::BruteForce => "none",
        }
    }
}

impl std::str::FromStr for Accel {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|a| a.name() == s)
            .ok_or_else(|| format!("unknown accelerator `{s}` (expected octree, bvh or none)"))
    }
}

/// Everything that decides the image besides the scene; the command line
/// and the viewer override the scene's own values.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(from = "RecordedSettings", into = "RecordedSettings")]
pub struct RenderSettings {
    pub width: u32,
    pub height: u32,
    /// Rays per pixel on a regular grid (ignored by [`Protocol::Spd`],
    /// which shoots the pixel corners).
    pub samples: u32,
    pub max_depth: u32,
    /// What ray queries go through.
    pub accel: Accel,
    pub view: ViewMode,
    pub protocol: Protocol,
    pub colors: ColorConvention,
    pub sides: Sides,
    /// With `samples > 1`: trace every pixel's centre, then the full grid
    /// only where the picture shows an edge (see [`crate::render::adaptive`]).
    pub adaptive: bool,
    /// Cast shadow rays (off only in the viewer's previews while moving:
    /// every light then reaches every point that faces it).
    pub shadows: bool,
    /// Draw materials' textures (off: each textured material in its own
    /// colour, with no cut-outs, to compare).
    pub textures: bool,
}

/// [`RenderSettings`] as PNG records and JSON write them: the accelerator
/// as `use_octree` and `bvh` (absent when false), the fields records held
/// before the BVH existed; fields added since default to what renders
/// made before them used.
#[derive(serde::Serialize, serde::Deserialize)]
struct RecordedSettings {
    width: u32,
    height: u32,
    samples: u32,
    max_depth: u32,
    use_octree: bool,
    view: ViewMode,
    #[serde(default)]
    protocol: Protocol,
    #[serde(default)]
    colors: ColorConvention,
    #[serde(default)]
    sides: Sides,
    #[serde(default)]
    adaptive: bool,
    #[serde(default = "yes", skip_serializing_if = "Clone::clone")]
    shadows: bool,
    #[serde(default, skip_serializing_if = "std::ops::Not::not")]
    bvh: bool,
    #[serde(default = "yes", skip_serializing_if = "Clone::clone")]
    textures: bool,
}

fn yes() -> bool {
    true
}

impl From<RecordedSettings> for RenderSettings {
    fn from(r: RecordedSettings) -> Self {
        let accel = if r.bvh {
            Accel::Bvh
        } else {
            Accel::from_octree_switch(r.use_octree)
        };
        Self {
            width: r.width,
            height: r.height,
            samples: r.samples,
            max_depth: r.max_depth,
            accel,
            view: r.view,
            protocol: r.protocol,
            colors: r.colors,
            sides: r.sides,
            adaptive: r.adaptive,
            shadows: r.shadows,
            textures: r.textures,
        }
    }
}

impl From<RenderSettings> for RecordedSettings {
    fn from(s: RenderSettings) -> Self {
        Self {
            width: s.width,
            height: s.height,
            samples: s.samples,
            max_depth: s.max_depth,
            use_octree: s.accel == Accel::Octree,
            view: s.view,
            protocol: s.protocol,
            colors: s.colors,
            sides: s.sides,
            adaptive: s.adaptive,
            shadows: s.shadows,
            bvh: s.accel == Accel::Bvh,
            textures: s.textures,
        }
    }
}

impl RenderSettings {
    /// Every value within [`crate::limits`].
    pub fn check(&self) -> Result<(), LimitError> {
        crate::limits::check_image_size(self.width, self.height)?;
        crate::limits::check_samples(self.samples)?;
        crate::limits::check_max_depth(self.max_depth)
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
            AntiAliasing::Adaptive => (AntiAliasing::SAMPLES, true),
            AntiAliasing::Full => (AntiAliasing::SAMPLES, false),
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

    /// Switches to `protocol` as the viewer does: entering the SPD protocol
    /// takes its depth and sidedness; leaving it restores the scene's own
    /// (`scene`, the scene's settings), which the protocol had replaced.
    pub fn switch_protocol(self, protocol: Protocol, scene: &RenderSettings) -> Self {
        if protocol == self.protocol {
            return self;
        }
        match protocol {
            Protocol::Glint => Self {
                protocol,
                max_depth: scene.max_depth,
                sides: scene.sides,
                ..self
            },
            Protocol::Spd => self.with_protocol(protocol),
        }
    }

    /// Whether eye rays go through pixel corners (the SPD protocol).
    pub fn corner_rays(&self) -> bool {
        self.protocol == Protocol::Spd
    }
}

/// Which sides of a surface rays can hit.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Sides {
    /// Every surface is seen from both sides (glint's default).
    #[default]
    Two,
    /// Opaque surfaces are seen from outside only, as the SPD allows (a
    /// ray meeting one from behind passes on). Transparent surfaces, and
    /// triangles with vertex normals (NFF `pp` patches, smooth meshes:
    /// tessellated open surfaces such as the SPD's teapot, which the SPD
    /// requires two-sided) stay two-sided.
    One,
}

impl Sides {
    pub const ALL: [Sides; 2] = [Sides::Two, Sides::One];

    pub fn name(self) -> &'static str {
        match self {
            Sides::Two => "two",
            Sides::One => "one",
        }
    }
}

impl std::str::FromStr for Sides {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|p| p.name() == s)
            .ok_or_else(|| format!("unknown sidedness `{s}` (expected one or two)"))
    }
}

/// Anti-aliasing, as the command line, the viewer and scene files name it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum AntiAliasing {
    /// One ray through each pixel's centre.
    #[default]
    Off,
    /// The centre everywhere, the 4x4 grid where neighbours differ.
    Adaptive,
    /// The regular 4x4 grid in every pixel.
    Full,
}

impl AntiAliasing {
    /// Rays per pixel with anti-aliasing: the regular 4x4 grid. The only
    /// other count glint renders is 1 (the pixel's centre).
    pub const SAMPLES: u32 = 16;

    pub const ALL: [AntiAliasing; 3] = [
        AntiAliasing::Off,
        AntiAliasing::Adaptive,
        AntiAliasing::Full,
    ];

    pub fn name(self) -> &'static str {
        match self {
            AntiAliasing::Off => "off",
            AntiAliasing::Adaptive => "adaptive",
            AntiAliasing::Full => "full",
        }
    }
}

impl std::str::FromStr for AntiAliasing {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Self::ALL
            .into_iter()
            .find(|a| a.name() == s)
            .ok_or_else(|| format!("unknown anti-aliasing `{s}` (expected off, adaptive or full)"))
    }
}

/// What the command line or the viewer asks for instead of a scene's own
/// settings; `None` keeps the scene's. `glint render`, `bench`, `view` and
/// the viewer all apply them through [`Overrides::apply`], in one order.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Overrides {
    pub width: Option<u32>,
    pub height: Option<u32>,
    pub anti_aliasing: Option<AntiAliasing>,
    pub max_depth: Option<u32>,
    /// What ray queries go through (`--accel`, or `--octree on|off`
    /// as [`Accel::from_octree_switch`] reads it).
    pub accel: Option<Accel>,
    pub octree: OctreeOverrides,
    pub view: Option<ViewMode>,
    /// Applied before colours and sides: it sets its own depth and sidedness.
    pub protocol: Option<Protocol>,
    pub colors: Option<ColorConvention>,
    pub sides: Option<Sides>,
    /// Draw materials' textures (`--textures on|off`).
    pub textures: Option<bool>,
}

/// Octree parameters overriding a scene's; `None` keeps the scene's.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OctreeOverrides {
    pub max_depth: Option<u32>,
    pub leaf_size: Option<u32>,
    pub cost_driven: Option<bool>,
    pub max_duplication: Option<u32>,
    pub memory_budget_mib: Option<u32>,
}

impl OctreeOverrides {
    pub fn apply(&self, params: &mut OctreeParams) {
        if let Some(d) = self.max_depth {
            params.max_depth = d;
        }
        if let Some(n) = self.leaf_size {
            params.leaf_size = n;
        }
        if let Some(c) = self.cost_driven {
            params.cost_driven = c;
        }
        if let Some(d) = self.max_duplication {
            params.max_duplication = d;
        }
        if let Some(m) = self.memory_budget_mib {
            params.memory_budget_mib = m;
        }
    }
}

impl Overrides {
    /// Applies the overrides to `settings` and the octree's `params`: size,
    /// anti-aliasing, depth, the octree switch and parameters, the view,
    /// then the protocol (which sets its depth and sidedness) and last the
    /// explicit colour and sidedness choices.
    pub fn apply(&self, settings: &mut RenderSettings, params: &mut OctreeParams) {
        if let Some(w) = self.width {
            settings.width = w;
        }
        if let Some(h) = self.height {
            settings.height = h;
        }
        if let Some(aa) = self.anti_aliasing {
            settings.set_anti_aliasing(aa);
        }
        if let Some(d) = self.max_depth {
            settings.max_depth = d;
        }
        if let Some(a) = self.accel {
            settings.accel = a;
        }
        self.octree.apply(params);
        if let Some(v) = self.view {
            settings.view = v;
        }
        if let Some(p) = self.protocol {
            *settings = settings.with_protocol(p);
        }
        if let Some(c) = self.colors {
            settings.colors = c;
        }
        if let Some(s) = self.sides {
            settings.sides = s;
        }
        if let Some(t) = self.textures {
            settings.textures = t;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn base() -> RenderSettings {
        RenderSettings {
            width: 64,
            height: 48,
            samples: 1,
            max_depth: 7,
            accel: Accel::Octree,
            view: ViewMode::Shaded,
            protocol: Protocol::Glint,
            colors: ColorConvention::Linear,
            sides: Sides::Two,
            adaptive: false,
            shadows: true,
            textures: true,
        }
    }

    #[test]
    fn each_accelerator_is_recorded_as_records_always_wrote_it_and_reads_back() {
        let fields = |accel| {
            let json = serde_json::to_value(RenderSettings { accel, ..base() }).unwrap();
            (json["use_octree"].as_bool(), json.get("bvh").cloned())
        };
        assert_eq!(
            fields(Accel::Octree),
            (Some(true), None),
            "bvh absent when false"
        );
        assert_eq!(fields(Accel::BruteForce), (Some(false), None));
        assert_eq!(fields(Accel::Bvh), (Some(false), Some(true.into())));
        for accel in Accel::ALL {
            let settings = RenderSettings { accel, ..base() };
            let json = serde_json::to_string(&settings).unwrap();
            let read: RenderSettings = serde_json::from_str(&json).unwrap();
            assert_eq!(read, settings);
        }
        // A record from before protocols, sides, adaptive and shadows.
        let old = r#"{"width":8,"height":6,"samples":1,"max_depth":5,"use_octree":false,"view":"shaded"}"#;
        let read: RenderSettings = serde_json::from_str(old).unwrap();
        assert_eq!(read.accel, Accel::BruteForce);
        assert!(read.shadows && !read.adaptive);
    }

    #[test]
    fn the_protocol_applies_after_depth_and_before_explicit_sides() {
        let mut settings = base();
        let mut params = OctreeParams::default();
        Overrides {
            max_depth: Some(3),
            protocol: Some(Protocol::Spd),
            sides: Some(Sides::Two),
            anti_aliasing: Some(AntiAliasing::Adaptive),
            octree: OctreeOverrides {
                leaf_size: Some(9),
                max_depth: Some(7),
                ..OctreeOverrides::default()
            },
            ..Overrides::default()
        }
        .apply(&mut settings, &mut params);
        assert_eq!(settings.max_depth, 5, "the SPD protocol fixes depth 5");
        assert_eq!(settings.sides, Sides::Two, "an explicit choice wins");
        assert_eq!((settings.samples, settings.adaptive), (16, true));
        assert_eq!(params.leaf_size, 9);
        assert_eq!(params.max_depth, 7);
    }

    #[test]
    fn leaving_the_spd_protocol_restores_the_scenes_depth_and_sides() {
        let scene = base();
        let spd = scene.switch_protocol(Protocol::Spd, &scene);
        assert_eq!((spd.max_depth, spd.sides), (5, Sides::One));
        let back = spd.switch_protocol(Protocol::Glint, &scene);
        assert_eq!(back, scene);
    }

    #[test]
    fn settings_outside_the_limits_are_refused() {
        use crate::limits::MAX_IMAGE_SIDE;
        assert!(base().check().is_ok());
        assert!(
            RenderSettings {
                samples: 16,
                ..base()
            }
            .check()
            .is_ok()
        );
        let refusal = |bad: RenderSettings| bad.check().err();
        assert!(matches!(
            refusal(RenderSettings {
                samples: 8,
                ..base()
            }),
            Some(LimitError::Samples(8))
        ));
        for depth in [0, 65] {
            assert!(matches!(
                refusal(RenderSettings {
                    max_depth: depth,
                    ..base()
                }),
                Some(LimitError::MaxDepth(d)) if d == depth
            ));
        }
        for (width, height) in [(0, 4), (MAX_IMAGE_SIDE + 1, 4)] {
            assert!(matches!(
                refusal(RenderSettings {
                    width,
                    height,
                    ..base()
                }),
                Some(LimitError::ImageSize(..))
            ));
        }
    }
}
