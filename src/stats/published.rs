//! Figures others published for the SPD scenes, which glint's own are
//! measured against: the ray counts in the README of Haines's Standard
//! Procedural Databases and V. Havran's best octree on each scene (his
//! 1999 octree statistics for the SPD). The figures are copied here, the
//! documents are not in this repository. `glint bench` prints them beside glint's,
//! and the tests check glint reproduces the counts.

use serde::Serialize;

/// The seven default SPD scenes, by file stem.
pub const SPD_SCENES: [&str; 7] = [
    "balls", "gears", "mount", "rings", "teapot", "tetra", "tree",
];

/// Ray counts the SPD Readme publishes for a default scene rendered by its
/// protocol (513 x 513 eye rays), which a ray tracer following its rules
/// should reproduce within about 10%.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct SpdCounts {
    pub eye_hits: u64,
    pub reflection: u64,
    /// Includes the rays that suffer total internal reflection, which the
    /// protocol's own rule 9 says are not spawned (docs/benchmarks.md, "The
    /// SPD protocol").
    pub refraction: u64,
    pub shadow: u64,
}

/// The published counts of the default SPD scene named `stem`.
pub fn spd_counts(stem: &str) -> Option<SpdCounts> {
    let (eye_hits, reflection, refraction, shadow) = match stem {
        "balls" => (263_169, 175_095, 0, 954_368),
        "gears" => (245_086, 304_643, 207_564, 2_246_955),
        "mount" => (173_125, 354_769, 354_769, 412_922),
        "rings" => (263_169, 315_236, 0, 1_085_002),
        "teapot" => (161_120, 225_248, 0, 407_656),
        "tetra" => (49_788, 0, 0, 46_112),
        "tree" => (169_836, 0, 0, 1_097_419),
        _ => return None,
    };
    Some(SpdCounts {
        eye_hits,
        reflection,
        refraction,
        shadow,
    })
}

/// Intersection tests per ray (N_IT) of Havran's best published octree
/// (Octree93-A at its best maximum depth) on the default SPD scene `stem`.
pub fn havran_best_nit(stem: &str) -> Option<f64> {
    Some(match stem {
        "balls" => 26.38,
        "gears" => 65.44,
        "mount" => 16.56,
        "rings" => 31.81,
        "teapot" => 47.91,
        "tetra" => 24.08,
        "tree" => 23.79,
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_default_scene_has_both_figures() {
        for stem in SPD_SCENES {
            let counts = spd_counts(stem).unwrap();
            assert!(counts.eye_hits <= 513 * 513, "{stem}");
            assert!(havran_best_nit(stem).unwrap() > 0.0);
        }
        assert_eq!(spd_counts("balls_s1"), None);
    }
}
