//! Geometry from the fuzzer's bytes: up to 32 spheres, triangles, planes,
//! quadrics and cones at any scale (1e-60 to 1e60) and any distance from
//! the origin, under any octree parameters. Every ray must find the same
//! closest hit and the same shadow verdict in the octree as by brute
//! force, the build must keep to its memory budget, and a small render
//! must have finite pixels, the same with the octree on and off.
#![no_main]

use std::sync::Arc;

use glint::accel::{
    Octree, OctreeParams, Primitives, ShadowCrossings, WalkStack, closest_brute_force,
    occlusion_brute_force,
};
use glint::camera::CameraSpec;
use glint::material::{Light, Material};
use glint::math::{Aabb, DVec3, Ray};
use glint::scene::{ImageSettings, Scene};
use glint::shapes::{Cone, Plane, PreparedRay, Quadric, Shape, Sphere, Triangle};
use glint::stats::NoCounts;
use glint_fuzz::{check_scene, single_thread};
use libfuzzer_sys::arbitrary::{self, Arbitrary};
use libfuzzer_sys::fuzz_target;

type Point = [i16; 3];

#[derive(Arbitrary, Debug)]
enum ShapeInput {
    Sphere {
        center: Point,
        radius: u16,
    },
    Triangle {
        vertices: [Point; 3],
    },
    Plane {
        point: Point,
        normal: [i8; 3],
    },
    Quadric {
        coefficients: [i8; 10],
        clip: Option<(Point, Point)>,
    },
    Cone {
        base: Point,
        base_radius: u16,
        apex: Point,
        apex_radius: u16,
    },
}

#[derive(Arbitrary, Debug)]
struct RayInput {
    origin: Point,
    direction: [i8; 3],
}

#[derive(Arbitrary, Debug)]
struct Input {
    /// Size of one unit of the integer coordinates: 2^(scale / 2).
    scale: i8,
    /// Where the scene sits, in units of 2^16 of its coordinates.
    offset: [i8; 3],
    shapes: Vec<(ShapeInput, u8)>,
    rays: Vec<RayInput>,
    max_depth: u8,
    leaf_size: u8,
    max_duplication: u8,
    cost_driven: bool,
    memory_budget_mib: u8,
    eye: Point,
    lookat: Point,
    fov: u8,
    shadow_length: u16,
}

struct Units {
    unit: f64,
    offset: DVec3,
}

impl Units {
    fn new(input: &Input) -> Self {
        let unit = 2f64.powi((input.scale as i32).clamp(-120, 120) / 2);
        let [x, y, z] = input.offset.map(|o| o as f64 * 65536.0 * unit);
        Self {
            unit,
            offset: DVec3::new(x, y, z),
        }
    }

    fn point(&self, p: Point) -> DVec3 {
        self.offset + DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64) * self.unit
    }

    fn length(&self, l: u16) -> f64 {
        l as f64 * self.unit
    }
}

/// The shape as a scene file could give it (the loaders' checks), if any.
fn shape(input: &ShapeInput, u: &Units) -> Option<Shape> {
    Some(match *input {
        ShapeInput::Sphere { center, radius } => {
            (radius > 0).then_some(())?;
            Shape::Sphere(Sphere::new(u.point(center), u.length(radius)))
        }
        ShapeInput::Triangle { vertices } => {
            Shape::Triangle(Triangle::new(vertices.map(|v| u.point(v)))?)
        }
        ShapeInput::Plane { point, normal } => {
            let n = DVec3::new(normal[0] as f64, normal[1] as f64, normal[2] as f64);
            (n != DVec3::ZERO).then_some(())?;
            Shape::Plane(Plane::new(u.point(point), n))
        }
        ShapeInput::Quadric { coefficients, clip } => {
            // Small integer coefficients of F in world coordinates; the
            // clip box, when any, in the scene's units.
            let c = coefficients.map(|c| c as f64);
            let clip = clip.map(|(a, b)| {
                let (a, b) = (u.point(a), u.point(b));
                Aabb::new(a.min(b), a.max(b))
            });
            Shape::Quadric(Box::new(Quadric::new(c, clip)))
        }
        ShapeInput::Cone {
            base,
            base_radius,
            apex,
            apex_radius,
        } => Shape::Cone(Box::new(Cone::new(
            u.point(base),
            u.length(base_radius),
            u.point(apex),
            u.length(apex_radius),
        )?)),
    })
}

fn materials() -> Vec<Material> {
    let base = Material {
        name: "matte".into(),
        color: DVec3::new(0.8, 0.5, 0.3),
        ka: 1.0,
        kd: 0.8,
        ks: 0.3,
        shininess: 40.0,
        reflectivity: 0.0,
        transparency: 0.0,
        ior: 1.0,
        color_map: None,
        cutout_map: None,
    };
    vec![
        base.clone(),
        Material {
            name: "mirror".into(),
            reflectivity: 0.8,
            ..base.clone()
        },
        Material {
            name: "glass".into(),
            transparency: 0.9,
            reflectivity: 0.1,
            ior: 1.5,
            ..base
        },
    ]
}

fuzz_target!(|input: Input| {
    let units = Units::new(&input);
    let mut shapes = Vec::new();
    let mut shape_materials = Vec::new();
    for (s, m) in input.shapes.iter().take(32) {
        if let Some(shape) = shape(s, &units) {
            shapes.push(shape);
            shape_materials.push((m % 3) as u32);
        }
    }
    let params = OctreeParams {
        max_depth: (input.max_depth % 22) as u32,
        leaf_size: (input.leaf_size % 8) as u32 + 1,
        cost_driven: input.cost_driven,
        max_duplication: (input.max_duplication % 8) as u32 + 1,
        memory_budget_mib: (input.memory_budget_mib % 2) as u32 + 1,
    };
    let Ok(octree) = single_thread(|| Octree::build(&shapes, params)) else {
        return;
    };
    let stats = octree.stats();
    assert!(stats.memory_bytes <= stats.memory_budget_bytes + 4096);

    let transparent: Vec<bool> = shape_materials.iter().map(|&m| m == 2).collect();
    let prims = Primitives {
        transparent: &transparent,
        ..Primitives::opaque(&shapes)
    };
    let shadow_length = units.length(input.shadow_length).max(f64::MIN_POSITIVE);
    let mut stack = WalkStack::default();
    for r in input.rays.iter().take(16) {
        let d = DVec3::new(
            r.direction[0] as f64,
            r.direction[1] as f64,
            r.direction[2] as f64,
        );
        if d == DVec3::ZERO {
            continue;
        }
        let ray = PreparedRay::new(Ray::new(units.point(r.origin), d.normalize()));
        let brute = closest_brute_force(&prims, &ray, f64::INFINITY, &mut NoCounts);
        let tree = octree.closest(&prims, &ray, f64::INFINITY, &mut stack, &mut NoCounts);
        assert_eq!(brute, tree, "closest hit differs");
        let mut b = ShadowCrossings::default();
        occlusion_brute_force(&prims, &ray, shadow_length, &mut b, &mut NoCounts);
        let mut t = ShadowCrossings::default();
        octree.occlusion(
            &prims,
            &ray,
            shadow_length,
            &mut t,
            &mut stack,
            &mut NoCounts,
        );
        assert_eq!(b, t, "shadow verdict differs");
    }

    let camera = CameraSpec {
        eye: units.point(input.eye),
        lookat: units.point(input.lookat),
        up: DVec3::Y,
        fov: (input.fov as f64 * 180.0 / 256.0).max(0.5),
    };
    let mut scene = Scene::empty("fuzz".into(), camera, ImageSettings::default());
    scene.materials = materials();
    scene.lights = vec![Light {
        position: units.point([100, 300, 200]),
        color: DVec3::ONE,
    }];
    scene.shapes = Arc::new(shapes);
    scene.shape_materials = Arc::new(shape_materials);
    scene.octree_params = params;
    check_scene(&mut scene);
});
