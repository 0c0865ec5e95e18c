//! The tree of rays one eye ray spawns, for explaining a pixel. Tracing is
//! generic over [`RayRecorder`]: [`NoRecord`] compiles every hook away,
//! [`RayNode`] keeps the whole tree. The JSON of [`RayNode`] is the
//! documented output of `glint render --trace-pixel` (docs/inspection.md, "A
//! pixel's ray tree"): add fields, never rename them.

use serde::Serialize;

use crate::math::{Color, Ray};
use crate::shapes::ShapeKind;
use crate::stats::walk_record::QueryRecord;

/// Why a ray was cast.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum RayKind {
    Eye,
    Reflection,
    Refraction,
}

/// What a ray hit.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct HitRecord {
    /// Index of the shape in the scene's shape list.
    pub object: u32,
    /// Kind of the shape: sphere, plane, triangle, quadric, cone.
    pub kind: ShapeKind,
    pub material: String,
    pub distance: f64,
    pub point: [f64; 3],
    /// Shading normal, turned to face the incoming ray.
    pub normal: [f64; 3],
    /// Whether the ray enters the surface (hits its outside).
    pub entering: bool,
}

/// What a light does at a hit point.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum ShadowVerdict {
    /// The shadow ray reaches the light unhindered.
    Lit,
    /// An opaque surface blocks it.
    Blocked,
    /// It passes through transparent surfaces, which dim the light.
    Attenuated,
    /// The surface faces away from the light: no shadow ray is cast.
    FacesAway,
}

impl ShadowVerdict {
    /// As the JSON spells it.
    pub fn name(self) -> &'static str {
        match self {
            ShadowVerdict::Lit => "lit",
            ShadowVerdict::Blocked => "blocked",
            ShadowVerdict::Attenuated => "attenuated",
            ShadowVerdict::FacesAway => "faces-away",
        }
    }
}

/// One light's verdict at a hit point.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct ShadowRecord {
    pub light: usize,
    pub verdict: ShadowVerdict,
    /// Fraction of the light arriving: 1 lit, 0 blocked or faces-away.
    pub transmittance: f64,
    /// Diffuse and specular light this light adds (linear RGB).
    pub color: [f64; 3],
    /// What the shadow ray's query did (`walk`, `walk_end` and its counts;
    /// absent when no shadow ray was cast).
    #[serde(flatten)]
    pub query: Option<QueryRecord>,
}

/// One ray of the tree and what it brought back.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct RayNode {
    pub kind: RayKind,
    /// Recursion depth: the eye ray is 1.
    pub depth: u32,
    pub origin: [f64; 3],
    pub direction: [f64; 3],
    /// `null` for a ray that leaves the scene (it returns the background).
    pub hit: Option<HitRecord>,
    pub shadows: Vec<ShadowRecord>,
    /// Ambient plus direct light at the hit (or the background).
    pub local_color: [f64; 3],
    /// Weight the parent gives this ray's colour (1 for the eye ray).
    pub weight: f64,
    /// Colour seen along this ray: `local_color` plus the children's
    /// `weight * color` (linear RGB).
    pub color: [f64; 3],
    /// `weight * color`: what this ray adds to its parent.
    pub contribution: [f64; 3],
    /// What the ray's closest-hit query did: `walk`, `walk_end` and its
    /// Havran counts (docs/inspection.md, "A ray's walk through the octree").
    #[serde(flatten)]
    pub query: Option<QueryRecord>,
    pub children: Vec<RayNode>,
}

impl RayNode {
    pub fn new(kind: RayKind, ray: &Ray, depth: u32, weight: f64) -> Self {
        Self {
            kind,
            depth,
            origin: ray.origin.to_array(),
            direction: ray.dir.to_array(),
            hit: None,
            shadows: Vec::new(),
            local_color: [0.0; 3],
            weight,
            color: [0.0; 3],
            contribution: [0.0; 3],
            query: None,
            children: Vec::new(),
        }
    }

    /// Every ray in the tree, depth first.
    pub fn rays(&self) -> Vec<&RayNode> {
        let mut out = vec![self];
        for c in &self.children {
            out.extend(c.rays());
        }
        out
    }
}

/// Receives what tracing one ray finds.
pub trait RayRecorder: Sized {
    /// A recorder for a secondary ray.
    fn child(&self, kind: RayKind, ray: &Ray, depth: u32, weight: f64) -> Self;
    #[inline(always)]
    fn hit(&mut self, _record: impl FnOnce() -> HitRecord) {}
    #[inline(always)]
    fn shadow(&mut self, _record: impl FnOnce() -> ShadowRecord) {}
    /// What the ray's closest-hit query did (its octree walk).
    #[inline(always)]
    fn query(&mut self, _record: impl FnOnce() -> Option<QueryRecord>) {}
    /// What the shadow ray of the last [`RayRecorder::shadow`] did.
    #[inline(always)]
    fn shadow_query(&mut self, _record: impl FnOnce() -> Option<QueryRecord>) {}
    /// The material of the surface hit (cheap, for the adaptive sampler).
    #[inline(always)]
    fn material(&mut self, _index: u32) {}
    /// Where the ray hit (cheap, for the render cache).
    #[inline(always)]
    fn surface(&mut self, _point: crate::math::DVec3) {}
    /// Whether light `index` reaches the hit point.
    #[inline(always)]
    fn light(&mut self, _index: usize, _lit: bool) {}
    #[inline(always)]
    fn local(&mut self, _color: Color) {}
    #[inline(always)]
    fn attach(&mut self, _child: Self, _color: Color) {}
    #[inline(always)]
    fn finish(&mut self, _color: Color) {}
}

/// Records nothing; the default.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoRecord;

impl RayRecorder for NoRecord {
    #[inline(always)]
    fn child(&self, _: RayKind, _: &Ray, _: u32, _: f64) -> Self {
        NoRecord
    }
}

impl RayRecorder for RayNode {
    fn child(&self, kind: RayKind, ray: &Ray, depth: u32, weight: f64) -> Self {
        RayNode::new(kind, ray, depth, weight)
    }
    fn hit(&mut self, record: impl FnOnce() -> HitRecord) {
        self.hit = Some(record());
    }
    fn shadow(&mut self, record: impl FnOnce() -> ShadowRecord) {
        self.shadows.push(record());
    }
    fn query(&mut self, record: impl FnOnce() -> Option<QueryRecord>) {
        self.query = record();
    }
    fn shadow_query(&mut self, record: impl FnOnce() -> Option<QueryRecord>) {
        let record = record();
        if let Some(shadow) = self.shadows.last_mut() {
            shadow.query = record;
        }
    }
    fn local(&mut self, color: Color) {
        self.local_color = color.to_array();
    }
    fn attach(&mut self, mut child: Self, color: Color) {
        child.color = color.to_array();
        child.contribution = (color * child.weight).to_array();
        self.children.push(child);
    }
    fn finish(&mut self, color: Color) {
        self.color = color.to_array();
        self.contribution = (color * self.weight).to_array();
    }
}
