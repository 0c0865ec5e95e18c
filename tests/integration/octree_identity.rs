//! The octree and the BVH answer exactly what brute force answers: images
//! are byte-identical, and random rays agree on the closest hit and on
//! shadows.

use crate::common;
use glint::settings::Accel;

use common::{all_scenes, render_with};
use glint::accel::{
    Bvh, BvhStack, Octree, OctreeParams, Primitives, ShadowCrossings, closest_brute_force,
    occlusion_brute_force,
};
use glint::math::{DVec3, Ray};
use glint::render::Renderer;
use glint::settings::RenderSettings;
use glint::shapes::{PreparedRay, Shape, Sphere, Triangle};
use glint::stats::{NoCounts, WorkCounts};
use proptest::prelude::*;

#[test]
fn octree_on_and_off_and_the_bvh_give_identical_bytes_for_every_scene() {
    for name in all_scenes() {
        let loaded = common::loaded(&name);
        let (scene, octree) = (&loaded.0, &loaded.1);
        // Brute force over tens of thousands of shapes is slow: keep the
        // biggest scenes small.
        let side = if scene.shapes.len() > 20_000 { 12 } else { 40 };
        let (on, c_on) = render_with(scene, octree, side, side, |s| {
            s.samples = 1;
            s.accel = Accel::Octree;
        });
        let (off, c_off) = render_with(scene, octree, side, side, |s| {
            s.samples = 1;
            s.accel = Accel::BruteForce;
        });
        let differing = on
            .chunks_exact(3)
            .zip(off.chunks_exact(3))
            .filter(|(a, b)| a != b)
            .count();
        assert_eq!(
            differing, 0,
            "{name}: {differing} pixels differ between octree on and off"
        );
        assert_eq!(c_on.rays, c_off.rays, "{name}: different rays were cast");
        let mut settings = scene.render_settings();
        (settings.width, settings.height, settings.samples) = (side, side, 1);
        settings.accel = glint::settings::Accel::Bvh;
        let accel = crate::common::accelerator(scene, &settings, Some(octree));
        let renderer = Renderer::new(scene, &accel, settings).unwrap();
        // Uncounted: single rays through the BVH's wide walk; counted:
        // through its binary walk.
        let (frame, _) = renderer.render(false, None);
        assert!(
            frame.to_rgb8() == on,
            "{name}: the BVH's image differs from the octree's"
        );
        let (frame, c_bvh) = renderer.render(true, None);
        assert!(
            frame.to_rgb8() == on,
            "{name}: the BVH's image (counted) differs from the octree's"
        );
        // With 16 samples a pixel's rays go as packets through the octree,
        // one by one through the BVH.
        let full = RenderSettings {
            samples: 16,
            ..settings
        };
        let through = |settings: RenderSettings| {
            let accel = crate::common::accelerator(scene, &settings, Some(octree));
            let renderer = Renderer::new(scene, &accel, settings).unwrap();
            renderer.render(false, None).0.to_rgb8()
        };
        let mut octree_full = full;
        octree_full.accel = glint::settings::Accel::Octree;
        assert!(
            through(full) == through(octree_full),
            "{name}: 16 samples through the BVH differ from the octree's packets"
        );
        assert_eq!(c_on.rays, c_bvh.rays, "{name}: different rays were cast");
        let brute_force_tests = scene.shapes.len() as u64 * c_bvh.rays.total();
        assert!(
            c_bvh.work.traversal_steps > 0 && c_bvh.work.leaves_visited > 0,
            "{name}: nothing went through the BVH"
        );
        assert!(
            (1..=brute_force_tests).contains(&c_bvh.work.intersection_tests),
            "{name}: the BVH counted {} tests, brute force would make {brute_force_tests}",
            c_bvh.work.intersection_tests
        );
    }
}

/// Shapes for the property tests: small random triangles and spheres in
/// the box [-4, 4]^3, some of them on the octree's split planes.
fn shapes_strategy() -> impl Strategy<Value = Vec<Shape>> {
    shapes_at(1.0, DVec3::ZERO)
}

/// [`shapes_strategy`]'s shapes scaled by `scale` and moved by `offset`.
fn shapes_at(scale: f64, offset: DVec3) -> impl Strategy<Value = Vec<Shape>> {
    let coord = prop_oneof![4 => -4.0..4.0f64, 1 => Just(0.0), 1 => Just(2.0), 1 => Just(-2.0)];
    let point = (coord.clone(), coord.clone(), coord.clone())
        .prop_map(move |(x, y, z)| DVec3::new(x, y, z) * scale + offset);
    let offset = (-1.0..1.0f64, -1.0..1.0f64, -1.0..1.0f64)
        .prop_map(move |(x, y, z)| DVec3::new(x, y, z) * scale);
    let triangle = (point.clone(), offset.clone(), offset)
        .prop_filter_map("degenerate", |(a, b, c)| {
            Triangle::new([a, a + b, a + c]).map(Shape::Triangle)
        });
    let sphere =
        (point, 0.05..0.8f64).prop_map(move |(c, r)| Shape::Sphere(Sphere::new(c, r * scale)));
    prop::collection::vec(prop_oneof![triangle, sphere], 1..60)
}

fn ray_strategy() -> impl Strategy<Value = Ray> {
    let comp = prop_oneof![6 => -1.0..1.0f64, 1 => Just(0.0), 1 => Just(-0.0)];
    let origin_coord = prop_oneof![4 => -6.0..6.0f64, 1 => Just(0.0), 1 => Just(2.0)];
    (
        (origin_coord.clone(), origin_coord.clone(), origin_coord),
        (comp.clone(), comp.clone(), comp),
    )
        .prop_filter_map("zero direction", |((ox, oy, oz), (dx, dy, dz))| {
            let d = DVec3::new(dx, dy, dz);
            (d.length() > 1e-3).then(|| Ray::new(DVec3::new(ox, oy, oz), d.normalize()))
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 400, ..ProptestConfig::default() })]

    #[test]
    fn closest_hit_and_shadows_match_brute_force(
        shapes in shapes_strategy(),
        rays in prop::collection::vec(ray_strategy(), 40),
        max_depth in 0u32..7,
        leaf_size in 1u32..6,
        transparent_mask in any::<u64>(),
        one_sided_mask in any::<u64>(),
        shadow_length in 0.5..20.0f64,
    ) {
        let params = OctreeParams { max_depth, leaf_size, cost_driven: max_depth % 2 == 0, ..Default::default() };
        let octree = std::sync::Arc::new(Octree::build(&shapes, params).unwrap());
        let bvh = Bvh::build(&shapes);
        let is_transparent: Vec<bool> = (0..shapes.len()).map(|i| transparent_mask >> (i % 64) & 1 == 1).collect();
        // Some shapes one-sided (the SPD protocol's opaque surfaces).
        let one_sided: Vec<bool> = (0..shapes.len()).map(|i| one_sided_mask >> (i % 64) & 1 == 1).collect();
        let prims = Primitives { one_sided: &one_sided, transparent: &is_transparent, ..Primitives::opaque(&shapes) };
        for ray in rays {
            agree(&octree, &bvh, &prims, ray, shadow_length)?;
        }
    }

    /// The same at the extremes: scenes a millionth and a million times
    /// the size, ten million units from the origin, and rays that start on
    /// a shape's surface (as shadow and secondary rays do) or graze it.
    #[test]
    fn closest_hit_and_shadows_match_brute_force_at_the_extremes(
        (shapes, scale, offset) in (
            prop_oneof![Just(1e-6), Just(1.0), Just(1e6)],
            prop_oneof![Just(0.0), Just(1e7)],
        ).prop_flat_map(|(scale, offset)| {
            (shapes_at(scale, DVec3::splat(offset)), Just(scale), Just(offset))
        }),
        rays in prop::collection::vec((ray_strategy(), 0usize..64, 0.0..1.0f64, 0.0..1.0f64), 40),
        leaf_size in 1u32..6,
        transparent_mask in any::<u64>(),
    ) {
        let octree = std::sync::Arc::new(Octree::build(&shapes, OctreeParams { leaf_size, ..Default::default() }).unwrap());
        let bvh = Bvh::build(&shapes);
        let is_transparent: Vec<bool> = (0..shapes.len()).map(|i| transparent_mask >> (i % 64) & 1 == 1).collect();
        let prims = Primitives { transparent: &is_transparent, ..Primitives::opaque(&shapes) };
        for (ray, on, u, v) in rays {
            let origin = ray.origin * scale + DVec3::splat(offset);
            let ray = match &shapes[on % shapes.len()] {
                // Every other ray starts on a triangle, inside or on an edge.
                Shape::Triangle(t) if on % 2 == 0 => {
                    let [a, b, c] = t.vertices;
                    let (u, v) = if u + v > 1.0 { (1.0 - u, 1.0 - v) } else { (u, v) };
                    Ray::new(a + (b - a) * u + (c - a) * v, ray.dir)
                }
                _ => Ray::new(origin, ray.dir),
            };
            agree(&octree, &bvh, &prims, ray, 20.0 * scale)?;
        }
    }
}

/// The octree's closest hit and shadow verdict for `ray`, by the walk that
/// counts nothing (the wide walk) and by the one that counts (the exact
/// walk Havran's measures come from), and the BVH's, equal brute force's.
fn agree(
    octree: &std::sync::Arc<Octree>,
    bvh: &Bvh,
    prims: &Primitives,
    ray: Ray,
    shadow_length: f64,
) -> Result<(), TestCaseError> {
    let prepared = PreparedRay::new(ray);
    let mut stack = glint::accel::WalkStack::default();
    let brute = closest_brute_force(prims, &prepared, f64::INFINITY, &mut NoCounts);
    let wide = octree.closest(prims, &prepared, f64::INFINITY, &mut stack, &mut NoCounts);
    prop_assert_eq!(brute, wide, "closest hit differs for {:?}", ray);
    let exact = octree.closest(
        prims,
        &prepared,
        f64::INFINITY,
        &mut stack,
        &mut WorkCounts::default(),
    );
    prop_assert_eq!(brute, exact, "closest hit (counted) differs for {:?}", ray);
    let mut b = ShadowCrossings::default();
    occlusion_brute_force(prims, &prepared, shadow_length, &mut b, &mut NoCounts);
    // Left over from another ray: cleared by the query.
    let mut t = b.clone();
    octree.occlusion(
        prims,
        &prepared,
        shadow_length,
        &mut t,
        &mut stack,
        &mut NoCounts,
    );
    prop_assert_eq!(&b, &t, "shadow verdict differs for {:?}", ray);
    octree.occlusion(
        prims,
        &prepared,
        shadow_length,
        &mut t,
        &mut stack,
        &mut WorkCounts::default(),
    );
    prop_assert_eq!(&b, &t, "shadow verdict (counted) differs for {:?}", ray);
    // The BVH: its wide walk (nothing counted) and its binary one.
    let mut bvh_stack = BvhStack::default();
    let found = bvh.closest(
        prims,
        &prepared,
        f64::INFINITY,
        &mut bvh_stack,
        &mut NoCounts,
    );
    prop_assert_eq!(brute, found, "the BVH's closest hit differs for {:?}", ray);
    let counted = bvh.closest(
        prims,
        &prepared,
        f64::INFINITY,
        &mut bvh_stack,
        &mut WorkCounts::default(),
    );
    prop_assert_eq!(
        brute,
        counted,
        "the BVH's closest hit (counted) differs for {:?}",
        ray
    );
    bvh.occlusion(
        prims,
        &prepared,
        shadow_length,
        &mut t,
        &mut bvh_stack,
        &mut NoCounts,
    );
    prop_assert_eq!(&b, &t, "the BVH's shadow verdict differs for {:?}", ray);
    bvh.occlusion(
        prims,
        &prepared,
        shadow_length,
        &mut t,
        &mut bvh_stack,
        &mut WorkCounts::default(),
    );
    prop_assert_eq!(
        &b,
        &t,
        "the BVH's shadow verdict (counted) differs for {:?}",
        ray
    );
    Ok(())
}
