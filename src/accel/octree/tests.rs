//! The octree's tests: its layout, its build, and its walk against brute force.

use super::node::{Cell, INTERIOR, Node};
use super::*;
use crate::accel::{Primitives, sphere_grid};
use crate::accel::{ShadowCrossings, closest_brute_force, occlusion_brute_force};
use crate::math::DVec3;
use crate::math::Ray;
use crate::shapes::{Plane, PreparedRay, Shape, Sphere};
use crate::stats::NoCounts;

/// Every stored leaf: its cell and its references.
fn leaves(tree: &Octree) -> Vec<(Cell, Vec<u32>)> {
    fn walk(tree: &Octree, index: usize, cell: Cell, out: &mut Vec<(Cell, Vec<u32>)>) {
        let node = tree.nodes[index];
        if node.is_leaf() {
            let first = node.first as usize;
            out.push((
                cell,
                tree.refs[first..first + node.count() as usize].to_vec(),
            ));
            return;
        }
        for c in 0..8 {
            if node.mask() >> c & 1 == 1 {
                walk(tree, node.child(c) as usize, cell.child(c), out);
            }
        }
    }
    let mut out = Vec::new();
    if !tree.nodes.is_empty() {
        walk(tree, 0, tree.root_cell(), &mut out);
    }
    out
}

/// The tree's closest hit along `ray`, checked against brute force.
fn closest_as_brute_force(
    tree: &Octree,
    prims: &Primitives,
    ray: &PreparedRay,
) -> Option<crate::accel::ClosestHit> {
    let octree = tree.closest(
        prims,
        ray,
        f64::INFINITY,
        &mut super::WalkStack::default(),
        &mut NoCounts,
    );
    let brute = closest_brute_force(prims, ray, f64::INFINITY, &mut NoCounts);
    assert_eq!(octree, brute, "{:?}", ray.ray);
    octree
}

#[test]
fn an_interior_node_finds_its_children_by_counting_octants_below() {
    // Octants 0, 2, 5 and 7 hold something, stored from node 10 on.
    let node = Node {
        first: 10,
        meta: INTERIOR | 0b1010_0101,
    };
    assert!(!node.is_leaf());
    let children: Vec<u32> = [0, 2, 5, 7].map(|c| node.child(c)).to_vec();
    assert_eq!(children, [10, 11, 12, 13]);
}

#[test]
fn child_cells_tile_their_parent_exactly() {
    let parent = Cell {
        min: DVec3::new(-1.5, 0.25, 3.0),
        side: 0.75,
    };
    let mut volume = 0.0;
    for c in 0..8 {
        let child = parent.child(c);
        assert_eq!(child.side, 0.375);
        for k in 0..3 {
            let lower = parent.min[k];
            let expected = if c >> k & 1 == 1 {
                parent.mid()[k]
            } else {
                lower
            };
            assert_eq!(child.min[k], expected, "octant {c}, axis {k}");
        }
        volume += child.side.powi(3);
    }
    assert_eq!(volume, parent.side.powi(3));
}

#[test]
fn every_shape_is_in_the_leaf_around_its_centre_and_only_in_leaves_it_overlaps() {
    let mut shapes = sphere_grid(6, 0.3);
    shapes.push(Shape::Plane(Plane::new(DVec3::ZERO, DVec3::Y)));
    let tree = Octree::build(&shapes, OctreeParams::default()).unwrap();
    assert_eq!(tree.unbounded, [216], "the plane is tested for every ray");
    let leaves = leaves(&tree);
    assert!(
        leaves.len() > 8,
        "the grid was split ({} leaves)",
        leaves.len()
    );
    for (cell, refs) in &leaves {
        for &r in refs {
            let bounds = shapes[r as usize].bounds().unwrap();
            assert!(
                cell.aabb().padded(1e-9).overlaps(&bounds),
                "shape {r} referenced by a leaf it does not touch"
            );
        }
    }
    for (index, shape) in shapes.iter().enumerate().take(216) {
        let centre = shape.bounds().unwrap().center();
        let around = leaves
            .iter()
            .filter(|(cell, _)| cell.aabb().contains(centre))
            .collect::<Vec<_>>();
        assert!(
            !around.is_empty(),
            "shape {index}: no leaf holds its centre"
        );
        for (_, refs) in around {
            assert!(refs.contains(&(index as u32)), "shape {index} missing");
        }
    }
    let stats = tree.stats();
    let stored: u64 = leaves.iter().map(|(_, r)| r.len() as u64).sum();
    assert_eq!(stats.references, stored);
    // Every interior node has eight children, stored or not.
    assert_eq!(stats.nodes, 1 + 8 * (stats.nodes - stats.leaves));
}

#[test]
fn a_budget_too_small_for_any_split_keeps_one_leaf_that_answers_alike() {
    let shapes = sphere_grid(4, 0.3);
    let params = OctreeParams {
        memory_budget_mib: 0,
        ..OctreeParams::default()
    };
    let tree = Octree::build(&shapes, params).unwrap();
    let stats = tree.stats();
    assert_eq!(stats.nodes, 1);
    assert_eq!(stats.leaves_stopped_by_budget, 1);
    let prims = Primitives::opaque(&shapes);
    for k in 0..16 {
        let ray = PreparedRay::new(Ray::new(
            DVec3::new(-2.0, k as f64 * 0.2, 1.1),
            DVec3::new(1.0, 0.05, 0.02).normalize(),
        ));
        assert_eq!(
            tree.closest(
                &prims,
                &ray,
                f64::INFINITY,
                &mut super::WalkStack::default(),
                &mut NoCounts
            ),
            closest_brute_force(&prims, &ray, f64::INFINITY, &mut NoCounts)
        );
    }
}

#[test]
fn rays_in_split_planes_parallel_to_axes_and_through_corners_agree_with_brute_force() {
    // Spheres that reach across the split planes. Rays lying in those
    // planes, with zero direction components, are traversal's
    // degenerate case (Revelles et al. 2000).
    let shapes = sphere_grid(4, 0.6);
    let tree = Octree::build(&shapes, OctreeParams::default()).unwrap();
    let prims = Primitives::opaque(&shapes);
    let root = tree.root_cell();
    let plane = |quarters: f64| root.min.x + root.side * quarters / 4.0;
    let mut rays = Vec::new();
    for a in [plane(2.0), plane(1.0), plane(3.0), 1.0, 0.2] {
        for b in [plane(2.0), plane(1.0), plane(3.0), 2.0, 0.0] {
            rays.push(Ray::new(DVec3::new(-5.0, a, b), DVec3::X));
            rays.push(Ray::new(DVec3::new(a, 9.0, b), -DVec3::Y));
            rays.push(Ray::new(DVec3::new(a, b, -5.0), DVec3::Z));
            rays.push(Ray::new(
                DVec3::new(-5.0, -5.0 + a, b),
                DVec3::new(1.0, 1.0, 0.0).normalize(),
            ));
        }
    }
    let mut hits = 0;
    let (mut a, mut b) = (ShadowCrossings::default(), ShadowCrossings::default());
    for ray in rays {
        let ray = PreparedRay::new(ray);
        let octree = closest_as_brute_force(&tree, &prims, &ray);
        hits += octree.is_some() as usize;
        tree.occlusion(
            &prims,
            &ray,
            20.0,
            &mut a,
            &mut super::WalkStack::default(),
            &mut NoCounts,
        );
        occlusion_brute_force(&prims, &ray, 20.0, &mut b, &mut NoCounts);
        assert_eq!(a, b, "{:?}", ray.ray);
    }
    assert!(hits > 40, "the rays meet the grid ({hits} hits)");
    // Rays through the centre of a root (a corner of all eight children)
    // and along its mid-planes, in all eight direction-sign combinations,
    // over spheres centred on those planes.
    {
        // A grid of small spheres centred on the split planes of a [-4, 4]^3 root.
        let mut shapes = Vec::new();
        for i in -4..=4 {
            for j in -4..=4 {
                shapes.push(Shape::Sphere(Sphere::new(
                    DVec3::new(i as f64, j as f64, 0.0),
                    0.2,
                )));
                shapes.push(Shape::Sphere(Sphere::new(
                    DVec3::new(i as f64, 0.0, j as f64),
                    0.2,
                )));
            }
        }
        let octree = Octree::build(
            &shapes,
            OctreeParams {
                max_depth: 6,
                leaf_size: 1,
                ..Default::default()
            },
        )
        .unwrap();
        let mut checked = 0;
        for sx in [-1.0, 1.0] {
            for sy in [-1.0, 1.0] {
                for sz in [-1.0, 1.0] {
                    for (origin, dir) in [
                        // Through the root's centre, a corner of all eight children.
                        (
                            DVec3::new(-6.0 * sx, -6.0 * sy, -6.0 * sz),
                            DVec3::new(sx, sy, sz),
                        ),
                        // In the plane z = 0, along x.
                        (
                            DVec3::new(-6.0 * sx, 0.0, 0.0),
                            DVec3::new(sx, 0.0, 0.0 * sz),
                        ),
                        // In the plane y = 0, diagonal in x and z.
                        (
                            DVec3::new(-6.0 * sx, 0.0, -6.0 * sz),
                            DVec3::new(sx, 0.0 * sy, sz),
                        ),
                    ] {
                        let ray = PreparedRay::new(Ray::new(origin, dir.normalize()));
                        let prims = Primitives::opaque(&shapes);
                        let brute = closest_brute_force(&prims, &ray, f64::INFINITY, &mut NoCounts);
                        let tree = octree.closest(
                            &prims,
                            &ray,
                            f64::INFINITY,
                            &mut super::WalkStack::default(),
                            &mut NoCounts,
                        );
                        assert_eq!(brute, tree, "origin {origin}, direction {dir}");
                        assert!(brute.is_some(), "these rays all hit a sphere");
                        checked += 1;
                    }
                }
            }
        }
        assert_eq!(checked, 24);
    }
}

#[test]
fn predicted_cost_is_what_random_lines_through_the_root_meet() {
    // Isotropic random lines (Crofton's measure) that cross the root must
    // enter, on average, the predicted cells, and test the predicted
    // references: those of the leaves whose box of what they hold the line
    // meets. The prediction leaves out rays stopping at a hit, so the
    // lines are shadow rays through shapes that all let light through;
    // the spheres sit well inside their leaves' cells (planes of a cube
    // 5.1 across never come within their radius of a grid point down to
    // depth 3), so the mailbox saves no test either.
    let shapes = sphere_grid(6, 0.05);
    let transparent = vec![true; shapes.len()];
    let prims = Primitives {
        transparent: &transparent,
        ..Primitives::opaque(&shapes)
    };
    for leaf_size in [1, 4] {
        let params = OctreeParams {
            leaf_size,
            max_depth: 3,
            ..OctreeParams::default()
        };
        let tree = Octree::build(&shapes, params).unwrap();
        let predicted = tree.predicted_cost();
        let (mut counts, mut crossing) = (crate::stats::WorkCounts::default(), 0u32);
        let mut stack = WalkStack::default();
        let mut found = crate::accel::ShadowCrossings::default();
        for ray in crate::render::random_lines(tree.bounds(), 200_000) {
            let mut one = crate::stats::WorkCounts::default();
            tree.occlusion(
                &prims,
                &PreparedRay::new(ray),
                f64::INFINITY,
                &mut found,
                &mut stack,
                &mut one,
            );
            if one.traversal_steps > 0 {
                crossing += 1;
                counts += one;
            }
        }
        assert!(crossing > 20_000, "{crossing} lines crossed the root");
        let per_ray = |x: u64| x as f64 / crossing as f64;
        let steps = per_ray(counts.traversal_steps);
        let tests = per_ray(counts.intersection_tests);
        let ratio_steps = steps / predicted.traversal_steps_per_ray;
        let ratio_tests = tests / predicted.intersection_tests_per_ray;
        assert!(
            (ratio_steps - 1.0).abs() < 0.03 && (ratio_tests - 1.0).abs() < 0.05,
            "leaf size {leaf_size}: steps {steps} vs {:?}, tests {tests}",
            predicted
        );
    }
    // One leaf: one step, every shape tested.
    let one = Octree::build(
        &shapes,
        OctreeParams {
            max_depth: 0,
            ..OctreeParams::default()
        },
    )
    .unwrap()
    .predicted_cost();
    assert_eq!(one.traversal_steps_per_ray, 1.0);
    assert_eq!(one.intersection_tests_per_ray, shapes.len() as f64);
}

#[test]
fn a_build_refuses_parameters_past_the_limits() {
    let shapes = sphere_grid(2, 0.1);
    let deepest = crate::limits::MAX_OCTREE_DEPTH;
    let at = |max_depth| OctreeParams {
        max_depth,
        ..OctreeParams::default()
    };
    assert!(Octree::build(&shapes, at(deepest)).is_ok());
    // Past it, the walk's level indices would wrap: an error, not a tree.
    assert_eq!(
        Octree::build(&shapes, at(deepest + 1)).err(),
        Some(OctreeError::Limit(crate::limits::LimitError::OctreeDepth(
            deepest + 1
        )))
    );
}

#[test]
fn a_small_model_far_from_the_origin_gets_the_tree_it_gets_at_the_origin() {
    // Small triangles 4 mm apart, as a scan in survey coordinates: 5e6 m
    // out, a padding relative to the coordinates (5 mm) dwarfed the deep
    // cells and every triangle was referenced by hundreds of them.
    let model = |offset: f64| -> Vec<Shape> {
        let mut shapes = Vec::new();
        for i in 0..20 {
            for j in 0..20 {
                let a = DVec3::new(i as f64, j as f64, (i * j % 7) as f64) * 4e-3
                    + DVec3::splat(offset);
                let (b, c) = (
                    a + DVec3::new(3e-3, 0.0, 1e-3),
                    a + DVec3::new(0.0, 3e-3, 2e-3),
                );
                if let Some(t) = crate::shapes::Triangle::new([a, b, c]) {
                    shapes.push(Shape::Triangle(t));
                }
            }
        }
        shapes
    };
    let near = Octree::build(&model(0.0), OctreeParams::default())
        .unwrap()
        .stats();
    let far = Octree::build(&model(5e6), OctreeParams::default())
        .unwrap()
        .stats();
    assert!(
        far.references <= 2 * near.references,
        "{} references far out against {} at the origin",
        far.references,
        near.references
    );
    assert_eq!(far.leaves_stopped_by_budget, 0);
}

/// `count` triangles around `centre` in a tilted plane, a unit away.
fn vertex_fan(centre: DVec3, count: usize) -> Vec<Shape> {
    let (u, v) = (DVec3::new(1.0, 0.2, 0.1), DVec3::new(-0.1, 0.3, 1.0));
    let rim = |k: usize| {
        let a = std::f64::consts::TAU * k as f64 / count as f64;
        centre + a.cos() * u + a.sin() * v
    };
    (0..count)
        .filter_map(|k| crate::shapes::Triangle::new([centre, rim(k), rim(k + 1)]))
        .map(Shape::Triangle)
        .collect()
}

#[test]
fn a_vertex_fan_stays_a_leaf_and_a_larger_fan_splits_as_before() {
    // Two fans of six triangles, as around a mesh vertex: once the fans
    // are apart, the cell around each vertex holds all six, and every child
    // holding the vertex would again.
    let centres = [DVec3::new(0.31, 0.17, 0.05), DVec3::new(4.13, 2.71, 1.09)];
    let shapes: Vec<Shape> = centres.iter().flat_map(|&c| vertex_fan(c, 6)).collect();
    // Without the cost-driven stop, which could stop these small trees too.
    let params = OctreeParams {
        cost_driven: false,
        ..OctreeParams::default()
    };
    let tree = Octree::build(&shapes, params).unwrap();
    for (cell, refs) in leaves(&tree) {
        assert!(refs.len() <= 6, "a leaf of {} references", refs.len());
        assert!(
            cell.side > tree.root_cell().side / 64.0,
            "a leaf at side {}",
            cell.side
        );
    }
    assert!(
        tree.stats().max_depth < 6,
        "depth {}",
        tree.stats().max_depth
    );
    // A polygon of 40 triangles cut into a fan (more than `MAX_FAN`): the
    // cells around it take its triangles apart, down to the maximum depth
    // at the centre as before.
    let tree = Octree::build(&vertex_fan(centres[0], 40), params).unwrap();
    assert_eq!(tree.stats().max_depth, params.max_depth);
    // The walk answers as brute force, through the fans' leaves.
    let tree = Octree::build(&shapes, params).unwrap();
    let prims = Primitives::opaque(&shapes);
    let mut hits = 0;
    for centre in centres {
        for k in 0..64 {
            let offset = DVec3::new(
                (k % 8) as f64 * 0.25 - 1.0,
                0.0,
                (k / 8) as f64 * 0.25 - 1.0,
            );
            let ray = PreparedRay::new(Ray::new(
                centre + offset - DVec3::new(0.0, 3.0, 0.0),
                DVec3::new(0.01, 1.0, 0.02).normalize(),
            ));
            hits += closest_as_brute_force(&tree, &prims, &ray).is_some() as usize;
        }
    }
    assert!(hits > 32, "{hits} hits");
}

/// Single rays that test triangles four at a time (AVX2 lanes) answer as
/// those testing them one by one, on scenes that mix triangle fans and
/// strips sharing vertices, coincident and coplanar triangles, slivers,
/// spheres, transparent shapes (crossed from both sides, more than
/// `MAX_SHADOW_CROSSINGS` of them along some rays) and one-sided ones:
/// the closest hit to the bit (ties at one `t` by the lower index), the
/// shadow answer and its crossings, through the walk and through a light
/// buffer's lists alike.
#[test]
fn triangles_four_at_a_time_answer_as_one_by_one() {
    use crate::accel::primitives::{occlusion_among, occlusion_among_in_lanes};
    use crate::math::XorShift;
    use crate::shapes::{Triangle, TriangleLanes};
    let Some(simd) = pulp::x86::V3::try_new() else {
        eprintln!("no AVX2 here: nothing to compare");
        return;
    };
    let mut random = XorShift(0x9e37_79b9_7f4a_7c15);
    let mut shapes = Vec::new();
    // Fans of 12 around shared hubs, each fan in one plane.
    for fan in 0..40 {
        let hub = DVec3::new(
            random.unit() * 4.0,
            random.unit() * 4.0,
            (fan % 5) as f64 * 0.5,
        );
        let rim: Vec<DVec3> = (0..13)
            .map(|k| {
                let a = k as f64 * std::f64::consts::TAU / 12.0;
                hub + DVec3::new(a.cos(), a.sin(), 0.0) * (0.3 + random.unit())
            })
            .collect();
        for k in 0..12 {
            shapes.extend(Triangle::new([hub, rim[k], rim[k + 1]]).map(Shape::Triangle));
        }
    }
    // Strips, slivers and coincident copies.
    for _ in 0..300 {
        let a = DVec3::new(
            random.unit() * 4.0,
            random.unit() * 4.0,
            random.unit() * 2.0,
        );
        let b = a + DVec3::new(
            random.unit() - 0.5,
            random.unit() - 0.5,
            random.unit() - 0.5,
        );
        let c = a + (b - a) * 0.5 + DVec3::new(1e-7, random.unit() * 0.3, 0.0);
        if let Some(t) = Triangle::new([a, b, c]) {
            if random.unit() < 0.2 {
                shapes.push(Shape::Triangle(t.clone()));
            }
            shapes.push(Shape::Triangle(t));
        }
    }
    for _ in 0..20 {
        let centre = DVec3::new(
            random.unit() * 4.0,
            random.unit() * 4.0,
            random.unit() * 2.0,
        );
        shapes.push(Shape::Sphere(Sphere::new(
            centre,
            0.05 + 0.3 * random.unit(),
        )));
    }
    let triangles: Vec<&Triangle> = shapes
        .iter()
        .filter_map(|s| match s {
            Shape::Triangle(t) => Some(t),
            _ => None,
        })
        .collect();
    let transparent: Vec<bool> = (0..shapes.len()).map(|_| random.unit() < 0.5).collect();
    let one_sided: Vec<bool> = (0..shapes.len()).map(|_| random.unit() < 0.2).collect();
    let tree = Octree::build(&shapes, OctreeParams::default()).unwrap();
    let mut stack = super::WalkStack::default();
    let (mut lanes, mut single) = (ShadowCrossings::default(), ShadowCrossings::default());
    let (mut hits, mut crossed) = (0, 0);
    for sides in [&[][..], &one_sided[..]] {
        let prims = Primitives {
            shapes: &shapes,
            one_sided: sides,
            transparent: &transparent,
            left_behind: crate::accel::ShapeRange::EMPTY,
        };
        for _ in 0..3000 {
            let origin = DVec3::new(
                random.unit() * 6.0 - 1.0,
                random.unit() * 6.0 - 1.0,
                random.unit() * 4.0 - 1.0,
            );
            // Aimed at a fan's hub (shared by twelve triangles) or anywhere.
            let target =
                match &shapes[(random.unit() * shapes.len() as f64) as usize % shapes.len()] {
                    Shape::Triangle(t) => t.vertices[0],
                    Shape::Sphere(s) => s.center,
                    _ => DVec3::ZERO,
                };
            let Some(dir) = (target - origin).try_normalize() else {
                continue;
            };
            let ray = PreparedRay::new(Ray::new(origin, dir));
            let four =
                tree.closest_inline(&prims, &ray, f64::INFINITY, &mut stack, &mut NoCounts, simd);
            let one = tree.closest_inline(
                &prims,
                &ray,
                f64::INFINITY,
                &mut stack,
                &mut NoCounts,
                OneByOne(simd),
            );
            assert_eq!(four, one, "{:?}", ray.ray);
            // The one-by-one levels' own four-at-once answer (which the
            // walks never ask of them) is the lanes' too.
            let picked: [&Triangle; 4] = std::array::from_fn(|_| {
                triangles[(random.unit() * triangles.len() as f64) as usize % triangles.len()]
            });
            let (a, b) = (
                simd.intersect_four(picked, 0b1111, &ray, 6.0),
                Baseline.intersect_four(picked, 0b1111, &ray, 6.0),
            );
            assert_eq!(a.hit, b.hit);
            for j in (0..4).filter(|j| a.hit >> j & 1 == 1) {
                assert_eq!(a.t[j].to_bits(), b.t[j].to_bits());
                assert_eq!((a.v[j] / a.det[j]).to_bits(), (b.v[j] / b.det[j]).to_bits());
                assert_eq!((a.w[j] / a.det[j]).to_bits(), (b.w[j] / b.det[j]).to_bits());
            }
            hits += four.is_some() as usize;
            let distance = 2.0 + 6.0 * random.unit();
            tree.occlusion_inline(
                &prims,
                &ray,
                distance,
                &mut lanes,
                &mut stack,
                &mut NoCounts,
                simd,
            );
            tree.occlusion_inline(
                &prims,
                &ray,
                distance,
                &mut single,
                &mut stack,
                &mut NoCounts,
                OneByOne(simd),
            );
            assert_eq!(lanes, single, "{:?}", ray.ray);
            crossed += lanes.transparent().len();
            // A light buffer's list: the shapes in random order.
            let list: Vec<u32> = (0..40)
                .map(|_| (random.unit() * shapes.len() as f64) as u32 % shapes.len() as u32)
                .collect();
            occlusion_among_in_lanes(&prims, [&[], &list], &ray, distance, &mut lanes, simd);
            occlusion_among(
                &prims,
                [&[], &list],
                &ray,
                distance,
                &mut single,
                &mut NoCounts,
            );
            assert_eq!(lanes, single, "{:?}", ray.ray);
        }
    }
    assert!(
        hits > 1000 && crossed > 1000,
        "{hits} hits, {crossed} crossings"
    );
}
