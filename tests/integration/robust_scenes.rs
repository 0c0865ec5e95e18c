//! Scenes nobody made to work: concave polygons, octree torture scenes,
//! shadows through glass however it is modelled, and records of scenes
//! whose text is too large for a PNG text chunk.

use crate::common;
use glint::settings::Accel;

use common::{render_with, repo_path, scene_from};
use glint::accel::{Octree, OctreeParams};
use glint::camera::Camera;
use glint::math::DVec3;
use glint::render::Renderer;
use glint::settings::ViewMode;

fn nff_with_polygon(eye: DVec3, vertices: &[DVec3], size: u32) -> String {
    let mut s = format!(
        "v\nfrom {} {} {}\nat 0 0 0\nup 0 1 0\nangle 40\nhither 1\nresolution {size} {size}\n\
         l 0 0 10\nf 1 1 1 1 0 1 0 0\np {}\n",
        eye.x,
        eye.y,
        eye.z,
        vertices.len()
    );
    for v in vertices {
        s.push_str(&format!("{:.17} {:.17} {:.17}\n", v.x, v.y, v.z));
    }
    s
}

/// Even-odd test of a point of the z = 0 plane against a polygon there,
/// independent of glint's triangulation, and the point's distance to the
/// outline.
fn inside_and_margin(polygon: &[DVec3], x: f64, y: f64) -> (bool, f64) {
    let mut inside = false;
    let mut margin = f64::INFINITY;
    for k in 0..polygon.len() {
        let (a, b) = (polygon[k], polygon[(k + 1) % polygon.len()]);
        if (a.y > y) != (b.y > y) && x < a.x + (y - a.y) / (b.y - a.y) * (b.x - a.x) {
            inside = !inside;
        }
        let (ab, ap) = (b - a, DVec3::new(x, y, 0.0) - a);
        let s = (ap.dot(ab) / ab.length_squared()).clamp(0.0, 1.0);
        margin = margin.min((ap - s * ab).length());
    }
    (inside, margin)
}

/// Renders the polygon (in the z = 0 plane) from `eye` and compares each
/// pixel's coverage with the exact answer for its centre ray. Pixels whose
/// ray meets the plane within 1e-9 of the outline are skipped (and
/// counted): there rounding may decide either way.
fn assert_exact_coverage(polygon: &[DVec3], eye: DVec3, size: u32) {
    let text = nff_with_polygon(eye, polygon, size);
    let scene = scene_from(&text, "polygon.nff");
    assert_eq!(scene.dropped_polygons.total(), 0, "the polygon is simple");
    let octree = std::sync::Arc::new(scene.build_octree().unwrap());
    let mut settings = scene.render_settings();
    settings.view = ViewMode::Depth;
    let accel = crate::common::accelerator(&scene, &settings, Some(&octree));
    let renderer = Renderer::new(&scene, &accel, settings).unwrap();
    let (frame, _) = renderer.render(false, None);
    let camera = Camera::new(&scene.camera, size, size).unwrap();
    let (mut covered, mut skipped, mut wrong) = (0, 0, Vec::new());
    for j in 0..size {
        for i in 0..size {
            let ray = camera.ray(i, j, 0.5, 0.5);
            let t = -ray.origin.z / ray.dir.z;
            let p = ray.at(t);
            let (inside, margin) = inside_and_margin(polygon, p.x, p.y);
            if margin < 1e-9 {
                skipped += 1;
                continue;
            }
            let hit = frame.pixels[(j * size + i) as usize].y > 0.0;
            covered += inside as u32;
            if hit != inside {
                wrong.push((i, j, inside));
            }
        }
    }
    assert!(
        covered > size * size / 20,
        "the polygon fills part of the image"
    );
    assert!(skipped <= 2, "{skipped} pixels on the outline");
    assert!(
        wrong.is_empty(),
        "{} pixels wrong: {:?}",
        wrong.len(),
        &wrong[..wrong.len().min(10)]
    );
}

fn star(points: usize, outer: f64, inner: f64) -> Vec<DVec3> {
    (0..2 * points)
        .map(|k| {
            let a = std::f64::consts::PI * k as f64 / points as f64 + 0.1;
            let r = if k % 2 == 0 { outer } else { inner };
            DVec3::new(r * a.cos(), r * a.sin(), 0.0)
        })
        .collect()
}

/// The first 144-vertex gear face of the SPD's gears, moved to z = 0 and
/// centred: 36 teeth, concave between every two.
fn gear_face() -> Vec<DVec3> {
    let text = std::fs::read_to_string(repo_path("scenes/spd/gears.nff")).unwrap();
    let mut lines = text.lines();
    while let Some(line) = lines.next() {
        if line.trim() == "p 144" {
            let points: Vec<DVec3> = (0..144)
                .map(|_| {
                    let v: Vec<f64> = lines
                        .next()
                        .unwrap()
                        .split_whitespace()
                        .map(|x| x.parse().unwrap())
                        .collect();
                    DVec3::new(v[0], v[1], v[2])
                })
                .collect();
            let centre = points.iter().copied().sum::<DVec3>() / 144.0;
            let scale = points
                .iter()
                .map(|p| (*p - centre).length())
                .fold(0.0, f64::max);
            return points
                .iter()
                .map(|p| (*p - centre).with_z(0.0) * (2.0 / scale))
                .collect();
        }
    }
    panic!("gears.nff has no 144-vertex face");
}

#[test]
fn star_is_filled_exactly_head_on_and_at_a_slant() {
    let s = star(5, 2.0, 0.8);
    let reversed: Vec<DVec3> = s.iter().rev().copied().collect();
    for eye in [DVec3::new(0.0, 0.0, 7.0), DVec3::new(3.0, -2.5, 5.0)] {
        assert_exact_coverage(&s, eye, 96);
        assert_exact_coverage(&reversed, eye, 96);
    }
}

#[test]
fn gear_face_keeps_its_teeth_head_on_and_at_a_slant() {
    let gear = gear_face();
    for eye in [DVec3::new(0.0, 0.0, 7.0), DVec3::new(-2.0, 3.0, 5.0)] {
        assert_exact_coverage(&gear, eye, 160);
    }
}

#[test]
fn polygons_that_are_not_simple_are_dropped_and_counted() {
    let bow_tie = [
        DVec3::new(-1.0, -1.0, 0.0),
        DVec3::new(1.0, 1.0, 0.0),
        DVec3::new(1.0, -1.0, 0.0),
        DVec3::new(-1.0, 1.0, 0.0),
    ];
    let mut text = nff_with_polygon(DVec3::new(0.0, 0.0, 5.0), &bow_tie, 8);
    text.push_str("p 3\n0 0 0\n1 0 0\n2 0 0\n");
    let scene = scene_from(&text, "defects.nff");
    assert_eq!(scene.shapes.len(), 0);
    assert_eq!(
        (
            scene.dropped_polygons.not_simple,
            scene.dropped_polygons.zero_area
        ),
        (1, 1)
    );
}

// ---------------------------------------------------------------------
// Octree torture scenes: built within budget, and rendering exactly what
// brute force renders.

/// A small deterministic generator, so the scenes are the same everywhere.
struct Lcg(u64);

impl Lcg {
    fn next(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }

    fn unit(&mut self) -> DVec3 {
        loop {
            let v = DVec3::new(self.next(), self.next(), self.next()) * 2.0 - DVec3::ONE;
            let l = v.length();
            if l > 0.1 && l <= 1.0 {
                return v / l;
            }
        }
    }
}

const HEAD: &str = "v\nfrom 0 -60 25\nat 0 0 0\nup 0 0 1\nangle 45\nhither 1\nresolution 40 40\n\
                    l 40 -40 60\nl -30 -20 50\nf 0.9 0.5 0.3 0.7 0.3 20 0 1\n";

fn chained_spheres(n: usize) -> String {
    let mut rng = Lcg(1);
    let mut s = String::from(HEAD);
    let mut c = DVec3::ZERO;
    for _ in 0..n {
        // Radii over four orders of magnitude, each centred on the last one's surface.
        let r = 10f64.powf(-2.0 + 4.0 * rng.next());
        s.push_str(&format!("s {} {} {} {r}\n", c.x, c.y, c.z));
        c = (c + rng.unit() * r).clamp(DVec3::splat(-30.0), DVec3::splat(30.0));
    }
    s
}

fn nested_spheres(n: usize) -> String {
    let mut s = String::from(HEAD);
    for k in 0..n {
        s.push_str(&format!(
            "s 0 0 0 {}\n",
            10f64.powf(-2.0 + 4.0 * k as f64 / n as f64)
        ));
    }
    s
}

/// Spheres on a logarithmic spiral, each far larger than the step to the
/// next, so each overlaps hundreds of its neighbours: the layout of the
/// SPD generator's `shells`.
fn spiral_shells(n: usize) -> String {
    let mut s = String::from(HEAD);
    for k in 0..n {
        let r = 0.0035 * (k as f64 / n as f64 * 4800f64.ln()).exp();
        let angle = k as f64 * std::f64::consts::TAU / 720.0;
        s.push_str(&format!(
            "s {} {} {} {r}\n",
            r * angle.cos(),
            r * angle.sin(),
            -2.0 * r
        ));
    }
    s
}

/// Issue 38: the default octree must not cost more than no octree. On
/// nested, overlapping spheres, splitting until the memory budget (what
/// the default did before the cost-driven stop) took 2.3 s where brute
/// force took 0.6 s; the default tree stays far from the budget.
#[test]
fn the_default_octree_stops_splitting_overlapping_shells_early() {
    let n = 1441;
    let scene = scene_from(&spiral_shells(n), "shells.nff");
    let default = Octree::build(&scene.shapes, OctreeParams::default())
        .unwrap()
        .stats();
    let unstopped = OctreeParams {
        cost_driven: false,
        ..OctreeParams::default()
    };
    let unstopped = Octree::build(&scene.shapes, unstopped).unwrap().stats();
    eprintln!("shells: default {default:?}\nwithout the stop {unstopped:?}");
    assert_eq!(default.leaves_stopped_by_budget, 0);
    // Measured: 166,455 references (115 per sphere) in 43,529 nodes.
    assert!(
        default.references < 200 * n as u64,
        "{} references",
        default.references
    );
    // Without the stop the same scene fills the budget (8.3 M references;
    // the case the default exists to avoid: if this stops holding, the
    // test above no longer shows anything).
    assert!(unstopped.leaves_stopped_by_budget > 0, "{unstopped:?}");
}

fn coincident_triangles(n: usize) -> String {
    let mut s = String::from(HEAD);
    s.push_str("f 0.5 0.7 1 0.6 0.2 30 0.5 1.3\n");
    for _ in 0..n {
        s.push_str("p 3\n-10 0 -5\n10 0 -5\n0 0 15\n");
    }
    s
}

fn huge_among_tiny(n: usize) -> String {
    let mut rng = Lcg(2);
    let mut s = String::from(HEAD);
    s.push_str("p 3\n-1e4 5 -1e4\n1e4 5 -1e4\n0 5 1e4\n");
    for _ in 0..n {
        let p = (DVec3::new(rng.next(), rng.next(), rng.next()) - 0.5) * 40.0;
        s.push_str("p 3\n");
        for _ in 0..3 {
            let v = p + (DVec3::new(rng.next(), rng.next(), rng.next()) - 0.5) * 2e-3;
            s.push_str(&format!("{} {} {}\n", v.x, v.y, v.z));
        }
    }
    s
}

fn through_one_point(n: usize) -> String {
    let mut rng = Lcg(3);
    let mut s = String::from(HEAD);
    for k in 0..n {
        let r = 10f64.powf(-1.0 + 2.5 * rng.next());
        let d = rng.unit();
        if k % 2 == 0 {
            let c = d * r;
            s.push_str(&format!("s {} {} {} {r}\n", c.x, c.y, c.z));
        } else {
            let (e, f) = (rng.unit() * r, rng.unit() * r);
            s.push_str(&format!(
                "p 3\n0 0 0\n{} {} {}\n{} {} {}\n",
                e.x, e.y, e.z, f.x, f.y, f.z
            ));
        }
    }
    s
}

/// Builds with `params`, checks the budget held, and renders octree on and
/// off (shaded, with shadows and reflections) at 40x40: byte-identical.
fn assert_bounded_and_exact(name: &str, text: &str, params: OctreeParams) {
    let mut scene = scene_from(text, &format!("{name}.nff"));
    scene.octree_params = params;
    let octree = std::sync::Arc::new(
        Octree::build(&scene.shapes, params).unwrap_or_else(|e| panic!("{name}: {e}")),
    );
    let stats = octree.stats();
    assert!(
        stats.memory_bytes <= stats.memory_budget_bytes,
        "{name}: {} bytes over a budget of {}",
        stats.memory_bytes,
        stats.memory_budget_bytes
    );
    let (on, counts) = render_with(&scene, &octree, 40, 40, |s| s.accel = Accel::Octree);
    let (off, _) = render_with(&scene, &octree, 40, 40, |s| s.accel = Accel::BruteForce);
    assert_eq!(counts.nonfinite_samples, 0, "{name}");
    assert!(on == off, "{name}: octree on and off differ");
    eprintln!(
        "{name}: {} shapes, {} nodes, {} references, {} KiB of {} KiB, {} leaves stopped by the budget, {} by duplication",
        scene.shapes.len(),
        stats.nodes,
        stats.references,
        stats.memory_bytes / 1024,
        stats.memory_budget_bytes / 1024,
        stats.leaves_stopped_by_budget,
        stats.leaves_stopped_by_duplication
    );
}

#[test]
fn torture_scenes_build_within_budget_and_render_like_brute_force() {
    let scenes = [
        ("chained_spheres", chained_spheres(1500)),
        ("nested_spheres", nested_spheres(1500)),
        ("coincident_triangles", coincident_triangles(1500)),
        ("huge_among_tiny", huge_among_tiny(1500)),
        ("through_one_point", through_one_point(1500)),
    ];
    for (name, text) in &scenes {
        // The default budget, and one small enough to bind on every scene
        // that would use more.
        assert_bounded_and_exact(name, text, OctreeParams::default());
        let tight = OctreeParams {
            memory_budget_mib: 1,
            ..OctreeParams::default()
        };
        assert_bounded_and_exact(name, text, tight);
        // The BVH on the same scenes: the same pixels, one reference per
        // shape, and a depth the median splits keep logarithmic.
        let scene = scene_from(text, &format!("{name}.nff"));
        let octree =
            std::sync::Arc::new(Octree::build(&scene.shapes, OctreeParams::default()).unwrap());
        let bvh = glint::accel::Bvh::build(&scene.shapes);
        let stats = bvh.stats();
        assert!(stats.references <= scene.shapes.len() as u64, "{name}");
        assert!(
            stats.max_depth <= 64,
            "{name}: BVH depth {}",
            stats.max_depth
        );
        let (brute, _) = render_with(&scene, &octree, 40, 40, |s| s.accel = Accel::BruteForce);
        let mut settings = scene.render_settings();
        (settings.width, settings.height) = (40, 40);
        settings.accel = glint::settings::Accel::Bvh;
        let accel = crate::common::accelerator(&scene, &settings, Some(&octree));
        let renderer = glint::render::Renderer::new(&scene, &accel, settings).unwrap();
        let through_bvh = renderer.render(false, None).0.to_rgb8();
        assert!(
            through_bvh == brute,
            "{name}: the BVH and brute force differ"
        );
        eprintln!("{name}: BVH {stats:?}");
    }
}

#[test]
fn coincident_triangles_stop_splitting_instead_of_multiplying() {
    let scene = scene_from(&coincident_triangles(1000), "coincident.nff");
    // Without the cost-driven stop (the default's stops first here): the
    // duplication rule alone must bound the tree.
    let params = OctreeParams {
        cost_driven: false,
        ..OctreeParams::default()
    };
    let octree = std::sync::Arc::new(Octree::build(&scene.shapes, params).unwrap());
    let stats = octree.stats();
    eprintln!("coincident triangles: {stats:?}");
    // Inside the triangle, a split only copies every reference into each
    // child: two levels of that and the nodes stay leaves. Only along the
    // triangle's edges do cells keep shrinking (towards empty space), so
    // the references grow with the edges' length in cells, not their area.
    assert!(stats.leaves_stopped_by_duplication > 0);
    assert_eq!(stats.leaves_stopped_by_budget, 0);
    // Refinement over the triangle's area to depth 10 would need about
    // 4^10 / 2 cells of 1,000 references each; measured: 28 leaves hold
    // references (checked with a margin).
    assert!(
        stats.references < 1000 * 100,
        "{} references",
        stats.references
    );
    // All 1,000 are hit at the same distance: the tie goes to the lowest
    // index, whichever leaf the walk finds them in.
    let prims = glint::accel::Primitives::opaque(&scene.shapes);
    let ray = glint::shapes::PreparedRay::new(glint::math::Ray::new(
        DVec3::new(0.5, 1.0, 0.5),
        -DVec3::Y,
    ));
    let hit = octree
        .closest(
            &prims,
            &ray,
            f64::INFINITY,
            &mut glint::accel::WalkStack::default(),
            &mut glint::stats::NoCounts,
        )
        .unwrap();
    assert_eq!(
        (hit.shape, hit.hit.t),
        (0, 1.0),
        "ties go to the lowest index"
    );
}

#[test]
fn tree_is_the_same_for_any_number_of_threads() {
    let scene = scene_from(&chained_spheres(800), "chain.nff");
    let params = OctreeParams {
        memory_budget_mib: 2,
        ..OctreeParams::default()
    };
    let build = |threads| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        let tree = pool.install(|| Octree::build(&scene.shapes, params).unwrap());
        (tree.stats(), tree.cells(glint::limits::MAX_OCTREE_DEPTH))
    };
    let one = build(1);
    assert!(one.0.leaves_stopped_by_budget > 0, "the budget binds");
    assert!(one == build(3), "the tree depends on the thread count");
}

// ---------------------------------------------------------------------
// Shadows through glass: once per surface crossed, whatever the shape.

/// A unit icosphere (icosahedron subdivided `levels` times, vertices
/// projected on the sphere) as NFF triangles, outward winding.
fn icosphere(levels: u32, centre: DVec3) -> String {
    let t = (1.0 + 5f64.sqrt()) / 2.0;
    let mut v: Vec<DVec3> = [
        (-1.0, t, 0.0),
        (1.0, t, 0.0),
        (-1.0, -t, 0.0),
        (1.0, -t, 0.0),
        (0.0, -1.0, t),
        (0.0, 1.0, t),
        (0.0, -1.0, -t),
        (0.0, 1.0, -t),
        (t, 0.0, -1.0),
        (t, 0.0, 1.0),
        (-t, 0.0, -1.0),
        (-t, 0.0, 1.0),
    ]
    .iter()
    .map(|&(x, y, z)| DVec3::new(x, y, z).normalize())
    .collect();
    let mut faces: Vec<[usize; 3]> = vec![
        [0, 11, 5],
        [0, 5, 1],
        [0, 1, 7],
        [0, 7, 10],
        [0, 10, 11],
        [1, 5, 9],
        [5, 11, 4],
        [11, 10, 2],
        [10, 7, 6],
        [7, 1, 8],
        [3, 9, 4],
        [3, 4, 2],
        [3, 2, 6],
        [3, 6, 8],
        [3, 8, 9],
        [4, 9, 5],
        [2, 4, 11],
        [6, 2, 10],
        [8, 6, 7],
        [9, 8, 1],
    ];
    for _ in 0..levels {
        let mut cache = std::collections::HashMap::new();
        let mut mid = |a: usize, b: usize, v: &mut Vec<DVec3>| {
            *cache.entry((a.min(b), a.max(b))).or_insert_with(|| {
                v.push((v[a] + v[b]).normalize());
                v.len() - 1
            })
        };
        faces = faces
            .iter()
            .flat_map(|&[a, b, c]| {
                let (ab, bc, ca) = (mid(a, b, &mut v), mid(b, c, &mut v), mid(c, a, &mut v));
                [[a, ab, ca], [b, bc, ab], [c, ca, bc], [ab, bc, ca]]
            })
            .collect();
    }
    let mut s = String::new();
    for f in faces {
        s.push_str("p 3\n");
        for i in f {
            let p = centre + v[i];
            s.push_str(&format!("{:.17} {:.17} {:.17}\n", p.x, p.y, p.z));
        }
    }
    s
}

/// Transmittance of the shadow ray from the floor point below a glass body
/// to a light above it, through the body's centre (it enters and leaves):
/// read from the ray tree of the image's centre pixel, whose ray goes
/// exactly to `lookat`, the floor point.
fn through(glass: &str, light_x: f64) -> f64 {
    // The floor point on the line from the light through the centre.
    let floor_x = -0.15 * light_x;
    let text = format!(
        "v\nfrom 0 -9 0.5\nat {floor_x} 0 -3\nup 0 0 1\nangle 20\nhither 1\nresolution 9 9\n\
         l {light_x} 0 20\nf 1 1 1 0.8 0 1 0 0\np 4\n-5 -5 -3\n5 -5 -3\n5 5 -3\n-5 5 -3\n\
         f 1 1 1 0.1 0 1 0.9 1.5\n{glass}"
    );
    let scene = scene_from(&text, "glass.nff");
    let octree = std::sync::Arc::new(scene.build_octree().unwrap());
    let mut settings = scene.render_settings();
    settings.max_depth = 1;
    let accel = crate::common::accelerator(&scene, &settings, Some(&octree));
    let renderer = Renderer::new(&scene, &accel, settings).unwrap();
    let tree = renderer.ray_tree(4, 4);
    let hit = tree.hit.as_ref().expect("the eye ray hits the floor");
    assert!((hit.point[2] + 3.0).abs() < 1e-9, "{:?}", hit.point);
    tree.shadows[0].transmittance
}

#[test]
fn glass_sphere_and_closed_glass_mesh_cast_the_same_shadow() {
    let t2 = 0.9 * 0.9;
    // Straight above, the shadow ray leaves the icosphere through vertices
    // shared by six triangles; off the axis, through faces.
    for light_x in [0.0, 3.0] {
        let sphere = through("s 0 0 0 1\n", light_x);
        let mesh = through(&icosphere(3, DVec3::ZERO), light_x);
        assert!((sphere - t2).abs() < 1e-12, "sphere {sphere}");
        assert!((mesh - t2).abs() < 1e-12, "mesh {mesh}");
    }
}

#[test]
fn coincident_glass_faces_count_once() {
    // The top and bottom of a box, each given twice; the shadow ray goes
    // through their centres, on the diagonal both triangles share.
    let faces = "p 4\n-1 -1 1\n1 -1 1\n1 1 1\n-1 1 1\np 4\n-1 -1 -1\n-1 1 -1\n1 1 -1\n1 -1 -1\n";
    let twice = through(&format!("{faces}{faces}"), 0.0);
    assert!((twice - 0.81).abs() < 1e-12, "{twice}");
}

// ---------------------------------------------------------------------
// Records of large scenes stay readable by every PNG reader.

/// Every standard text chunk (tEXt, zTXt, iTXt) of a PNG, decompressed.
fn text_chunks(png: &[u8]) -> Vec<(String, usize)> {
    use std::io::Read;
    let mut out = Vec::new();
    let mut pos = 8;
    while pos + 8 <= png.len() {
        let n = u32::from_be_bytes(png[pos..pos + 4].try_into().unwrap()) as usize;
        let kind = &png[pos + 4..pos + 8];
        let data = &png[pos + 8..pos + 8 + n];
        let keyword_end = data.iter().position(|&b| b == 0).unwrap_or(0);
        let keyword = String::from_utf8_lossy(&data[..keyword_end]).into_owned();
        let size = match kind {
            b"tEXt" => n - keyword_end - 1,
            b"zTXt" => {
                let mut text = Vec::new();
                flate2::read::ZlibDecoder::new(&data[keyword_end + 2..])
                    .read_to_end(&mut text)
                    .unwrap();
                text.len()
            }
            b"iTXt" => {
                let compressed = data[keyword_end + 1] == 1;
                // Skip the flag, method, language tag and translated keyword.
                let mut rest = &data[keyword_end + 3..];
                for _ in 0..2 {
                    let z = rest.iter().position(|&b| b == 0).unwrap();
                    rest = &rest[z + 1..];
                }
                if compressed {
                    let mut text = Vec::new();
                    flate2::read::ZlibDecoder::new(rest)
                        .read_to_end(&mut text)
                        .unwrap();
                    text.len()
                } else {
                    rest.len()
                }
            }
            _ => {
                pos += 12 + n;
                continue;
            }
        };
        out.push((keyword, size));
        pos += 12 + n;
    }
    out
}

#[test]
fn records_of_large_scenes_keep_standard_text_chunks_small() {
    // gears.nff is 1.3 MB of text, past the 1 MB text-chunk limit of common readers.
    let path = repo_path("scenes/spd/gears.nff");
    let scene = glint::scene::load(&path).unwrap();
    assert!(scene.source_text.len() > 1 << 20);
    let octree = std::sync::Arc::new(scene.build_octree().unwrap());
    let mut settings = scene.render_settings();
    (settings.width, settings.height) = (8, 8);
    let accel = crate::common::accelerator(&scene, &settings, Some(&octree));
    let renderer = Renderer::new(&scene, &accel, settings).unwrap();
    let (frame, _) = renderer.render(false, None);
    let record = glint::export::RenderRecord::new(
        &scene,
        &path.display().to_string(),
        &scene.camera,
        settings,
    );
    let tmp = common::temp_dir();
    let dir = tmp.path();
    let png = dir.join("gears.png");
    glint::export::save_png(&frame, &png, Some(&record)).unwrap();
    let bytes = std::fs::read(&png).unwrap();
    let chunks = text_chunks(&bytes);
    assert!(
        chunks.iter().any(|(k, _)| k == "glint:settings"),
        "{chunks:?}"
    );
    for (keyword, size) in &chunks {
        assert!(
            *size <= 1 << 20,
            "text chunk {keyword} decompresses to {size} bytes"
        );
    }
    // The scene is still all there, for --from-png and glint info.
    let read = glint::export::read_record(&png).unwrap();
    assert_eq!(read.scene_text, &*scene.source_text);
    assert_eq!(read, record);
    // And a reader that does not know glint still decodes the image.
    assert_eq!(image::open(&png).unwrap().to_rgb8().dimensions(), (8, 8));
}
