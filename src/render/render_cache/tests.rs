use std::time::Duration;

use super::*;
use crate::camera::CameraSpec;
use crate::material::Light;
use crate::scene::{ImageSettings, Scene};
use crate::shapes::{Plane, Sphere};

/// A floor, a diffuse sphere and a mirror sphere under one light, seen
/// from `(0, 2, 8)`, `size` pixels wide and three quarters as high, shifted
/// by `offset` (a scene far from the origin).
fn scene(size: u32, offset: DVec3) -> Scene {
    let mut s = Scene::empty(
        "unit".into(),
        CameraSpec {
            eye: offset + DVec3::new(0.0, 2.0, 8.0),
            lookat: offset + DVec3::new(0.0, 0.5, 0.0),
            up: DVec3::Y,
            fov: 40.0,
        },
        ImageSettings {
            width: size,
            height: size * 3 / 4,
            samples: 1,
            max_depth: 4,
            background: DVec3::new(0.3, 0.5, 0.8),
            ambient: DVec3::splat(0.1),
            ..ImageSettings::default()
        },
    );
    s.materials = vec![
        Material {
            name: "floor".into(),
            color: DVec3::new(0.7, 0.6, 0.5),
            ..Material::default()
        },
        Material {
            name: "red".into(),
            color: DVec3::new(0.8, 0.2, 0.1),
            ..Material::default()
        },
        Material {
            name: "mirror".into(),
            kd: 0.1,
            ks: 0.6,
            shininess: 200.0,
            reflectivity: 0.8,
            ..Material::default()
        },
    ];
    s.lights = vec![Light {
        position: offset + DVec3::new(-3.0, 6.0, 4.0),
        color: DVec3::ONE,
    }];
    s.push(Shape::Plane(Plane::new(offset, DVec3::Y)), 0);
    s.push(
        Shape::Sphere(Sphere::new(offset + DVec3::new(-1.0, 1.0, 0.0), 1.0)),
        1,
    );
    s.push(
        Shape::Sphere(Sphere::new(offset + DVec3::new(1.3, 0.8, 0.5), 0.8)),
        2,
    );
    s
}

/// The scene seen from its camera turned `degrees` about the vertical
/// axis through lookat.
fn turned(s: &Scene, degrees: f64) -> CameraSpec {
    let c = s.camera;
    let (sin, cos) = degrees.to_radians().sin_cos();
    let d = c.eye - c.lookat;
    CameraSpec {
        eye: c.lookat + DVec3::new(cos * d.x + sin * d.z, d.y, -sin * d.x + cos * d.z),
        ..c
    }
}

/// The 1-sample picture of `s` from `camera`, RGBA8 as shown.
fn exact(s: &Scene, camera: &CameraSpec) -> Vec<u8> {
    let accel = crate::render::Accelerator::of_octree(s, s.build_octree().unwrap());
    let r = Renderer::with_camera(s, &accel, s.render_settings(), camera).unwrap();
    let (frame, _) = r.render(false, None);
    crate::image::frame::rgb_to_rgba(&frame.to_rgb8())
}

/// Panics with the number of differing pixels (and the first) unless
/// `a` and `b` are the same picture.
#[track_caller]
fn assert_same_picture(a: &[u8], b: &[u8], what: &str) {
    assert_eq!(a.len(), b.len(), "{what}: sizes");
    let differing: Vec<usize> = (0..a.len() / 4)
        .filter(|&k| a[4 * k..4 * k + 4] != b[4 * k..4 * k + 4])
        .collect();
    if let Some(&k) = differing.first() {
        panic!(
            "{what}: {} of {} pixels differ, the first {k}: {:?} against {:?}",
            differing.len(),
            a.len() / 4,
            &a[4 * k..4 * k + 4],
            &b[4 * k..4 * k + 4]
        );
    }
}

/// Panics unless `a` and `b` agree within `tolerance` levels in every
/// channel on all but `share` of their pixels. A re-traced point's ray
/// passes where the point had landed in its pixel (within 1/16 pixel of
/// the centre for a seeded point), not always through the centre: close
/// to the 1-sample picture, exact only where its rays were.
#[track_caller]
fn assert_close_picture(a: &[u8], b: &[u8], tolerance: u8, share: f64, what: &str) {
    assert_eq!(a.len(), b.len(), "{what}: sizes");
    let off = (0..a.len() / 4)
        .filter(|&k| (0..3).any(|c| a[4 * k + c].abs_diff(b[4 * k + c]) > tolerance))
        .count();
    assert!(
        off as f64 <= share * (a.len() / 4) as f64,
        "{what}: {off} of {} pixels off by more than {tolerance}",
        a.len() / 4
    );
}

/// PSNR of RGBA8 pictures over their colour channels.
fn psnr(a: &[u8], b: &[u8]) -> f64 {
    crate::image::metrics::psnr_8bit(a, b, 4)
}

fn no_time() -> PreviewBudget {
    PreviewBudget {
        rays: Duration::ZERO,
    }
}

fn all_the_time() -> PreviewBudget {
    PreviewBudget {
        rays: Duration::from_secs(3600),
    }
}

/// What a preview showed: its summary, picture and sources.
struct Shown {
    summary: PreviewSummary,
    rgba: Vec<u8>,
    sources: Vec<PixelSource>,
    width: u32,
    height: u32,
}

fn show(
    cache: &mut RenderCache,
    renderer: &Renderer,
    seed: Option<(&Renderer, &[u8])>,
    budget: PreviewBudget,
) -> Shown {
    let summary = cache.preview(renderer, seed, budget);
    let (rgba, width, height) = cache.image();
    Shown {
        summary,
        rgba: rgba.to_vec(),
        sources: cache.sources(),
        width,
        height,
    }
}

/// A cache seeded from the exact picture at `s`'s camera, and the preview
/// at `camera` within `budget`.
fn preview_after_seed(s: &Scene, camera: &CameraSpec, budget: PreviewBudget) -> Shown {
    let accel = crate::render::Accelerator::of_octree(s, s.build_octree().unwrap());
    let seed = Renderer::new(s, &accel, s.render_settings()).unwrap();
    let r = Renderer::with_camera(s, &accel, s.render_settings(), camera).unwrap();
    let shown = exact(s, &s.camera);
    let mut cache = RenderCache::default();
    show(&mut cache, &r, Some((&seed, &shown)), budget)
}

#[test]
fn a_seeded_cache_shows_its_seed_again_from_the_same_eye() {
    // Every point lands back in its own pixel: the picture is the seed's,
    // byte for byte, with no ray traced; also far from the origin, where
    // positions relative to the scene's own origin would lose the pixel.
    for offset in [DVec3::ZERO, DVec3::new(3e6, -2e6, 5e6)] {
        let s = scene(64, offset);
        let preview = preview_after_seed(&s, &s.camera, no_time());
        assert!(preview.summary.seeded);
        assert_eq!(preview.summary.fresh, 0);
        assert_eq!(preview.summary.filled, 0, "offset {offset}");
        assert_same_picture(
            &preview.rgba,
            &exact(&s, &s.camera),
            &format!("offset {offset}"),
        );
        assert!(
            preview
                .sources
                .iter()
                .all(|s| *s == PixelSource::Reprojected { age: 1 })
        );
    }
}

#[test]
fn fresh_rays_give_the_one_sample_picture() {
    // An empty cache with time for every pixel traces them all through
    // their centres: the preview is the 1-sample render, byte for byte
    // (the same integrator, in packets where the scene allows).
    let s = scene(48, DVec3::ZERO);
    let camera = turned(&s, 10.0);
    let accel = crate::render::Accelerator::of_octree(&s, s.build_octree().unwrap());
    let r = Renderer::with_camera(&s, &accel, s.render_settings(), &camera).unwrap();
    let mut cache = RenderCache::default();
    let preview = show(&mut cache, &r, None, all_the_time());
    assert_eq!(preview.summary.fresh, preview.summary.pixels());
    assert_same_picture(&preview.rgba, &exact(&s, &camera), "traced");
    assert_eq!(preview.summary.rays.primary, preview.summary.pixels());
}

#[test]
fn a_turned_view_is_close_to_the_exact_one_without_a_ray() {
    // Two degrees of orbit, no time for rays: reprojected points and
    // filled gaps only. The diffuse surfaces and shadows move with the
    // surface; the mirror lags. Close, not equal.
    let s = scene(160, DVec3::ZERO);
    let camera = turned(&s, 2.0);
    let preview = preview_after_seed(&s, &camera, no_time());
    let truth = exact(&s, &camera);
    let db = psnr(&preview.rgba, &truth);
    assert!(db > 25.0, "{db:.1} dB");
    assert!(db < 60.0, "not exact: {db:.1} dB");
    assert_eq!(preview.summary.fresh, 0);
    assert!(
        preview.summary.reprojected > preview.summary.pixels() * 8 / 10,
        "{:?}",
        preview.summary
    );
    // With time for every ray it wants, the gaps and the mirror are traced
    // again and the preview comes closer still.
    let traced = preview_after_seed(&s, &camera, all_the_time());
    let better = psnr(&traced.rgba, &truth);
    assert!(better > db + 2.0, "{better:.1} dB against {db:.1} dB");
    assert_eq!(traced.summary.gaps_filled, 0);
}

#[test]
fn a_surface_moving_in_front_hides_what_it_covers() {
    // The view turns so that the red sphere moves across the floor and the
    // mirror: the floor's points that end behind it must not show through
    // the gaps between the sphere's points. Every pixel well inside the
    // sphere in the exact picture is red-dominated in the preview too.
    let s = scene(160, DVec3::ZERO);
    let camera = turned(&s, 6.0);
    let preview = preview_after_seed(&s, &camera, no_time());
    let truth = exact(&s, &camera);
    let accel = crate::render::Accelerator::of_octree(&s, s.build_octree().unwrap());
    let r = Renderer::with_camera(&s, &accel, s.render_settings(), &camera).unwrap();
    let (w, h) = (preview.width, preview.height);
    let mut query_scratch = crate::render::renderer::Scratch::default();
    let mut query = crate::render::renderer::Query {
        counter: &mut crate::stats::NoCounts,
        scratch: &mut query_scratch,
    };
    let mut on_sphere = |x: u32, y: u32| {
        let ray = r.camera.ray(x, y, 0.5, 0.5);
        r.closest(&crate::shapes::PreparedRay::new(ray), &mut query)
            .is_some_and(|h| h.shape == 1)
    };
    let mut sphere_pixels = 0;
    for y in 1..h - 1 {
        for x in 1..w - 1 {
            // Well inside the red sphere's silhouette: all eight neighbours
            // hit it too.
            let inside = (0..9).all(|k| on_sphere(x + k % 3 - 1, y + k / 3 - 1));
            if !inside {
                continue;
            }
            sphere_pixels += 1;
            let p = 4 * (y * w + x) as usize;
            let (red, green) = (preview.rgba[p], preview.rgba[p + 1]);
            assert!(
                red > green && (i32::from(red) - i32::from(truth[p])).abs() < 40,
                "pixel {x},{y}: {:?} against {:?}",
                &preview.rgba[p..p + 3],
                &truth[p..p + 3]
            );
        }
    }
    assert!(sphere_pixels > 500, "{sphere_pixels}");
}

#[test]
fn a_material_edit_retraces_the_pixels_that_met_it() {
    // The red sphere turns green. Without time, its pixels (and the
    // mirror's, which may see it: not known for seeded points of
    // materials that spawn rays) keep their old colour, marked stale; the
    // background is untouched. With time, the preview is the new picture,
    // byte for byte, though not every pixel was traced again.
    let s = scene(96, DVec3::ZERO);
    let accel = crate::render::Accelerator::of_octree(&s, s.build_octree().unwrap());
    let seed = Renderer::new(&s, &accel, s.render_settings()).unwrap();
    let shown = exact(&s, &s.camera);
    let mut edited = s.clone();
    edited.materials[1].color = DVec3::new(0.1, 0.8, 0.2);
    let r = Renderer::new(&edited, &accel, edited.render_settings()).unwrap();
    let mut cache = RenderCache::default();
    let stale = show(&mut cache, &r, Some((&seed, &shown)), no_time());
    assert!(stale.summary.stale > 0);
    assert!(stale.summary.reprojected > 0, "the background is untouched");
    let mut cache = RenderCache::default();
    let done = show(&mut cache, &r, Some((&seed, &shown)), all_the_time());
    assert_eq!(done.summary.stale, 0);
    // Within two levels of the new picture but for a few pixels at the
    // horizon, where a ray a sixteenth of a pixel off the centre meets
    // the sky instead of the floor.
    let truth = exact(&edited, &edited.camera);
    assert_close_picture(&done.rgba, &truth, 2, 0.015, &format!("{:?}", done.summary));
    // Which the old picture is not: the sphere's pixels changed.
    let changed = (0..truth.len() / 4)
        .filter(|&k| (0..3).any(|c| shown[4 * k + c].abs_diff(truth[4 * k + c]) > 2))
        .count();
    assert!(changed > truth.len() / 4 / 20, "{changed}");
}

#[test]
fn a_traced_point_knows_the_materials_it_met() {
    // After a first preview traces every pixel, a change of the red
    // sphere marks only pixels whose rays met it: most of the floor (its
    // shadow rays and the sky beyond) is kept.
    let s = scene(64, DVec3::ZERO);
    let accel = crate::render::Accelerator::of_octree(&s, s.build_octree().unwrap());
    let r = Renderer::new(&s, &accel, s.render_settings()).unwrap();
    let mut cache = RenderCache::default();
    let first = show(&mut cache, &r, None, all_the_time());
    assert_eq!(first.summary.fresh, first.summary.pixels());
    let mut edited = s.clone();
    edited.materials[1].color = DVec3::new(0.1, 0.8, 0.2);
    let r = Renderer::new(&edited, &accel, edited.render_settings()).unwrap();
    let second = show(&mut cache, &r, None, no_time());
    assert!(second.summary.stale > 0);
    assert!(
        second.summary.reprojected > second.summary.pixels() / 2,
        "{:?}",
        second.summary
    );
    // Traced until nothing is stale, the picture is the edited one.
    let mut last = second;
    for _ in 0..16 {
        if last.summary.stale == 0 {
            break;
        }
        last = show(&mut cache, &r, None, all_the_time());
    }
    assert_eq!(last.summary.stale, 0);
    assert_close_picture(
        &last.rgba,
        &exact(&edited, &edited.camera),
        2,
        0.03,
        &format!("{:?}", last.summary),
    );
}

#[test]
fn a_moved_light_marks_every_lit_surface() {
    let s = scene(64, DVec3::ZERO);
    let accel = crate::render::Accelerator::of_octree(&s, s.build_octree().unwrap());
    let seed = Renderer::new(&s, &accel, s.render_settings()).unwrap();
    let shown = exact(&s, &s.camera);
    let mut moved = s.clone();
    moved.lights[0].position.x += 2.0;
    let r = Renderer::new(&moved, &accel, moved.render_settings()).unwrap();
    let mut cache = RenderCache::default();
    let stale = show(&mut cache, &r, Some((&seed, &shown)), no_time());
    // Every pixel is stale but the sky's.
    let sky = stale
        .sources
        .iter()
        .filter(|s| matches!(s, PixelSource::Reprojected { .. }))
        .count();
    let all_stale = stale
        .sources
        .iter()
        .filter(|s| **s == PixelSource::Stale)
        .count();
    assert!(sky > 0 && all_stale > 0);
    assert_eq!(sky + all_stale, stale.sources.len());
}

#[test]
fn other_geometry_or_settings_start_over() {
    let s = scene(32, DVec3::ZERO);
    let accel = crate::render::Accelerator::of_octree(&s, s.build_octree().unwrap());
    let r = Renderer::new(&s, &accel, s.render_settings()).unwrap();
    let mut cache = RenderCache::default();
    cache.preview(&r, None, all_the_time());
    assert!(cache.can_serve(&r));
    let deeper = RenderSettings {
        max_depth: 2,
        ..s.render_settings()
    };
    let r2 = Renderer::new(&s, &accel, deeper).unwrap();
    assert!(!cache.can_serve(&r2));
    let other = scene(32, DVec3::ZERO);
    let accel2 = crate::render::Accelerator::of_octree(&other, other.build_octree().unwrap());
    let r3 = Renderer::new(&other, &accel2, other.render_settings()).unwrap();
    assert!(!cache.can_serve(&r3), "other geometry");
    // Samples and the accelerator change nothing a preview shows.
    let aa = RenderSettings {
        samples: 16,
        adaptive: true,
        ..s.render_settings()
    };
    assert!(cache.can_serve(&Renderer::new(&s, &accel, aa).unwrap()));
}

#[test]
fn rays_go_to_gaps_first_then_by_class_within_a_turn() {
    // A 4 x 2 image: one turn takes the pixel at lattice place (0, 0) of
    // each 4 x 4 block, here pixel 0 only; the gaps come before it. Each
    // next turn takes the next lattice place.
    let surface = |flags, view_weight| Point {
        flags,
        view_weight,
        material: 0,
        ..Point::NONE
    };
    let points = vec![
        surface(Point::STALE, 0),      // 0
        surface(0, 0),                 // 1
        surface(0, 0),                 // 2
        surface(Point::NOTHING, 0),    // 3: a gap
        surface(Point::NOTHING, 0),    // 4: a gap
        surface(0, 0),                 // 5
        surface(Point::BACKGROUND, 0), // 6: the sky: never
        surface(0, 0),                 // 7
    ];
    let mut scratch = trace::Scratch::default();
    let order = trace::turn_order(&points, &[3, 4], (4, 2), 3, &mut scratch).to_vec();
    assert_eq!(
        order[..2]
            .iter()
            .copied()
            .collect::<std::collections::BTreeSet<_>>(),
        [3, 4].into()
    );
    assert_eq!(&order[2..], &[0]);
    // Asking for more rays takes further turns, within a turn stale, then
    // view-dependent, filled and diffuse points; never the sky.
    let mut scratch = trace::Scratch::default();
    let order = trace::turn_order(&points, &[3, 4], (4, 2), 100, &mut scratch).to_vec();
    let mut rest = order[2..].to_vec();
    rest.sort_unstable();
    assert_eq!(rest, vec![0, 1, 2, 5, 7]);
    assert_eq!(order[2], 0, "stale first");
}

#[test]
fn the_source_view_tells_the_sources_apart() {
    // One traced preview, then one with no time from a turned eye: fresh,
    // reused and filled pixels each get their own hue.
    let s = scene(64, DVec3::ZERO);
    let accel = crate::render::Accelerator::of_octree(&s, s.build_octree().unwrap());
    let r = Renderer::new(&s, &accel, s.render_settings()).unwrap();
    let mut cache = RenderCache::default();
    cache.preview(&r, None, all_the_time());
    let mut colors = Vec::new();
    cache.source_colors(&mut colors);
    let px = |c: &[u8], k: usize| [c[4 * k], c[4 * k + 1], c[4 * k + 2]];
    let fresh = px(&colors, 0);
    assert!(
        fresh[1] > fresh[0] && fresh[1] > fresh[2],
        "fresh: green {fresh:?}"
    );
    let turned_eye =
        Renderer::with_camera(&s, &accel, s.render_settings(), &turned(&s, 8.0)).unwrap();
    cache.preview(&turned_eye, None, no_time());
    cache.source_colors(&mut colors);
    let sources = cache.sources();
    let reused = sources
        .iter()
        .position(|s| matches!(s, PixelSource::Reprojected { .. }))
        .unwrap();
    let c = px(&colors, reused);
    assert!(c[2] > c[0] && c[2] > c[1], "reused: blue {c:?}");
    if let Some(filled) = sources.iter().position(|s| *s == PixelSource::Filled) {
        let c = px(&colors, filled);
        assert!(c[0] > c[1] && c[0] > c[2], "filled: red {c:?}");
    }
}

#[test]
fn shrink_then_enlarge_keeps_flat_colour_and_sizes() {
    // A flat image shrunk by 3 (clipped blocks at the edges) and enlarged
    // back is the same flat image; a two-tone one keeps its halves away
    // from the seam.
    let (w, h) = (10u32, 7u32);
    let flat: Vec<u8> = [40u8, 120, 200, 255].repeat((w * h) as usize);
    let small = shrink(&flat, (w, h), 3);
    assert_eq!(small.len(), 4 * 4 * 3);
    assert!(small.chunks(4).all(|p| p == [40, 120, 200, 255]));
    let mut big = Vec::new();
    enlarge(&small, (4, 3), (w, h), true, &mut big);
    assert_eq!(big, flat);
    let two: Vec<u8> = (0..w * h)
        .flat_map(|i| {
            if i % w < w / 2 {
                [0u8, 0, 0, 255]
            } else {
                [255, 255, 255, 255]
            }
        })
        .collect();
    let mut back = Vec::new();
    enlarge(&shrink(&two, (w, h), 2), (5, 4), (w, h), false, &mut back);
    assert_eq!(&back[..4], &[0, 0, 0, 255]);
    assert_eq!(
        &back[4 * (w as usize - 1)..4 * w as usize],
        &[255, 255, 255, 255]
    );
}
