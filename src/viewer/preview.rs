//! How a preview while the user drags simplifies the image: its
//! resolution, reflections and shadows (chosen by [`super::budget`]).

/// How a preview while moving simplifies the image to fit the frame budget.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Preview {
    /// 1/`divisor` of the resolution on each axis.
    pub divisor: u32,
    /// How deep reflection and refraction rays go.
    pub reflections: Reflections,
    pub shadows: bool,
}

/// Reflection and refraction in a preview.
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

impl Preview {
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
