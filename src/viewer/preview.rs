//! What the viewer shows while the camera, a light or a material moves:
//! the render cache's whole-image preview with the scene's own shading
//! ([`crate::render::render_cache`]), or, for the views and rules the cache
//! does not serve, a reduced 1-sample pass (its resolution, reflections and
//! shadows chosen by [`super::budget`]).

/// How a preview while moving is made.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Preview {
    /// The render cache: the last picture's points moved into the new view,
    /// fresh rays where they matter most within the frame's time, the rest
    /// filled; the whole image (a point for every pixel, or for every
    /// block of pixels, enlarged), full depth, shadows.
    Reuse,
    /// A 1-sample pass, simplified to fit the frame budget.
    Reduced(Reduced),
}

/// How a reduced preview simplifies the image to fit the frame budget.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Reduced {
    /// 1/`divisor` of the resolution on each axis.
    pub divisor: u32,
    /// How deep reflection and refraction rays go.
    pub reflections: Reflections,
    pub shadows: bool,
}

/// Reflection and refraction in a reduced preview.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Reflections {
    /// To the scene's depth.
    All,
    /// One bounce: the eye ray's reflection and refraction rays, not
    /// theirs (glass and mirrors keep their look, deeper paths go).
    OneBounce,
    /// None: the eye ray only.
    Off,
}

/// The time a render-cache preview aims at, of a frame budget of
/// `budget_ms`: three quarters, leaving the rest for putting it on screen
/// (the window's texture upload and drawing run beside the next preview).
pub fn reuse_seconds(budget_ms: f64) -> f64 {
    budget_ms * 0.75 / 1000.0
}

impl Preview {
    /// E.g. "reused points and fresh rays" or "1/2, no reflections".
    pub fn describe(&self) -> String {
        match self {
            Preview::Reuse => "render cache".to_string(),
            Preview::Reduced(r) => r.describe(),
        }
    }

    /// The reduced preview's settings, if it is one.
    pub fn reduced(&self) -> Option<Reduced> {
        match self {
            Preview::Reduced(r) => Some(*r),
            Preview::Reuse => None,
        }
    }
}

impl Reduced {
    /// E.g. "1/2, no reflections".
    pub fn describe(&self) -> String {
        let mut s = if self.divisor == 1 {
            "full resolution".to_string()
        } else {
            format!("1/{}", self.divisor)
        };
        match self.reflections {
            Reflections::All => {}
            Reflections::OneBounce => s.push_str(", one bounce"),
            Reflections::Off => s.push_str(", no reflections"),
        }
        if !self.shadows {
            s.push_str(", no shadows");
        }
        s
    }
}
