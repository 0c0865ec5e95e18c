//! The light buffer against brute force on scenes made to break it.

use super::projection::triangle_rows;
use super::*;
use crate::accel::{Primitives, ShadowCrossings, occlusion_among, occlusion_brute_force};
use crate::math::Ray;
use crate::shapes::{Plane, PreparedRay, Sphere, Triangle};
use crate::stats::NoCounts;

/// A deterministic stream of numbers in `[0, 1)`.
struct Uniform(u64);

impl Uniform {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    fn point(&mut self, b: Aabb) -> DVec3 {
        let t = DVec3::new(self.next(), self.next(), self.next());
        b.min + t * b.extent()
    }
}

/// A ray from the origin along `dir`.
fn along(dir: DVec3) -> PreparedRay {
    PreparedRay::new(Ray::new(DVec3::ZERO, dir))
}

/// How a scene's shadow rays went.
#[derive(Debug, Default)]
struct Tally {
    /// Answered from a cell's list, of which the list was not empty.
    few: usize,
    listed: usize,
    many: usize,
    blocked: usize,
}

/// Shadow rays from points over `shapes`' boxes (and on their surfaces,
/// by aiming at them) to each light, answered through the buffer where it
/// lists a cell and checked bit for bit against brute force.
fn check(shapes: &[Shape], lights: &[DVec3], transparent: &[bool], rays: usize) -> Tally {
    let buffer = LightBuffer::build(shapes, lights).expect("a small scene keeps a buffer");
    assert!(buffer.fits(shapes.len(), lights));
    let prims = Primitives {
        shapes,
        one_sided: &[],
        transparent,
        left_behind: crate::accel::ShapeRange::EMPTY,
    };
    let bounds = shapes
        .iter()
        .filter_map(Shape::bounds)
        .fold(Aabb::from_points(lights), Aabb::union);
    // Origins a little outside the scene too.
    let around = Aabb::new(
        bounds.min - 0.1 * bounds.extent(),
        bounds.max + 0.1 * bounds.extent(),
    );
    let mut uniform = Uniform(0x9e37_79b9_7f4a_7c15);
    let mut tally = Tally::default();
    for n in 0..rays {
        let light_index = n % lights.len();
        let light = lights[light_index];
        let mut origin = uniform.point(around);
        // Every third ray starts on the first surface seen from a random
        // point towards the light, as a renderer's shadow rays do.
        if n % 3 == 0 {
            let ray = PreparedRay::new(Ray::new(origin, (light - origin).normalize()));
            let hit = crate::accel::closest_brute_force(&prims, &ray, f64::INFINITY, &mut NoCounts);
            if let Some(hit) = hit {
                origin = ray.ray.at(hit.hit.t);
            }
        }
        let to_light = light - origin;
        let distance = to_light.length();
        if !(distance > 0.0) {
            continue;
        }
        let ray = PreparedRay::new(Ray::new(origin, to_light / distance));
        let mut expected = ShadowCrossings::default();
        occlusion_brute_force(&prims, &ray, distance, &mut expected, &mut NoCounts);
        tally.blocked += expected.is_blocked() as usize;
        match buffer.candidates(light_index, &ray) {
            Candidates::Few(list) => {
                tally.few += 1;
                tally.listed += !list.is_empty() as usize;
                let mut found = ShadowCrossings::default();
                let lists = [buffer.unbounded(), list];
                occlusion_among(&prims, lists, &ray, distance, &mut found, &mut NoCounts);
                assert_eq!(
                    found.is_blocked(),
                    expected.is_blocked(),
                    "ray {n} from {origin:?} to light {light:?}: listed {list:?}"
                );
                if !expected.is_blocked() {
                    assert_eq!(found, expected, "ray {n} from {origin:?} to {light:?}");
                }
            }
            Candidates::Many => tally.many += 1,
        }
    }
    tally
}

fn sphere(c: DVec3, r: f64) -> Shape {
    Shape::Sphere(Sphere::new(c, r))
}

fn triangle(a: DVec3, b: DVec3, c: DVec3) -> Shape {
    Shape::Triangle(Triangle::new([a, b, c]).expect("not degenerate"))
}

/// Spheres on a grid with lights among them, thin triangles across the
/// planes through each light, a triangle through a light, a sphere whose
/// surface holds a light, slanted cylinders and cones (listed by pieces),
/// one through a light, a row of spheres seen end on from a light (long
/// cells), a polygon cut into a fan of slivers under a light and slivers
/// pointing every way round a light (projected row by row), and a floor.
fn adversarial(scale: f64, offset: DVec3) -> (Vec<Shape>, Vec<DVec3>) {
    let p = |x: f64, y: f64, z: f64| offset + scale * DVec3::new(x, y, z);
    let mut shapes = crate::accel::sphere_grid(4, 0.3)
        .into_iter()
        .map(|s| match s {
            Shape::Sphere(s) => sphere(offset + scale * s.center, scale * s.radius),
            other => other,
        })
        .collect::<Vec<_>>();
    let lights = vec![p(1.5, 1.5, 1.5), p(0.0, 0.0, 5.0), p(3.0, 0.5, 0.5)];
    // Long slivers straddling x = 1.5, y = 1.5 and z = 1.5.
    for k in 0..4 {
        let s = k as f64;
        shapes.push(triangle(
            p(-2.0, s, 0.7),
            p(5.0, s, 0.75),
            p(5.0, s + 0.01, 0.7),
        ));
        shapes.push(triangle(
            p(0.7, -2.0, s),
            p(0.75, 5.0, s),
            p(0.7, 5.0, s + 0.01),
        ));
        shapes.push(triangle(
            p(s, 0.7, -2.0),
            p(s, 0.75, 5.0),
            p(s + 0.01, 0.7, 5.0),
        ));
    }
    // The second light lies in this triangle's plane, on its edge.
    shapes.push(triangle(
        p(-1.0, 0.0, 5.0),
        p(1.0, 0.0, 5.0),
        p(0.0, 1.0, 5.0),
    ));
    // The third light lies on this sphere's surface.
    shapes.push(sphere(p(3.0, 0.5, 0.0), 0.5 * scale));
    // A tiny sphere next to the first light, inside its near zone's reach
    // only at the smallest scales.
    shapes.push(sphere(p(1.5 + 1e-7, 1.5, 1.5), 1e-8 * scale));
    // Slanted thin cylinders and cones round the first light, one a
    // cone to a point, one along the axis the second light is on, one
    // through the first light.
    for k in 0..8 {
        let a = k as f64 * std::f64::consts::FRAC_PI_4;
        let (c, s) = (a.cos(), a.sin());
        let (base, apex) = (p(1.5 + c, 1.5 + s, 1.0), p(1.5 - s, 1.5 + c, 2.2));
        let apex_radius = if k % 3 == 0 { 0.0 } else { 0.04 * scale };
        let cone = crate::shapes::Cone::new(base, 0.05 * scale, apex, apex_radius);
        shapes.push(Shape::Cone(Box::new(cone.expect("a cone"))));
    }
    for (base, apex) in [
        (p(0.0, 0.0, 2.0), p(0.0, 0.0, 4.5)),
        (p(1.0, 1.0, 1.5), p(2.0, 2.0, 1.5)),
    ] {
        let cone = crate::shapes::Cone::new(base, 0.03 * scale, apex, 0.03 * scale);
        shapes.push(Shape::Cone(Box::new(cone.expect("a cylinder"))));
    }
    for k in 0..16 {
        shapes.push(sphere(p(3.0, 0.5, 0.8 + 0.1 * k as f64), 0.03 * scale));
    }
    let corner = |k: usize| {
        let a = k as f64 * std::f64::consts::TAU / 30.0;
        p(1.5 * a.cos(), 1.5 * a.sin(), 3.0)
    };
    for k in 1..29 {
        shapes.push(triangle(corner(0), corner(k), corner(k + 1)));
    }
    let mut uniform = Uniform(17);
    for _ in 0..40 {
        let mut towards = || DVec3::new(uniform.next(), uniform.next(), uniform.next()) - 0.5;
        let (d, e) = (towards().normalize(), 0.02 * towards());
        let (near, far) = (0.05 + uniform.next(), 0.5 + 2.0 * uniform.next());
        let at = |t: f64| p(1.5, 1.5, 1.5) + scale * t * d;
        shapes.push(triangle(at(near), at(far), at(far) + scale * e));
    }
    shapes.push(Shape::Plane(Plane::new(p(0.0, -1.0, 0.0), DVec3::Y)));
    (shapes, lights)
}

#[test]
fn a_buffer_answers_as_brute_force_on_adversarial_scenes() {
    let cases = [
        (1.0, DVec3::ZERO),
        (1e-6, DVec3::ZERO),
        (1e6, DVec3::ZERO),
        (1.0, DVec3::new(1e7, -3e6, 2e7)),
        (1e-3, DVec3::new(5e3, 5e3, -5e3)),
    ];
    for (scale, offset) in cases {
        let (shapes, lights) = adversarial(scale, offset);
        let transparent: Vec<bool> = (0..shapes.len()).map(|i| i % 4 == 1).collect();
        for transparent in [&[][..], &transparent[..]] {
            let tally = check(&shapes, &lights, transparent, 6_000);
            // The lists answered most rays, many of them with shapes to test.
            assert!(
                tally.few > 3_000 && tally.listed > 500 && tally.blocked > 500,
                "scale {scale}, offset {offset:?}: {tally:?}"
            );
        }
    }
}

#[test]
fn rays_along_the_cube_edges_and_axes_answer_as_brute_force() {
    // A light at the centre of a shell of small spheres placed exactly on
    // the axes and the diagonals, where a direction's face is a tie.
    let light = DVec3::new(0.25, -0.5, 2.0);
    let mut shapes = Vec::new();
    for x in -1..=1 {
        for y in -1..=1 {
            for z in -1..=1 {
                if (x, y, z) != (0, 0, 0) {
                    let d = DVec3::new(x as f64, y as f64, z as f64);
                    shapes.push(sphere(light + 2.0 * d, 0.05));
                }
            }
        }
    }
    let buffer = LightBuffer::build(&shapes, &[light]).unwrap();
    let prims = Primitives::opaque(&shapes);
    let mut blocked = 0;
    for (i, shape) in shapes.iter().enumerate() {
        let Shape::Sphere(s) = shape else { continue };
        // From just beyond each sphere, straight through its centre to the light.
        let origin = light + 1.5 * (s.center - light);
        let to_light = light - origin;
        let distance = to_light.length();
        let ray = PreparedRay::new(Ray::new(origin, to_light / distance));
        let Candidates::Few(list) = buffer.candidates(0, &ray) else {
            panic!("ray {i}: a few spheres per cell")
        };
        let mut found = ShadowCrossings::default();
        occlusion_among(
            &prims,
            [&[], list],
            &ray,
            distance,
            &mut found,
            &mut NoCounts,
        );
        assert!(found.is_blocked(), "ray {i}: listed {list:?}");
        blocked += 1;
    }
    assert_eq!(blocked, 26);
}

#[test]
fn crowded_cells_go_to_the_accelerator() {
    // More spheres in a row, seen end on from the light, than a cell
    // keeps: their cells are long, and so are those of a light inside
    // all their boxes.
    let count = MAX_LIST + 20;
    let shapes: Vec<Shape> = (0..count)
        .map(|i| sphere(DVec3::new(2.0 + i as f64, 0.0, 0.0), 0.4))
        .collect();
    let beyond = LightBuffer::build(&shapes, &[DVec3::ZERO]).unwrap();
    let from = |x: f64| PreparedRay::new(Ray::new(DVec3::new(x, 0.0, 0.0), DVec3::NEG_X));
    // A ray from x meets at most the spheres that come nearer the light
    // (sphere i from 1.6 + i): up to the last one kept (to MAX_LIST +
    // 1.4), those are listed; from the next one's start (MAX_LIST + 1.6)
    // on, the cell has too many.
    let kept = MAX_LIST as f64;
    for (x, nearer) in [
        (0.5, 0),
        (1.0, 0),
        (1.7, 1),
        (8.0, 7),
        (kept + 1.5, MAX_LIST as u32),
    ] {
        let expected: Vec<u32> = (0..nearer).collect();
        match beyond.candidates(0, &from(x)) {
            Candidates::Few(list) => assert_eq!(list, expected, "from x = {x}"),
            Candidates::Many => panic!("from x = {x}: the nearest suffice"),
        }
    }
    for x in [kept + 1.7, kept + 10.0, 2.0 * count as f64] {
        assert!(
            matches!(beyond.candidates(0, &from(x)), Candidates::Many),
            "from x = {x}"
        );
    }
    assert!(matches!(
        beyond.candidates(0, &along(DVec3::X)),
        Candidates::Few([])
    ));
    let mut big = shapes.clone();
    big.extend((0..=MAX_LIST).map(|_| sphere(DVec3::ZERO, 100.0)));
    let inside = LightBuffer::build(&big, &[DVec3::ZERO]).unwrap();
    assert_eq!(inside.stats().cubes, 0, "every cell long: no cube");
    assert!(matches!(
        inside.candidates(0, &along(DVec3::X)),
        Candidates::Many
    ));
}

#[test]
fn a_buffer_fits_only_its_own_lights_and_shapes() {
    let shapes = vec![sphere(DVec3::ZERO, 1.0)];
    let lights = [DVec3::new(0.0, 5.0, 0.0)];
    let buffer = LightBuffer::build(&shapes, &lights).unwrap();
    assert!(buffer.fits(1, &lights));
    assert!(!buffer.fits(2, &lights));
    assert!(!buffer.fits(1, &[DVec3::new(0.0, 5.0, 1e-12)]));
    assert!(LightBuffer::build(&shapes, &[]).is_none());
    // A light with no cube answers "ask the accelerator".
    assert!(matches!(
        buffer.candidates(7, &along(DVec3::X)),
        Candidates::Many
    ));
}

#[test]
fn counts_by_difference_table_match_counting_cell_by_cell() {
    let mut uniform = Uniform(7);
    let rects: Vec<Rect> = (0..200)
        .map(|k| {
            let mut c = [0u8; 4];
            for pair in 0..2 {
                let a = (uniform.next() * SIDE as f64) as u8;
                let b = (uniform.next() * SIDE as f64) as u8;
                c[2 * pair] = a.min(b);
                c[2 * pair + 1] = a.max(b);
            }
            Rect {
                shape: k,
                near: 0.0,
                face: (k % 6) as u8,
                cells: c,
            }
        })
        .collect();
    let mut direct = vec![0u32; CUBE_CELLS];
    for r in &rects {
        let [i0, i1, j0, j1] = r.cells.map(usize::from);
        for j in j0..=j1 {
            for i in i0..=i1 {
                direct[r.face as usize * FACE_CELLS + j * SIDE + i] += 1;
            }
        }
    }
    assert_eq!(cell_counts(&rects), direct);
}

#[test]
fn a_face_coordinate_falls_in_the_cell_that_holds_it() {
    // Cell k holds [k, k + 1) / SIDE of [0, 1] after `(u + 1) / 2`; below
    // the face (and NaN) is cell 0, its far edge and beyond the last cell.
    let side = SIDE as f64;
    for k in 0..SIDE {
        let low = 2.0 * k as f64 / side - 1.0;
        let high = 2.0 * (k + 1) as f64 / side - 1.0;
        // Exact at `low` (SIDE is a power of two); just inside `high` the
        // arithmetic may round up into the next cell.
        for u in [low, low + 1e-12, 0.5 * (low + high), high - 1e-12] {
            assert_eq!(cell_index(u), k, "u = {u}");
        }
    }
    for (u, k) in [
        (f64::NAN, 0),
        (f64::NEG_INFINITY, 0),
        (-1.5, 0),
        (-1.0, 0),
        (1.0, SIDE - 1),
        (1.0f64.next_up(), SIDE - 1),
        (3e9, SIDE - 1),
        (f64::INFINITY, SIDE - 1),
    ] {
        assert_eq!(cell_index(u), k, "u = {u}");
    }
}

#[test]
fn a_rays_cell_from_its_shear_is_the_cell_of_its_reversed_direction() {
    // Every face and its edges and corners, where the dominant axis is a
    // tie; zero and negative-zero components; random directions; and
    // components far apart in magnitude. The zero direction lands in
    // cell 0 both ways.
    let mut dirs = Vec::new();
    let values = [-1.0, -0.5, -1e-300, -0.0, 0.0, 1e-300, 0.5, 1.0];
    for &x in &values {
        for &y in &values {
            for &z in &values {
                dirs.push(DVec3::new(x, y, z));
            }
        }
    }
    // Components no prepared ray should carry, but might: NaN (every
    // quotient NaN, cell 0 of its face) and infinities (inf / inf).
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        dirs.extend([
            DVec3::new(bad, 0.5, -0.25),
            DVec3::new(0.5, bad, 1.0),
            DVec3::new(-1.0, 0.25, bad),
            DVec3::new(bad, bad, 1.0),
        ]);
    }
    let mut uniform = Uniform(7);
    for _ in 0..20_000 {
        let d = uniform.point(Aabb::new(DVec3::splat(-1.0), DVec3::ONE));
        dirs.push(d);
        dirs.push(d * DVec3::new(1e-12, 1.0, 1e12));
    }
    for d in dirs {
        assert_eq!(cell_of_ray(&along(d)), cell_of(-d), "direction {d:?}");
    }
}

#[test]
fn a_triangles_rows_hold_every_point_near_it() {
    // Points within the padding of triangles near and far, in every
    // direction from the light (at the origin), fall in cells the rows
    // list, for the face their direction belongs to.
    let pad = 1e-3;
    let mut uniform = Uniform(5);
    let mut covered = vec![false; CUBE_CELLS];
    let mut by_rows = 0;
    for n in 0..400 {
        let distance = [0.02, 0.1, 1.0, 30.0][n % 4];
        let centre = (DVec3::new(uniform.next(), uniform.next(), uniform.next()) - 0.5).normalize()
            * distance;
        let size = distance * [0.05, 0.5, 2.0][n % 3];
        let mut corner =
            || centre + size * (DVec3::new(uniform.next(), uniform.next(), uniform.next()) - 0.5);
        let v = [corner(), corner(), corner()];
        let b = Aabb::from_points(&v);
        let b = Aabb::new(b.min - pad, b.max + pad);
        covered.fill(false);
        for face in 0..6 {
            let Some(bound) = face_rect(&b, face) else {
                continue;
            };
            let mut mark = |[i0, i1, j0, j1]: [u8; 4]| {
                for j in j0..=j1 {
                    for i in i0..=i1 {
                        covered[face * FACE_CELLS + j as usize * SIDE + i as usize] = true;
                    }
                }
            };
            if triangle_rows(&v, face, pad, bound, &mut mark) {
                by_rows += 1;
            } else {
                mark(bound);
            }
        }
        for _ in 0..200 {
            let (s, t) = (uniform.next(), uniform.next());
            let (s, t) = if s + t > 1.0 {
                (1.0 - s, 1.0 - t)
            } else {
                (s, t)
            };
            let off =
                pad * (2.0 * DVec3::new(uniform.next(), uniform.next(), uniform.next()) - 1.0);
            // On the edges too: a third of the points.
            let (s, t) = if uniform.next() < 0.33 {
                (s, 0.0)
            } else {
                (s, t)
            };
            let point = v[0] + s * (v[1] - v[0]) + t * (v[2] - v[0]) + off;
            assert!(
                covered[cell_of(point)],
                "triangle {n} {v:?}: point {point:?} in no listed cell"
            );
        }
    }
    assert!(by_rows > 300, "most triangles projected by rows: {by_rows}");
}

#[test]
fn a_triangles_nearest_distance_is_no_more_than_any_of_its_points() {
    // Against the distances of points spread over triangles of every
    // shape, slivers included, the light inside, beside and far off;
    // and exact where the answer is known.
    use super::projection::nearest_distance;
    let mut uniform = Uniform(11);
    let mut measured = 0;
    for n in 0..3_000 {
        let spread = [0.01, 1.0, 100.0][n % 3];
        let mut corner =
            || spread * (DVec3::new(uniform.next(), uniform.next(), uniform.next()) - 0.3);
        let (a, b) = (corner(), corner());
        // Every fourth a sliver: the third corner near the first edge.
        let c = if n % 4 == 0 {
            a + uniform.next() * (b - a) + 1e-3 * spread * uniform.next() * DVec3::Z
        } else {
            corner()
        };
        let Some(d) = nearest_distance(&[a, b, c]) else {
            continue;
        };
        measured += 1;
        let mut closest = f64::INFINITY;
        for i in 0..=40 {
            for j in 0..=40 - i {
                let (s, t) = (i as f64 / 40.0, j as f64 / 40.0);
                closest = closest.min((a + s * (b - a) + t * (c - a)).length());
            }
        }
        assert!(
            d <= closest * (1.0 + 1e-12),
            "triangle {n}: {d} > {closest}"
        );
        assert!(d >= 0.0);
    }
    assert!(measured > 2_000, "{measured}");
    let unit = [
        DVec3::new(-1.0, -1.0, 2.0),
        DVec3::new(3.0, -1.0, 2.0),
        DVec3::new(-1.0, 3.0, 2.0),
    ];
    assert_eq!(nearest_distance(&unit), Some(2.0));
    let aside = unit.map(|p| p + DVec3::new(5.0, 0.0, -2.0));
    // Nearest on the edge x = 4, at (4, 0, 0).
    assert!((nearest_distance(&aside).unwrap() - 4.0).abs() < 1e-12);
    let sliver = [DVec3::ZERO, DVec3::X, DVec3::new(0.5, 1e-9, 0.0)];
    assert_eq!(nearest_distance(&sliver.map(|p| p + DVec3::Y)), None);
}
