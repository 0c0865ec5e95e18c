//! The BVH's tests: its layout, and its answers against brute force.

use super::BvhStack;
use super::tree::Bvh;
use crate::accel::{
    Primitives, ShadowCrossings, closest_brute_force, occlusion_brute_force, sphere_grid,
};
use crate::math::Aabb;
use crate::math::{DVec3, Ray};
use crate::shapes::{Plane, PreparedRay, Shape, Sphere};
use crate::stats::{NoCounts, WorkCounts};

/// Shape indices under `index`, and checks on the way that every node's
/// box holds its children's and every leaf's box its shapes'.
fn shapes_below(bvh: &Bvh, shapes: &[Shape], index: usize, depth: u32) -> Vec<u32> {
    let node = bvh.nodes[index];
    assert!(depth <= bvh.stats.max_depth);
    let inside = |b: Aabb| b.min.cmpge(node.bounds.min).all() && b.max.cmple(node.bounds.max).all();
    if node.count > 0 {
        let start = node.first_or_second as usize;
        let refs = bvh.refs[start..start + node.count as usize].to_vec();
        for &r in &refs {
            let b = shapes[r as usize].bounds().unwrap();
            assert!(inside(b), "leaf {index} does not hold shape {r}");
        }
        return refs;
    }
    let (first, second) = (index + 1, node.first_or_second as usize);
    assert!(
        second > first,
        "the second child follows the first's subtree"
    );
    for child in [first, second] {
        assert!(
            inside(bvh.nodes[child].bounds),
            "node {index} does not hold {child}"
        );
    }
    let mut below = shapes_below(bvh, shapes, first, depth + 1);
    below.extend(shapes_below(bvh, shapes, second, depth + 1));
    below
}

#[test]
fn every_bounded_shape_is_referenced_once_inside_every_box_above_it() {
    let mut shapes = sphere_grid(12, 0.3);
    shapes.push(Shape::Plane(Plane::new(-DVec3::Y, DVec3::Y)));
    let bvh = Bvh::build(&shapes);
    assert_eq!(bvh.unbounded, [1728], "the plane is tested for every ray");
    let mut below = shapes_below(&bvh, &shapes, 0, 0);
    below.sort_unstable();
    assert_eq!(below, (0..1728).collect::<Vec<u32>>());
    let stats = bvh.stats();
    assert_eq!(stats.references, 1728);
    assert_eq!(stats.nodes, 2 * stats.leaves - 1, "a binary tree");
    assert!(stats.max_depth <= 20, "depth {}", stats.max_depth);
}

#[test]
fn geometrically_spaced_shapes_still_get_a_shallow_tree() {
    // Each split by the heuristic would peel one sphere off the rest.
    let shapes: Vec<Shape> = (0..3000)
        .map(|k| Shape::Sphere(Sphere::new(DVec3::X * 0.99f64.powi(k), 1e-6)))
        .collect();
    let bvh = Bvh::build(&shapes);
    let depth = bvh.stats().max_depth;
    assert!(depth <= 48 + 14, "depth {depth}");
    assert_eq!(shapes_below(&bvh, &shapes, 0, 0).len(), 3000);
}

#[test]
fn the_tree_is_the_same_on_any_number_of_threads() {
    let shapes = sphere_grid(18, 0.45);
    let build = |threads| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| Bvh::build(&shapes))
    };
    let (one, four) = (build(1), build(4));
    assert_eq!(one.refs, four.refs);
    assert_eq!(one.stats(), four.stats());
    let boxes = |b: &Bvh| b.nodes.iter().map(|n| n.bounds).collect::<Vec<_>>();
    assert_eq!(boxes(&one), boxes(&four));
}

#[test]
fn rays_along_axes_and_through_shared_boundaries_agree_with_brute_force() {
    // Overlapping spheres touching each other's boxes; rays in the planes
    // through their centres, with zero direction components, and counted
    // and uncounted.
    let shapes = sphere_grid(4, 0.6);
    let bvh = Bvh::build(&shapes);
    assert!(bvh.has_wide(), "uncounted queries take the wide walk");
    let prims = Primitives::opaque(&shapes);
    let mut rays = Vec::new();
    for a in [0.0, 1.0, 1.5, 2.0, 0.2, 3.6] {
        for b in [0.0, 1.0, 2.5, 3.0, -0.6] {
            rays.push(Ray::new(DVec3::new(-5.0, a, b), DVec3::X));
            rays.push(Ray::new(DVec3::new(a, 9.0, b), -DVec3::Y));
            rays.push(Ray::new(DVec3::new(a, b, -5.0), DVec3::Z));
            rays.push(Ray::new(
                DVec3::new(-5.0, -5.0 + a, b),
                DVec3::new(1.0, 1.0, 0.0).normalize(),
            ));
        }
    }
    let mut stack = BvhStack::default();
    let (mut a, mut b) = (ShadowCrossings::default(), ShadowCrossings::default());
    let mut hits = 0;
    for ray in rays {
        let ray = PreparedRay::new(ray);
        let brute = closest_brute_force(&prims, &ray, f64::INFINITY, &mut NoCounts);
        let found = bvh.closest(&prims, &ray, f64::INFINITY, &mut stack, &mut NoCounts);
        assert_eq!(found, brute, "{:?}", ray.ray);
        let mut counts = WorkCounts::default();
        let counted = bvh.closest(&prims, &ray, f64::INFINITY, &mut stack, &mut counts);
        assert_eq!(counted, brute, "{:?}", ray.ray);
        assert!(counts.intersection_tests <= shapes.len() as u64);
        hits += found.is_some() as usize;
        occlusion_brute_force(&prims, &ray, 20.0, &mut b, &mut NoCounts);
        bvh.occlusion(&prims, &ray, 20.0, &mut a, &mut stack, &mut NoCounts);
        assert_eq!(a, b, "{:?}", ray.ray);
        let mut counts = WorkCounts::default();
        bvh.occlusion(&prims, &ray, 20.0, &mut a, &mut stack, &mut counts);
        assert_eq!(a, b, "{:?} (counted)", ray.ray);
    }
    assert!(hits > 40, "the rays meet the grid ({hits} hits)");
}

#[test]
fn a_scene_without_bounded_shapes_has_an_empty_tree_that_answers() {
    let shapes = vec![Shape::Plane(Plane::new(DVec3::ZERO, DVec3::Y))];
    let bvh = Bvh::build(&shapes);
    assert_eq!(bvh.stats().nodes, 0);
    let prims = Primitives::opaque(&shapes);
    let ray = PreparedRay::new(Ray::new(DVec3::Y, -DVec3::Y));
    let hit = bvh.closest(
        &prims,
        &ray,
        f64::INFINITY,
        &mut BvhStack::default(),
        &mut NoCounts,
    );
    assert_eq!(hit.map(|h| h.shape), Some(0));
    assert!(
        Bvh::build(&[])
            .closest(&prims, &ray, 1.0, &mut BvhStack::default(), &mut NoCounts)
            .is_none()
    );
}
