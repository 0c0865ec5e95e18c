//! The frame budget while the user drags: the render cache where it
//! serves the view, else which reduced preview (resolution, reflections,
//! shadows) fits the time, estimated from the passes so far.

pub use super::preview::reuse_seconds;
use super::worker::{PassRecord, Preview, Reduced, Reflections};
use crate::render::PassKind as Engine;
use crate::settings::RenderSettings;

/// Whether previews while moving use the render cache: where it serves the
/// view ([`crate::render::render_cache::serves`]), unless the environment
/// variable `GLINT_PREVIEW` is `reduced` (the reduced previews glint showed
/// before it, to compare the two on the same build). Read once.
pub fn reuses(settings: &RenderSettings) -> bool {
    static REDUCED: std::sync::OnceLock<bool> = std::sync::OnceLock::new();
    let reduced =
        *REDUCED.get_or_init(|| std::env::var("GLINT_PREVIEW").is_ok_and(|v| v == "reduced"));
    !reduced && crate::render::render_cache::serves(settings)
}

/// The preview to render while the user drags: the best image whose estimated time fits the frame budget. Candidates in order
/// of preference: full, 1/2, 1/4, 1/8 resolution, each first complete,
/// then with one bounce of reflection and refraction (glass and mirrors
/// keep their look), then without reflections, then without shadows too. Estimates come
/// from this scene's last full 1-sample pass (its time per pixel, and
/// its rays by kind for what dropping reflections or shadows saves),
/// made more careful when the last preview took longer than estimated; a
/// candidate already tried is judged by its own measured times.
pub fn choose_preview(
    history: &[PassRecord],
    settings: &RenderSettings,
    budget_ms: f64,
) -> Option<(Preview, f64)> {
    if reuses(settings) && reuse_keeps_up(history, settings, budget_ms) {
        return Some((Preview::Reuse, reuse_seconds(budget_ms)));
    }
    choose_reduced(history, settings, budget_ms).map(|(p, t)| (Preview::Reduced(p), t))
}

/// How many times its aim the render cache's previews may take before the
/// reduced previews are shown instead.
const REUSE_OVERRUN: f64 = 2.5;

/// Previews the rule of [`reuse_keeps_up`] looks at.
const REUSE_JUDGED: usize = 5;

/// Whether the render cache keeps up at this image size: the median of its
/// last [`REUSE_JUDGED`] previews of it within [`REUSE_OVERRUN`] times their
/// aim (a large image on few cores can take several times the budget even
/// at the cache's coarsest scale: its enlargement and upload alone are a
/// frame's worth; the reduced previews then keep the motion fluid).
/// Previews that seeded the cache (the first of a drag, and after a change
/// of scale) trace a ray for every point and are not judged. Untried, it is
/// given the chance.
fn reuse_keeps_up(history: &[PassRecord], settings: &RenderSettings, budget_ms: f64) -> bool {
    let mut recent: Vec<f64> = history
        .iter()
        .rev()
        .filter(|r| {
            r.reuse.is_some_and(|s| !s.seeded)
                && (r.width, r.height) == (settings.width, settings.height)
        })
        .take(REUSE_JUDGED)
        .map(|r| r.seconds)
        .collect();
    if recent.len() < REUSE_JUDGED {
        return true;
    }
    recent.sort_by(f64::total_cmp);
    recent[REUSE_JUDGED / 2] <= REUSE_OVERRUN * reuse_seconds(budget_ms)
}

/// The reduced preview that fits `budget_ms`, and its estimated seconds.
fn choose_reduced(
    history: &[PassRecord],
    settings: &RenderSettings,
    budget_ms: f64,
) -> Option<(Reduced, f64)> {
    let fallback = Reduced {
        divisor: 4,
        reflections: Reflections::All,
        shadows: true,
    };
    let Some(base) = history.iter().rev().find(|r| {
        r.kind.preview.is_none() && matches!(r.kind.pass, Engine::OneSample | Engine::Corners)
    }) else {
        return Some((fallback, f64::NAN));
    };
    let estimate = |p: &Reduced| estimate_preview(base, p, settings);
    // How far off the model was on the last preview it predicted: slower
    // than estimated makes every estimate more careful. Faster than
    // estimated makes none bolder: the model prices every ray alike, while
    // an eye ray in a packet costs a fraction of a single reflected ray
    // and its shadow rays, so a correction learnt on a preview without
    // reflections would send a drag into one with them at several times
    // the budget.
    let correction = history
        .iter()
        .rev()
        .find_map(|r| match r.kind.preview.and_then(|p| p.reduced()) {
            Some(p) if r.finished_at > base.finished_at => {
                Some((r.seconds / estimate(&p)).clamp(1.0, 4.0))
            }
            _ => None,
        })
        .unwrap_or(1.0);
    // A candidate measured since the base pass is judged by its own
    // recent times (the median of its last three), the model only guides
    // the choice of candidates not yet tried: a fixed cost per preview
    // makes the model's pixel scaling too hopeful for large previews.
    let measured = |p: &Reduced| {
        let mut times: Vec<f64> = history
            .iter()
            .rev()
            .filter(|r| {
                r.kind.preview == Some(Preview::Reduced(*p)) && r.finished_at > base.finished_at
            })
            .take(3)
            .map(|r| r.seconds)
            .collect();
        times.sort_by(f64::total_cmp);
        times.get(times.len() / 2).copied()
    };
    let budget = budget_ms / 1000.0;
    let candidates = [1u32, 2, 4, 8].into_iter().flat_map(|divisor| {
        [
            (Reflections::All, true),
            (Reflections::OneBounce, true),
            (Reflections::Off, true),
            (Reflections::Off, false),
        ]
        .map(|(reflections, shadows)| Reduced {
            divisor,
            reflections,
            shadows,
        })
    });
    let mut last = None;
    for p in candidates {
        let t = measured(&p).unwrap_or_else(|| estimate(&p) * correction);
        if t <= budget {
            return Some((p, t));
        }
        last = Some((p, t));
    }
    last
}

/// Estimated seconds of `preview` at the current settings, from the full
/// 1-sample pass `base`: time per pixel times the pixels, times the share
/// of its rays the preview still casts. The model: every hit (an eye ray's
/// or a secondary ray's) spawns on average the same number of secondary
/// and of shadow rays, so one bounce keeps the secondary rays of eye-ray
/// hits, and dropping reflections keeps only the eye-ray hits' shadow rays.
fn estimate_preview(base: &PassRecord, preview: &Reduced, settings: &RenderSettings) -> f64 {
    let per_pixel = base.seconds / (base.width as f64 * base.height as f64).max(1.0);
    let d = preview.divisor as f64;
    let pixels = (settings.width as f64 / d).max(1.0) * (settings.height as f64 / d).max(1.0);
    let r = base.rays;
    let total = r.total().max(1) as f64;
    let secondary = (r.reflection + r.refraction) as f64;
    let hits = r.primary_hits as f64;
    // Hits that spawn rays: the eye rays' and (at most) every secondary ray's.
    let all_hits = (hits + secondary).max(1.0);
    let shadow_per_hit = r.shadow as f64 / all_hits;
    let kept_secondary = match preview.reflections {
        Reflections::All => secondary,
        Reflections::OneBounce if settings.max_depth <= 2 => secondary,
        Reflections::OneBounce => secondary * hits / all_hits,
        Reflections::Off => 0.0,
    };
    let shadow = if preview.shadows {
        if kept_secondary == secondary {
            r.shadow as f64
        } else {
            shadow_per_hit * (hits + kept_secondary)
        }
    } else {
        0.0
    };
    let rays = r.primary as f64 + kept_secondary + shadow;
    per_pixel * pixels * (rays / total).max(0.05)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::stats::RayCounts;
    use crate::viewer::worker::ShownPass;

    fn base() -> PassRecord {
        PassRecord {
            generation: 1,
            kind: ShownPass::full(Engine::OneSample),
            seconds: 0.4,
            // 100 eye rays, 80 hit; 40 secondary rays; 240 shadow rays.
            rays: RayCounts {
                primary: 100,
                primary_hits: 80,
                shadow: 240,
                reflection: 30,
                refraction: 10,
                total_internal_reflections: 0,
            },
            accel: crate::settings::Accel::Octree,
            anti_aliasing: false,
            width: 800,
            height: 600,
            finished_at: 1.0,
            one_sample_error: None,
            refined_pixels: None,
            view: crate::settings::ViewMode::Shaded,
            max_depth: 5,
            protocol: crate::settings::Protocol::Glint,
            from_cache: false,
            reuse: None,
        }
    }

    fn settings() -> RenderSettings {
        RenderSettings {
            width: 800,
            height: 600,
            samples: 1,
            max_depth: 5,
            accel: crate::settings::Accel::Octree,
            view: crate::settings::ViewMode::Shaded,
            protocol: crate::settings::Protocol::Glint,
            colors: crate::color::ColorConvention::Linear,
            sides: crate::settings::Sides::Two,
            adaptive: false,
            shadows: true,
            textures: true,
        }
    }

    #[test]
    fn the_render_cache_gives_way_where_it_cannot_keep_up() {
        if !reuses(&settings()) {
            eprintln!("GLINT_PREVIEW=reduced: the render cache is off");
            return;
        }
        let reuse_record = |seconds, width| PassRecord {
            kind: ShownPass::drag_preview(Preview::Reuse),
            seconds,
            width,
            reuse: Some(Default::default()),
            ..base()
        };
        let seeding = |seconds| PassRecord {
            reuse: Some(crate::render::render_cache::PreviewSummary {
                seeded: true,
                ..Default::default()
            }),
            ..reuse_record(seconds, 800)
        };
        let choose =
            |history: &[PassRecord]| choose_preview(history, &settings(), 33.0).map(|(p, _)| p);
        // Untried, and after previews near their aim (25 ms of 33): the cache.
        assert_eq!(choose(&[base()]), Some(Preview::Reuse));
        let fast = [0.03, 0.028, 0.2, 0.03, 0.05].map(|s| reuse_record(s, 800));
        assert_eq!(choose(&fast), Some(Preview::Reuse), "the median is 30 ms");
        // Five at four times their aim: a reduced preview instead.
        let slow = [0.1, 0.11, 0.09, 0.1, 0.1].map(|s| reuse_record(s, 800));
        assert!(matches!(choose(&slow), Some(Preview::Reduced(_))));
        // Previews that seeded the cache are slow by nature: not judged.
        let seeded = [0.1, 0.11, 0.09, 0.1, 0.1].map(seeding);
        assert_eq!(choose(&seeded), Some(Preview::Reuse));
        // Slow at another size says nothing about this one.
        let other = [0.1, 0.11, 0.09, 0.1, 0.1].map(|s| reuse_record(s, 1920));
        assert_eq!(choose(&other), Some(Preview::Reuse));
    }

    #[test]
    fn the_budget_picks_the_best_preview_that_fits() {
        let p = |divisor, reflections, shadows| Reduced {
            divisor,
            reflections,
            shadows,
        };
        let history = [base()];
        let choose = |ms| choose_reduced(&history, &settings(), ms).map(|(p, _)| p);
        // The full 1-sample pass took 400 ms.
        assert_eq!(choose(500.0), Some(p(1, Reflections::All, true)));
        // 1/2 resolution: 100 ms; without reflections 100 * 260/380 = 68 ms.
        assert_eq!(choose(100.0), Some(p(2, Reflections::All, true)));
        // One bounce at 1/2: 100 * 340/380 = 89 ms (see the estimates test).
        assert_eq!(choose(90.0), Some(p(2, Reflections::OneBounce, true)));
        assert_eq!(choose(70.0), Some(p(2, Reflections::Off, true)));
        // Resolution goes before effects: 1/2 with neither reflections nor
        // shadows (100 * 100/380 = 26 ms) before 1/4 (25 ms).
        assert_eq!(choose(33.0), Some(p(2, Reflections::Off, false)));
        // 1/4 without reflections: 25 * 260/380 = 17 ms.
        assert_eq!(choose(20.0), Some(p(4, Reflections::Off, true)));
        // Nothing fits: the cheapest candidate.
        assert_eq!(choose(0.001), Some(p(8, Reflections::Off, false)));
        // No full pass yet: a quarter-resolution guess.
        assert_eq!(
            choose_reduced(&[], &settings(), 33.0).map(|(p, _)| p),
            Some(p(4, Reflections::All, true))
        );
    }

    #[test]
    fn a_preview_slower_than_estimated_corrects_the_next_choice() {
        // The last 1/4 preview took four times its 25 ms estimate: the
        // model is scaled by 4, so 1/2 bare (4 x 26 ms) no longer fits 33 ms
        // and 1/4 bare (4 x 6.6 ms) does.
        let mut slow = base();
        slow.kind = ShownPass::drag_preview(Preview::Reduced(Reduced {
            divisor: 4,
            reflections: Reflections::All,
            shadows: true,
        }));
        slow.seconds = 0.1;
        slow.finished_at = 2.0;
        let history = [base(), slow];
        let (chosen, estimate) = choose_reduced(&history, &settings(), 33.0).unwrap();
        assert_eq!(
            chosen,
            Reduced {
                divisor: 4,
                reflections: Reflections::Off,
                shadows: false
            }
        );
        assert!(
            (estimate - 4.0 * 0.4 / 16.0 * 100.0 / 380.0).abs() < 1e-12,
            "{estimate}"
        );
    }

    #[test]
    fn a_preview_measured_over_budget_is_not_chosen_again() {
        // The full 1-sample pass took 400 ms, so the model puts 1/2 at
        // 100 ms, within 104 ms; measured at 150 ms it is left out, and
        // 1/2 with one bounce (89 ms) is next.
        let p = |divisor, reflections| Reduced {
            divisor,
            reflections,
            shadows: true,
        };
        let at = |kind, seconds, finished_at| PassRecord {
            kind: ShownPass::drag_preview(Preview::Reduced(kind)),
            seconds,
            finished_at,
            ..base()
        };
        // The latest preview as fast as estimated: no correction.
        let history = [
            base(),
            at(p(2, Reflections::All), 0.15, 2.0),
            at(p(4, Reflections::All), 0.025, 3.0),
        ];
        let (chosen, estimate) = choose_reduced(&history, &settings(), 104.0).unwrap();
        assert_eq!(chosen, p(2, Reflections::OneBounce));
        assert!((estimate - 0.1 * 340.0 / 380.0).abs() < 1e-12, "{estimate}");
        let unmeasured = [base(), history[2]];
        let (chosen, _) = choose_reduced(&unmeasured, &settings(), 104.0).unwrap();
        assert_eq!(chosen, p(2, Reflections::All));
        // A preview faster than estimated makes no other estimate bolder.
        let fast = [base(), at(p(4, Reflections::All), 0.005, 3.0)];
        let (chosen, estimate) = choose_reduced(&fast, &settings(), 104.0).unwrap();
        assert_eq!(chosen, p(2, Reflections::All));
        assert!((estimate - 0.1).abs() < 1e-12, "{estimate}");
    }

    #[test]
    fn preview_estimates_scale_with_pixels_and_rays_cast() {
        let settings = settings();
        let p = |divisor, reflections, shadows| Reduced {
            divisor,
            reflections,
            shadows,
        };
        let full = estimate_preview(&base(), &p(1, Reflections::All, true), &settings);
        assert!((full - 0.4).abs() < 1e-12, "the base pass itself");
        let half = estimate_preview(&base(), &p(2, Reflections::All, true), &settings);
        assert!((half - 0.1).abs() < 1e-12, "a quarter of the pixels");
        // Without reflections: 100 eye rays and the 240 * 80/120 = 160
        // shadow rays of eye-ray hits, of 380 rays.
        // One bounce: of the 40 secondary rays, those of eye-ray hits,
        // 40 * 80/120; shadow rays 2 per hit (240 over 120 hits) of the
        // 80 + 26.7 hits left: 100 + 26.7 + 213.3 = 340 of 380 rays.
        let one = estimate_preview(&base(), &p(1, Reflections::OneBounce, true), &settings);
        assert!((one - 0.4 * 340.0 / 380.0).abs() < 1e-12, "{one}");
        // With the scene's depth at 2, one bounce is all of them.
        let shallow = RenderSettings {
            max_depth: 2,
            ..settings
        };
        let one = estimate_preview(&base(), &p(1, Reflections::OneBounce, true), &shallow);
        assert!((one - 0.4).abs() < 1e-12, "{one}");
        let flat = estimate_preview(&base(), &p(1, Reflections::Off, true), &settings);
        assert!((flat - 0.4 * 260.0 / 380.0).abs() < 1e-12, "{flat}");
        let bare = estimate_preview(&base(), &p(1, Reflections::Off, false), &settings);
        assert!((bare - 0.4 * 100.0 / 380.0).abs() < 1e-12, "{bare}");
    }
}
