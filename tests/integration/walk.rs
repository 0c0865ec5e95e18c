//! A ray's walk through the octree, as `--trace-pixel` reports it: checked
//! against what the ray found, against brute force, and against the
//! Havran counts the render itself keeps.

use crate::common;
use glint::settings::Accel;

use glint::accel::{QueryRecord, StepKind, WalkEnd};
use glint::render::Renderer;
use glint::render::ray_tree::{RayNode, ShadowVerdict};
use glint::scene::Scene;
use glint::settings::RenderSettings;
use glint::simd::SimdLevel;
use glint::stats::WorkCounts;

/// Scenes with an infinite plane (the unbounded step), glass (shadow rays
/// that cross surfaces) and a mesh (many leaves).
const SCENES: [&str; 3] = [
    "scenes/glass.toml",
    "scenes/spd/teapot.nff",
    "scenes/cornell_box.toml",
];
const SIZE: (u32, u32) = (24, 18);

fn settings(scene: &Scene, use_octree: bool) -> RenderSettings {
    let mut s = scene.render_settings();
    s.width = SIZE.0;
    s.height = SIZE.1;
    s.samples = 1;
    s.adaptive = false;
    s.accel = Accel::from_octree_switch(use_octree);
    s
}

/// Every query in a tree: each ray's closest-hit query with the ray, and
/// each shadow ray's with its verdict.
fn queries(tree: &RayNode) -> Vec<(&QueryRecord, Option<&RayNode>, Option<ShadowVerdict>)> {
    let mut out = Vec::new();
    for ray in tree.rays() {
        out.push((
            ray.query.as_ref().expect("every ray has a query"),
            Some(ray),
            None,
        ));
        for shadow in &ray.shadows {
            if let Some(q) = &shadow.query {
                out.push((q, None, Some(shadow.verdict)));
            }
        }
    }
    out
}

fn counts(q: &QueryRecord) -> WorkCounts {
    WorkCounts {
        intersection_tests: q.intersection_tests,
        traversal_steps: q.traversal_steps,
        leaves_visited: q.leaves_visited,
    }
}

#[test]
fn walks_go_front_to_back_and_find_what_the_ray_and_brute_force_find() {
    for path in SCENES {
        let scene = common::load(path);
        let octree = std::sync::Arc::new(scene.build_octree().unwrap());
        let accel = crate::common::accelerator(&scene, &settings(&scene, true), Some(&octree));
        let on = Renderer::new(&scene, &accel, settings(&scene, true)).unwrap();
        let accel = crate::common::accelerator(&scene, &settings(&scene, false), Some(&octree));
        let off = Renderer::new(&scene, &accel, settings(&scene, false)).unwrap();
        let (mut leaves, mut empties, mut missed, mut blocked) = (0, 0, 0, 0);
        for j in (0..SIZE.1).step_by(3) {
            for i in (0..SIZE.0).step_by(3) {
                let tree = on.ray_tree(i, j);
                let brute = off.ray_tree(i, j);
                // Brute force finds the same hits, ray for ray.
                let hits = |t: &RayNode| {
                    t.rays()
                        .iter()
                        .map(|r| r.hit.as_ref().map(|h| (h.object, h.distance)))
                        .collect::<Vec<_>>()
                };
                assert_eq!(hits(&tree), hits(&brute), "{path} pixel {i},{j}");
                for (q, _, _) in queries(&brute) {
                    assert!(q.walk.is_none() && q.walk_end.is_none());
                    assert_eq!(q.traversal_steps, 0);
                }
                for (q, ray, verdict) in queries(&tree) {
                    let walk = q.walk.as_ref().expect("the octree is on");
                    let at = format!("{path} pixel {i},{j}");
                    // One step per traversal step, one entry per test.
                    assert_eq!(
                        walk.len() as u64,
                        q.traversal_steps + unbounded(walk),
                        "{at}"
                    );
                    let tested: Vec<_> = walk
                        .iter()
                        .flat_map(|s| s.tested.iter().flatten())
                        .collect();
                    assert_eq!(tested.len() as u64, q.intersection_tests, "{at}");
                    let entered = walk
                        .iter()
                        .filter(|s| {
                            matches!(s.kind, StepKind::Leaf | StepKind::Empty | StepKind::Missed)
                        })
                        .count();
                    assert_eq!(entered as u64, q.leaves_visited, "{at}");
                    // Leaves front to back, those whose box the ray misses
                    // among them; those test nothing.
                    let enters: Vec<f64> = walk
                        .iter()
                        .filter(|s| matches!(s.kind, StepKind::Leaf | StepKind::Missed))
                        .map(|s| s.t_enter.unwrap())
                        .collect();
                    assert!(enters.windows(2).all(|w| w[0] <= w[1]), "{at}: {enters:?}");
                    leaves += enters.len();
                    empties += walk.iter().filter(|s| s.kind == StepKind::Empty).count();
                    for s in walk.iter().filter(|s| s.kind == StepKind::Missed) {
                        assert!(s.tested.as_ref().is_none_or(Vec::is_empty), "{at}");
                        missed += 1;
                    }
                    for s in walk.iter().filter(|s| s.kind != StepKind::Unbounded) {
                        let (min, max) = (s.min.unwrap(), s.max.unwrap());
                        assert!((0..3).all(|k| min[k] < max[k]), "{at}: a cell has a side");
                        assert!(s.t_enter.unwrap() <= s.t_exit.unwrap(), "{at}");
                    }
                    let nearest = tested
                        .iter()
                        .filter_map(|t| t.t.map(|d| (d, t.object)))
                        .min_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
                    match (ray, verdict) {
                        // A ray's hit is the nearest tested hit.
                        (Some(ray), _) => {
                            let hit = ray.hit.as_ref().map(|h| (h.distance, h.object));
                            assert_eq!(nearest, hit, "{at}");
                            if hit.is_some() {
                                assert!(matches!(
                                    q.walk_end,
                                    Some(
                                        WalkEnd::HitInCell
                                            | WalkEnd::CellsBeyondHit
                                            | WalkEnd::LeftOctree
                                            | WalkEnd::MissedOctree
                                    )
                                ));
                            }
                        }
                        // A shadow ray is blocked where it met something
                        // opaque, and the walk says so; lit, it met nothing.
                        (None, Some(ShadowVerdict::Blocked)) => {
                            if !scene_has_glass(&scene) {
                                assert_eq!(q.walk_end, Some(WalkEnd::Blocked), "{at}");
                            }
                            assert!(nearest.is_some(), "{at}");
                            blocked += 1;
                        }
                        (None, Some(ShadowVerdict::Lit)) => {
                            assert!(nearest.is_none(), "{at}: lit but hit {nearest:?}");
                            assert_ne!(q.walk_end, Some(WalkEnd::Blocked));
                        }
                        _ => {}
                    }
                }
            }
        }
        // The checks above ran on real walks.
        assert!(leaves > 50, "{path}: {leaves} leaves");
        if path.ends_with("teapot.nff") {
            assert!(
                empties > 0 && missed > 0 && blocked > 0,
                "{path}: {empties} empty, {missed} missed, {blocked} blocked"
            );
        }
    }
}

fn unbounded(walk: &[glint::accel::WalkStep]) -> u64 {
    walk.iter()
        .filter(|s| s.kind == StepKind::Unbounded)
        .count() as u64
}

fn scene_has_glass(scene: &Scene) -> bool {
    scene.materials.iter().any(|m| m.transparency > 0.0)
}

#[test]
fn the_walks_of_every_pixel_sum_to_the_renders_havran_counts() {
    // Rays one at a time, as the walks are taken, count exactly the same.
    // Packets of eye rays (SIMD lanes, where the machine has them) keep
    // their own accounts: a lane is counted in every cell the packet
    // enters while its own interval there is open, and the lanes share
    // one mailbox, whose evictions depend on the other rays. They agree
    // within that slack.
    let levels = SimdLevel::ALL.iter().copied().filter(|l| l.is_available());
    for level in levels {
        for path in SCENES {
            let scene = common::load(path);
            let octree = std::sync::Arc::new(scene.build_octree().unwrap());
            for use_octree in [true, false] {
                let accel = crate::common::accelerator(
                    &scene,
                    &settings(&scene, use_octree),
                    Some(&octree),
                );
                let renderer = Renderer::new(&scene, &accel, settings(&scene, use_octree))
                    .unwrap()
                    .with_simd(level);
                let (_, rendered) = renderer.render(true, None);
                let mut summed = WorkCounts::default();
                for j in 0..SIZE.1 {
                    for i in 0..SIZE.0 {
                        for (q, _, _) in queries(&renderer.ray_tree(i, j)) {
                            summed += counts(q);
                        }
                    }
                }
                let at = format!("{path}, octree {use_octree}, {level:?}");
                if level == SimdLevel::Scalar || !use_octree {
                    assert_eq!(summed, rendered.work, "{at}");
                } else {
                    // Packets: within 10% (measured: docs/inspection.md, "A ray's walk").
                    for (what, walked, counted) in [
                        (
                            "steps",
                            summed.traversal_steps,
                            rendered.work.traversal_steps,
                        ),
                        (
                            "leaves",
                            summed.leaves_visited,
                            rendered.work.leaves_visited,
                        ),
                        (
                            "tests",
                            summed.intersection_tests,
                            rendered.work.intersection_tests,
                        ),
                    ] {
                        let ratio = walked as f64 / counted as f64;
                        eprintln!("{at}: {what} walked/counted {ratio:.4}");
                        assert!(
                            (ratio - 1.0).abs() <= 0.1,
                            "{at}: {what} {walked} vs {counted}"
                        );
                    }
                }
            }
        }
    }
}
