//! Tests of `worker`.

use super::*;
use crate::render::PassKind as Engine;
use crate::stats::RayCounts;

#[test]
fn passes_describe_what_they_dropped() {
    let preview = Reduced {
        divisor: 2,
        reflections: Reflections::Off,
        shadows: true,
    };
    assert_eq!(
        ShownPass::drag_preview(Preview::Reduced(preview)).label(),
        "preview 1/2, no reflections"
    );
    let one = Reduced {
        reflections: Reflections::OneBounce,
        ..preview
    };
    assert_eq!(one.describe(), "1/2, one bounce");
    let bare = Reduced {
        divisor: 1,
        reflections: Reflections::Off,
        shadows: false,
    };
    assert_eq!(
        bare.describe(),
        "full resolution, no reflections, no shadows"
    );
    assert_eq!(
        ShownPass::drag_preview(Preview::Reuse).label(),
        "preview render cache"
    );
}

/// The history keeps every full pass and the newest previews, in order,
/// and a list a reader holds does not change under it.
#[test]
fn the_history_keeps_full_passes_and_the_newest_previews() {
    let record = |generation: u64, preview: bool| PassRecord {
        generation,
        kind: if preview {
            ShownPass::drag_preview(Preview::Reduced(Reduced {
                divisor: 2,
                reflections: Reflections::Off,
                shadows: false,
            }))
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
        reuse: None,
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

#[test]
fn the_light_buffer_follows_moved_lights_and_new_geometry() {
    use crate::math::DVec3;
    let camera = crate::camera::CameraSpec {
        eye: DVec3::new(0.0, 0.0, 5.0),
        lookat: DVec3::ZERO,
        up: DVec3::Y,
        fov: 40.0,
    };
    let image = crate::scene::ImageSettings::default();
    let mut scene = crate::scene::Scene::empty("cache".into(), camera, image);
    scene.materials = vec![crate::material::Material::default()];
    let sphere = crate::shapes::Sphere::new(DVec3::ZERO, 1.0);
    scene.push(crate::shapes::Shape::Sphere(sphere), 0);
    scene.lights = vec![crate::material::Light {
        position: DVec3::new(2.0, 3.0, 4.0),
        color: DVec3::ONE,
    }];
    let mut cache = LightBufferCache::default();
    // Through the BVH: a one-leaf octree of one sphere asks no buffer.
    let fits = |c: &mut LightBufferCache, s: &crate::scene::Scene| {
        let settings = crate::settings::RenderSettings {
            accel: crate::settings::Accel::Bvh,
            ..s.render_settings()
        };
        let reuse = crate::render::Reuse {
            light_buffer: c.current(s),
            ..crate::render::Reuse::default()
        };
        let accel = crate::render::Accelerator::build(s, &settings, reuse).unwrap();
        c.keep(s, &accel);
        let lights: Vec<_> = s.lights.iter().map(|l| l.position).collect();
        accel
            .light_buffer()
            .is_some_and(|b| b.fits(s.shapes.len(), &lights))
    };
    let address = |c: &LightBufferCache| c.buffer.as_ref().map(Arc::as_ptr);
    assert!(fits(&mut cache, &scene));
    let first = address(&cache);
    // A new camera keeps it; a moved light builds it again.
    assert!(fits(&mut cache, &scene));
    assert_eq!(address(&cache), first);
    scene.lights[0].position.x += 1.0;
    assert!(fits(&mut cache, &scene));
    // Other geometry of the same size builds it again too.
    let mut other = scene.clone();
    other.shapes = Arc::new(other.shapes.as_ref().clone());
    assert!(fits(&mut cache, &other));
    assert!(
        cache
            .shapes
            .as_ref()
            .is_some_and(|s| Arc::ptr_eq(s, &other.shapes))
    );
}
