//! Tests of `worker`.

use super::*;
use crate::render::PassKind as Engine;
use crate::stats::RayCounts;

#[test]
fn passes_describe_what_they_dropped() {
    let preview = Preview {
        divisor: 2,
        reflections: Reflections::Off,
        shadows: true,
    };
    assert_eq!(
        ShownPass::drag_preview(preview).label(),
        "preview 1/2, no reflections"
    );
    let one = Preview {
        reflections: Reflections::OneBounce,
        ..preview
    };
    assert_eq!(one.describe(), "1/2, one bounce");
    let bare = Preview {
        divisor: 1,
        reflections: Reflections::Off,
        shadows: false,
    };
    assert_eq!(
        bare.describe(),
        "full resolution, no reflections, no shadows"
    );
}

/// The history keeps every full pass and the newest previews, in order,
/// and a list a reader holds does not change under it.
#[test]
fn the_history_keeps_full_passes_and_the_newest_previews() {
    let record = |generation: u64, preview: bool| PassRecord {
        generation,
        kind: if preview {
            ShownPass::drag_preview(Preview {
                divisor: 2,
                reflections: Reflections::Off,
                shadows: false,
            })
        } else {
            ShownPass::full(Engine::OneSample)
        },
        seconds: 0.01,
        rays: RayCounts::default(),
        accel: crate::settings::Accel::Octree,
        anti_aliasing: false,
        width: 8,
        height: 6,
        finished_at: generation as f64,
        one_sample_error: None,
        refined_pixels: None,
        view: crate::settings::ViewMode::Shaded,
        max_depth: 5,
        protocol: crate::settings::Protocol::Glint,
        from_cache: false,
    };
    let mut history = History::default();
    let extra = 10;
    let total = History::MAX_PREVIEWS + extra;
    let mut held = None;
    for g in 0..total as u64 {
        // A full pass every 1000 records, the rest previews.
        history.push(record(g, g % 1000 != 0));
        if g == 5 {
            held = Some(Arc::clone(&history.records));
        }
    }
    let records = &history.records;
    let fulls: Vec<u64> = records
        .iter()
        .filter(|r| r.kind.preview.is_none())
        .map(|r| r.generation)
        .collect();
    assert_eq!(fulls, [0, 1000, 2000, 3000, 4000]);
    let previews = records.len() - fulls.len();
    assert_eq!(previews, History::MAX_PREVIEWS);
    assert!(
        records
            .windows(2)
            .all(|w| w[0].generation < w[1].generation)
    );
    assert_eq!(history.last().map(|r| r.generation), Some(total as u64 - 1));
    // 4,101 previews were pushed: the oldest 5 (generations 1 to 5) went.
    let oldest_preview = records
        .iter()
        .find(|r| r.kind.preview.is_some())
        .map(|r| r.generation);
    assert_eq!(oldest_preview, Some(6));
    assert_eq!(held.map(|h| h.len()), Some(6));
}
