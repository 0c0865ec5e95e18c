//! A ray spawned from a hit point never hits its own surface again where
//! it should not: reflection, refraction and shadow rays leave from the
//! point moved off the surface as the renderer moves it
//! (`offset_ray_origin`, after Wächter & Binder 2019), over random shapes,
//! sizes from 1e-4 to 1e4 and positions up to a million sizes from the
//! origin. Expected answers come from geometry: a line meets a plane once,
//! a ray leaving a convex surface on its outside never meets it again, and
//! a chord of a sphere or ellipsoid ends where the quadratic says.

use glint::math::{DVec3, Ray, offset_ray_origin, reflect, refract};
use glint::shapes::{Plane, PreparedRay, Quadric, Shape, Sphere, Triangle};
use proptest::prelude::*;
use proptest::strategy::ValueTree;

/// The shape kinds under test, each with what the test needs to know of it.
#[derive(Clone, Debug)]
enum Solid {
    Sphere {
        centre: DVec3,
        radius: f64,
    },
    /// Axis-aligned ellipsoid as a general quadric.
    Ellipsoid {
        centre: DVec3,
        axes: DVec3,
    },
    Triangle([DVec3; 3]),
    Plane {
        point: DVec3,
        normal: DVec3,
    },
}

impl Solid {
    fn shape(&self) -> Shape {
        match self {
            Solid::Sphere { centre, radius } => Shape::Sphere(Sphere::new(*centre, *radius)),
            Solid::Ellipsoid { centre, axes } => {
                // ((x - cx) / ax)^2 + ... - 1, expanded (no implicit 2s).
                let k = DVec3::ONE / (*axes * *axes);
                let l = -2.0 * *centre * k;
                let j = (*centre * *centre * k).element_sum() - 1.0;
                Shape::Quadric(Box::new(Quadric::new(
                    [k.x, 0.0, 0.0, l.x, k.y, 0.0, l.y, k.z, l.z, j],
                    None,
                )))
            }
            Solid::Triangle(v) => Shape::Triangle(Triangle::new(*v).expect("not degenerate")),
            Solid::Plane { point, normal } => Shape::Plane(Plane::new(*point, *normal)),
        }
    }

    /// Where the line `p + t d` leaves the solid again, for a point `p` on a
    /// closed surface and `d` pointing inside: the second root of the
    /// quadratic in the unit-sphere frame (`None` for flat shapes).
    fn far_side(&self, p: DVec3, d: DVec3) -> Option<f64> {
        let (centre, axes) = match self {
            Solid::Sphere { centre, radius } => (*centre, DVec3::splat(*radius)),
            Solid::Ellipsoid { centre, axes } => (*centre, *axes),
            _ => return None,
        };
        let (q, e) = ((p - centre) / axes, d / axes);
        Some(-2.0 * q.dot(e) / e.dot(e))
    }

    /// A size of the solid: its radius, smallest axis or shortest edge.
    fn size(&self) -> f64 {
        match self {
            Solid::Sphere { radius, .. } => *radius,
            Solid::Ellipsoid { axes, .. } => axes.min_element(),
            Solid::Triangle([a, b, c]) => (*b - *a).length().min((*c - *a).length()),
            Solid::Plane { .. } => 1.0,
        }
    }

    /// A point on the surface, chosen by two numbers in [0, 1).
    fn target(&self, s: f64, t: f64) -> DVec3 {
        match self {
            Solid::Sphere { centre, radius } => *centre + *radius * unit(s, t),
            Solid::Ellipsoid { centre, axes } => *centre + *axes * unit(s, t),
            Solid::Triangle([a, b, c]) => {
                // Uniform over the triangle, kept off its edges.
                let (s, t) = if s + t > 1.0 {
                    (1.0 - s, 1.0 - t)
                } else {
                    (s, t)
                };
                let (s, t) = (0.01 + 0.97 * s, 0.01 + 0.97 * t);
                *a + s * (*b - *a) + t * (*c - *a)
            }
            Solid::Plane { point, normal } => {
                let (u, v) = basis(*normal);
                *point + (s - 0.5) * 10.0 * u + (t - 0.5) * 10.0 * v
            }
        }
    }
}

/// A unit vector from two numbers in [0, 1).
fn unit(s: f64, t: f64) -> DVec3 {
    let z = 2.0 * s - 1.0;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = std::f64::consts::TAU * t;
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Two unit vectors perpendicular to `n` and to each other.
fn basis(n: DVec3) -> (DVec3, DVec3) {
    let n = n.normalize();
    let helper = if n.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
    let u = n.cross(helper).normalize();
    (u, n.cross(u))
}

/// A random solid of size `scale` whose centre is `position`.
fn solid_strategy() -> impl Strategy<Value = Solid> {
    let scale = (-4.0..4.0f64).prop_map(|e| 10f64.powf(e));
    // Up to a million sizes from the origin, in any direction.
    let position = (0.0..6.0f64, 0.0..1.0f64, 0.0..1.0f64);
    let shape = (0..4u8, 0.0..1.0f64, 0.0..1.0f64, 0.0..1.0f64, 0.0..1.0f64);
    (scale, position, shape).prop_map(|(scale, (distance, s, t), (kind, a, b, c, d))| {
        let centre = unit(s, t) * scale * 10f64.powf(distance);
        match kind {
            0 => Solid::Sphere {
                centre,
                radius: scale,
            },
            1 => Solid::Ellipsoid {
                centre,
                axes: scale * DVec3::new(0.3 + a, 0.3 + b, 0.3 + c),
            },
            2 => {
                let e1 = unit(a, b) * scale;
                let e2 = unit(c, d) * scale;
                // Keep the triangle well shaped: e2 at least 30° from e1.
                let e2 = if e1.normalize().dot(e2.normalize()).abs() > 0.85 {
                    e1.cross(e2).normalize().cross(e1)
                } else {
                    e2
                };
                Solid::Triangle([centre, centre + e1, centre + e2])
            }
            _ => Solid::Plane {
                point: centre,
                normal: unit(a, b),
            },
        }
    })
}

/// A hit on the solid: a ray from outside (or, for closed solids when
/// `inside`, from within) towards a random point of its surface.
struct Case {
    shape: Shape,
    ray: Ray,
    point: DVec3,
    /// Geometric normal facing the incoming ray.
    facing: DVec3,
    /// The scene's magnitude, as the renderer's floor for offsets.
    floor_scale: f64,
}

fn hit(solid: &Solid, aim: (f64, f64), from: (f64, f64, f64), inside: bool) -> Option<Case> {
    let shape = solid.shape();
    let target = solid.target(aim.0, aim.1);
    let size = solid.size();
    let origin = if inside {
        // A point inside the closed solid: part way from its centre.
        match solid {
            Solid::Sphere { centre, radius } => {
                *centre + 0.5 * from.2 * *radius * unit(from.0, from.1)
            }
            Solid::Ellipsoid { centre, axes } => {
                *centre + 0.5 * from.2 * *axes * unit(from.0, from.1)
            }
            _ => return None,
        }
    } else {
        // Outside: 1.5 to 100 sizes away, on the side the target faces.
        let away = 10f64.powf(0.2 + 1.8 * from.2) * size;
        let mut dir = unit(from.0, from.1);
        let outward = match solid {
            Solid::Sphere { centre, .. } => (target - *centre).normalize(),
            // The gradient of the implicit function.
            Solid::Ellipsoid { centre, axes } => ((target - *centre) / (*axes * *axes)).normalize(),
            Solid::Triangle([a, b, c]) => (*b - *a).cross(*c - *a).normalize(),
            Solid::Plane { normal, .. } => normal.normalize(),
        };
        if dir.dot(outward) < 0.1 {
            dir = reflect(dir, outward);
            if dir.dot(outward) < 0.1 {
                dir = (dir + outward).normalize();
            }
        }
        target + dir * away
    };
    let ray = Ray::new(origin, (target - origin).normalize());
    let found = shape.intersect(&PreparedRay::new(ray), f64::INFINITY)?;
    let surface = shape.surface(&ray, &found, &[]);
    let facing = if ray.dir.dot(surface.geometric_normal) < 0.0 {
        surface.geometric_normal
    } else {
        -surface.geometric_normal
    };
    let extent = match solid {
        Solid::Sphere { centre, radius } => (centre.abs() + *radius).max_element(),
        Solid::Ellipsoid { centre, axes } => (centre.abs() + *axes).max_element(),
        Solid::Triangle(v) => v.iter().map(|p| p.abs().max_element()).fold(0.0, f64::max),
        Solid::Plane { point, .. } => point.abs().max_element(),
    };
    Some(Case {
        shape,
        ray,
        point: surface.point,
        facing,
        floor_scale: extent.max(origin.abs().max_element()),
    })
}

/// The nearest hit of `shape` along a ray from `origin` in direction `dir`.
fn next_hit(shape: &Shape, origin: DVec3, dir: DVec3, t_max: f64) -> Option<f64> {
    shape
        .intersect(&PreparedRay::new(Ray::new(origin, dir)), t_max)
        .map(|h| h.t)
}

fn is_closed(solid: &Solid) -> bool {
    matches!(solid, Solid::Sphere { .. } | Solid::Ellipsoid { .. })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 3000, ..ProptestConfig::default() })]

    /// From outside: the mirror ray and a shadow ray towards any light on
    /// the lit side never meet the surface again; the refracted ray meets
    /// a closed solid only at the far end of its chord, a flat one never.
    #[test]
    fn rays_leaving_an_outside_hit_do_not_hit_their_surface_again(
        solid in solid_strategy(),
        aim in (0.0..1.0f64, 0.0..1.0f64),
        from in (0.0..1.0f64, 0.0..1.0f64, 0.0..1.0f64),
        light in (0.0..1.0f64, 0.0..1.0f64, -3.0..6.0f64),
        ior in 1.01..3.0f64,
    ) {
        let Some(case) = hit(&solid, aim, from, false) else {
            // Only rays within rounding of a silhouette can miss.
            return Ok(());
        };
        let size = solid.size();
        let (p, n) = (case.point, case.facing);
        let reflected = reflect(case.ray.dir, n);
        let out = offset_ray_origin(p, n, case.floor_scale);
        prop_assert_eq!(next_hit(&case.shape, out, reflected, f64::INFINITY), None);

        // A light somewhere on the lit side, from 1e-3 to 1e6 sizes away.
        let mut to_light = unit(light.0, light.1);
        if to_light.dot(n) < 0.0 {
            to_light = reflect(to_light, n);
        }
        if to_light.dot(n) > 1e-3 {
            let light_at = p + to_light * size * 10f64.powf(light.2);
            let towards = light_at - out;
            let distance = towards.length();
            prop_assert_eq!(
                next_hit(&case.shape, out, towards / distance, distance),
                None,
                "shadow ray"
            );
        }

        let refracted = refract(case.ray.dir, n, 1.0 / ior).expect("no TIR entering");
        let inside = offset_ray_origin(p, -n, case.floor_scale);
        let again = next_hit(&case.shape, inside, refracted, f64::INFINITY);
        match solid.far_side(p, refracted) {
            Some(far) => {
                let t = again.expect("the refracted ray leaves through the far side");
                // The offset moves the origin by about 1e-12 of the scene's
                // magnitude; quadrics far out carry their coefficients'
                // rounding as well.
                let tolerance = 1e-6 * size + 1e-9 * case.floor_scale;
                prop_assert!(
                    (t - far).abs() <= tolerance,
                    "far side at {} expected, hit at {} (size {})", far, t, size
                );
            }
            None => prop_assert_eq!(again, None, "a flat surface is crossed once"),
        }
    }

    /// From inside a closed solid: the internally reflected ray meets the
    /// surface only at the far end of its chord, and the refracted ray
    /// leaving it never meets it again.
    #[test]
    fn rays_leaving_an_inside_hit_do_not_hit_their_surface_again(
        solid in solid_strategy().prop_filter("closed", is_closed),
        aim in (0.0..1.0f64, 0.0..1.0f64),
        from in (0.0..1.0f64, 0.0..1.0f64, 0.0..1.0f64),
        ior in 1.01..3.0f64,
    ) {
        let Some(case) = hit(&solid, aim, from, true) else {
            return Ok(());
        };
        let size = solid.size();
        let (p, n) = (case.point, case.facing);
        let reflected = reflect(case.ray.dir, n);
        let back_in = offset_ray_origin(p, n, case.floor_scale);
        let far = solid.far_side(p, reflected).expect("closed");
        let t = next_hit(&case.shape, back_in, reflected, f64::INFINITY)
            .expect("the reflected ray crosses the solid");
        prop_assert!(
            (t - far).abs() <= 1e-6 * size + 1e-9 * case.floor_scale,
            "far side at {} expected, hit at {}", far, t
        );
        // Leaving into air (eta = ior > 1): unless totally reflected.
        if let Some(out_dir) = refract(case.ray.dir, n, ior) {
            let out = offset_ray_origin(p, -n, case.floor_scale);
            prop_assert_eq!(next_hit(&case.shape, out, out_dir, f64::INFINITY), None);
        }
    }
}

#[test]
fn the_generated_cases_mostly_hit() {
    // The properties above skip a case only when the aimed ray misses:
    // check that this is rare, so they are not vacuous.
    let mut runner = proptest::test_runner::TestRunner::deterministic();
    let strategy = (
        solid_strategy(),
        (0.0..1.0f64, 0.0..1.0f64),
        (0.0..1.0f64, 0.0..1.0f64, 0.0..1.0f64),
    );
    let (mut outside, mut inside, mut closed) = (0, 0, 0);
    for _ in 0..1000 {
        let (solid, aim, from) = strategy.new_tree(&mut runner).unwrap().current();
        outside += hit(&solid, aim, from, false).is_some() as u32;
        if is_closed(&solid) {
            closed += 1;
            inside += hit(&solid, aim, from, true).is_some() as u32;
        }
    }
    assert!(outside >= 990, "{outside} of 1000 rays from outside hit");
    assert!(
        closed > 300 && inside == closed,
        "{inside} of {closed} rays from inside hit"
    );
}
