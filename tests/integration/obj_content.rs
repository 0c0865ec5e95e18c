//! OBJ content as users bring it: MTL materials, an .obj opened directly,
//! f64 coordinates far from the origin, smooth terminators, and the quirks
//! of exporters. Every expected value is independent of the loader: known
//! colours at known pixels, an analytic sphere, the same mesh placed by
//! TOML.

use crate::common;

use std::path::Path;

use common::{render_with, scene_from, temp_dir};
use glint::scene::Scene;

pub(crate) fn write(dir: &Path, name: &str, bytes: &[u8]) {
    std::fs::write(dir.join(name), bytes).unwrap();
}

pub(crate) fn load_file(path: &Path) -> Scene {
    glint::scene::load(path).unwrap_or_else(|e| panic!("{e}"))
}

pub(crate) fn render(scene: &Scene, w: u32, h: u32, samples: u32) -> Vec<u8> {
    let octree = std::sync::Arc::new(scene.build_octree().unwrap());
    render_with(scene, &octree, w, h, |s| s.samples = samples).0
}

pub(crate) fn pixel(image: &[u8], width: u32, x: u32, y: u32) -> [u8; 3] {
    let i = ((y * width + x) * 3) as usize;
    [image[i], image[i + 1], image[i + 2]]
}

/// A TOML scene looking down -z at the unit square [-1, 1]^2, lit from the
/// camera, around the mesh `obj` (with `extra` keys on the mesh object).
pub(crate) fn facing_scene(obj: &str, extra: &str) -> String {
    format!(
        "[camera]\neye = [0, 0, 3]\nlookat = [0, 0, 0]\nup = [0, 1, 0]\nfov = 60\n\
         [image]\nwidth = 40\nheight = 40\nsamples = 1\nmax_depth = 4\n\
         background = [0, 0, 0]\nambient = [0, 0, 0]\n\
         [[lights]]\nposition = [0, 0, 3]\n\
         [[objects]]\nkind = \"mesh\"\npath = \"{obj}\"\n{extra}"
    )
}

const TWO_QUADS: &str = "mtllib two.mtl\n\
v -1 -1 0\nv 0 -1 0\nv 0 1 0\nv -1 1 0\nv 1 -1 0\nv 1 1 0\n\
usemtl left\nf 1 2 3 4\nusemtl right\nf 2 5 6 3\n";

#[test]
fn each_face_gets_its_mtl_colour() {
    let dir = temp_dir();
    write(dir.path(), "two.obj", TWO_QUADS.as_bytes());
    write(
        dir.path(),
        "two.mtl",
        b"newmtl left\nKd 1 0 0\nillum 1\nnewmtl right\nKd 0 1 0\nillum 1\n",
    );
    let toml = dir.path().join("scene.toml");
    std::fs::write(&toml, facing_scene("two.obj", "")).unwrap();
    let scene = load_file(&toml);
    let image = render(&scene, 40, 40, 1);
    let left = pixel(&image, 40, 10, 20);
    let right = pixel(&image, 40, 30, 20);
    assert!(
        left[0] > 200 && left[1] == 0 && left[2] == 0,
        "left {left:?}"
    );
    assert!(
        right[1] > 200 && right[0] == 0 && right[2] == 0,
        "right {right:?}"
    );
    // `material = ...` overrides the file's materials, as before.
    let overridden = facing_scene("two.obj", "material = \"grey\"\n")
        + "[materials.grey]\ncolor = [0.5, 0.5, 0.5]\n";
    std::fs::write(&toml, overridden).unwrap();
    let image = render(&load_file(&toml), 40, 40, 1);
    // Pixel centres 9.5 and 30.5 mirror each other about the axis.
    assert_eq!(pixel(&image, 40, 9, 20), pixel(&image, 40, 30, 20));
}

#[test]
fn an_obj_opens_directly_and_missing_materials_are_said() {
    let dir = temp_dir();
    write(dir.path(), "two.obj", TWO_QUADS.as_bytes());
    write(
        dir.path(),
        "two.mtl",
        b"newmtl left\nKd 1 0 0\nmap_Kd wood.png\n",
    );
    let scene = load_file(&dir.path().join("two.obj"));
    let names: Vec<&str> = scene.materials.iter().map(|m| m.name.as_str()).collect();
    assert_eq!(names, ["left", "default"]);
    // The texture the MTL names is not there: said, with what stands in.
    assert!(scene.not_rendered.is_empty(), "{:?}", scene.not_rendered);
    assert_eq!(scene.load_notes.len(), 2, "{:?}", scene.load_notes);
    let notes = scene.load_notes.join("\n");
    assert!(
        notes.contains("texture `wood.png` (map_Kd) cannot be read: no such file")
            && notes.contains("material `left` is drawn in its own `Kd` colour")
            && notes.contains("`right`"),
        "{notes}"
    );
    // The framing camera sees the whole model: no corner of the image is
    // the model, the centre is.
    let image = render(&scene, 64, 48, 1);
    let background = pixel(&image, 64, 0, 0);
    assert_ne!(pixel(&image, 64, 32, 24), background);
}

/// A mirror (illum 3) in front of a red wall, a glass pane (illum 7)
/// before a green one: the mirror shows red, the glass lets green through.
#[test]
fn mirror_and_glass_by_illum() {
    let dir = temp_dir();
    // The camera looks down -z at a mirror (left) and a pane of glass
    // (right); a red wall stands behind the camera, a green one behind
    // the panes.
    write(
        dir.path(),
        "room.obj",
        b"mtllib room.mtl\n\
          v -1 -1 0\nv 0 -1 0\nv 0 1 0\nv -1 1 0\n\
          v 0 -1 0\nv 1 -1 0\nv 1 1 0\nv 0 1 0\n\
          v -10 -10 6\nv 10 -10 6\nv 10 10 6\nv -10 10 6\n\
          v -10 -10 -2\nv 10 -10 -2\nv 10 10 -2\nv -10 10 -2\n\
          usemtl mirror\nf 1 2 3 4\nusemtl glass\nf 5 6 7 8\n\
          usemtl red\nf 9 10 11 12\nusemtl green\nf 13 14 15 16\n",
    );
    write(
        dir.path(),
        "room.mtl",
        b"newmtl mirror\nKd 0 0 0\nKs 1 1 1\nillum 3\n\
          newmtl glass\nKd 0 0 0\nKs 0 0 0\nNi 1.0\nd 0\nillum 7\n\
          newmtl red\nKd 1 0 0\nillum 1\n\
          newmtl green\nKd 0 1 0\nillum 1\n",
    );
    let toml = dir.path().join("scene.toml");
    std::fs::write(
        &toml,
        facing_scene("room.obj", "").replace("position = [0, 0, 3]", "position = [0, 0, 2.5]"),
    )
    .unwrap();
    let scene = load_file(&toml);
    let image = render(&scene, 40, 40, 1);
    let mirror = pixel(&image, 40, 10, 20);
    let glass = pixel(&image, 40, 30, 20);
    // (The mirror's Ks also gives it a faint white highlight.)
    assert!(
        mirror[0] > 100 && mirror[0] > 4 * mirror[1],
        "mirror {mirror:?}"
    );
    assert!(glass[1] > 100 && glass[1] > 4 * glass[0], "glass {glass:?}");
}

/// The same mesh written 1e6 from the origin, and written at the origin
/// but moved 1e6 by `translate`: f64 coordinates give the same picture
/// (f32 would have merged vertices a few millimetres apart).
#[test]
fn far_from_the_origin_in_the_file_equals_far_by_translate() {
    let dir = temp_dir();
    let offset = 1.0e6;
    let mut near = String::new();
    let mut far = String::new();
    // A fine zig-zag strip: vertices 0.01 apart.
    for i in 0..=100 {
        let x = -0.5 + i as f64 * 0.01;
        let y = if i % 2 == 0 { -0.5 } else { 0.5 };
        near += &format!("v {x} {y} {}\n", 0.1 * (i as f64 * 0.3).sin());
        far += &format!("v {} {} {}\n", x + offset, y, 0.1 * (i as f64 * 0.3).sin());
    }
    for i in 1..100 {
        let f = format!("f {} {} {}\n", i, i + 1, i + 2);
        near += &f;
        far += &f;
    }
    write(dir.path(), "near.obj", near.as_bytes());
    write(dir.path(), "far.obj", far.as_bytes());
    let camera = |x: f64| {
        format!(
            "[camera]\neye = [{x}, 0.3, 1.5]\nlookat = [{x}, 0, 0]\nup = [0, 1, 0]\nfov = 50\n\
             [image]\nwidth = 64\nheight = 64\nsamples = 1\nbackground = [0, 0, 0]\n\
             [materials.m]\ncolor = [0.8, 0.7, 0.6]\n[[lights]]\nposition = [{}, 2, 2]\n",
            x + 0.5
        )
    };
    let by_file =
        camera(offset) + "[[objects]]\nkind = \"mesh\"\nmaterial = \"m\"\npath = \"far.obj\"\n";
    let by_translate = camera(offset)
        + &format!(
            "[[objects]]\nkind = \"mesh\"\nmaterial = \"m\"\npath = \"near.obj\"\ntranslate = [{offset}, 0, 0]\n"
        );
    std::fs::write(dir.path().join("a.toml"), by_file).unwrap();
    std::fs::write(dir.path().join("b.toml"), by_translate).unwrap();
    let a = load_file(&dir.path().join("a.toml"));
    let b = load_file(&dir.path().join("b.toml"));
    assert_eq!(a.shapes.len(), 99);
    assert_eq!(a.dropped_triangles, 0);
    let (ia, ib) = (render(&a, 64, 64, 1), render(&b, 64, 64, 1));
    let (differing, largest) = common::diff(&ia, &ib, 1);
    assert_eq!(differing, 0, "largest difference {largest}");
    assert!(ia.chunks(3).filter(|p| p != &[0, 0, 0]).count() > 500);
}

/// A UV sphere with exact vertex normals shades like the analytic sphere
/// away from its silhouette, terminator included: no facet steps.
#[test]
fn a_tessellated_sphere_shades_like_the_analytic_sphere() {
    let (lat, lon) = (24, 48);
    let mut obj = String::new();
    for i in 0..=lat {
        let theta = std::f64::consts::PI * i as f64 / lat as f64;
        for j in 0..lon {
            let phi = std::f64::consts::TAU * j as f64 / lon as f64;
            let p = [
                theta.sin() * phi.cos(),
                theta.cos(),
                theta.sin() * phi.sin(),
            ];
            obj += &format!(
                "v {} {} {}\nvn {} {} {}\n",
                p[0], p[1], p[2], p[0], p[1], p[2]
            );
        }
    }
    let at = |i: usize, j: usize| i * lon + j % lon + 1;
    for i in 0..lat {
        for j in 0..lon {
            let (a, b, c, d) = (at(i, j), at(i, j + 1), at(i + 1, j + 1), at(i + 1, j));
            if i > 0 {
                obj += &format!("f {a}//{a} {c}//{c} {b}//{b}\n");
            }
            if i + 1 < lat {
                obj += &format!("f {a}//{a} {d}//{d} {c}//{c}\n");
            }
        }
    }
    let dir = temp_dir();
    write(dir.path(), "sphere.obj", obj.as_bytes());
    let head = "[camera]\neye = [0, 0, 4]\nlookat = [0, 0, 0]\nup = [0, 1, 0]\nfov = 36\n\
                [image]\nwidth = 96\nheight = 96\nsamples = 1\nbackground = [0, 0, 0]\n\
                ambient = [0, 0, 0]\n[materials.m]\ncolor = [1, 1, 1]\nkd = 1\n\
                [[lights]]\nposition = [0.5, 10, -3]\n[[objects]]\nmaterial = \"m\"\n";
    let mesh = format!("{head}kind = \"mesh\"\npath = \"sphere.obj\"\n");
    let analytic = format!("{head}kind = \"sphere\"\ncenter = [0, 0, 0]\nradius = 1\n");
    std::fs::write(dir.path().join("mesh.toml"), mesh).unwrap();
    let a = render(&load_file(&dir.path().join("mesh.toml")), 96, 96, 1);
    let b = render(&scene_from(&analytic, "analytic.toml"), 96, 96, 1);
    // Inside 85 % of the projected radius (the tessellated outline differs
    // from the circle near it).
    let radius_px = 0.25f64.asin().tan() / 18f64.to_radians().tan() * 48.0 * 0.85;
    let (mut worst, mut compared, mut over_4) = (0u8, 0, 0);
    for y in 0..96u32 {
        for x in 0..96u32 {
            let (dx, dy) = (x as f64 + 0.5 - 48.0, y as f64 + 0.5 - 48.0);
            if (dx * dx + dy * dy).sqrt() > radius_px {
                continue;
            }
            compared += 1;
            let (pa, pb) = (pixel(&a, 96, x, y), pixel(&b, 96, x, y));
            let d = (0..3).map(|k| pa[k].abs_diff(pb[k])).max().unwrap();
            worst = worst.max(d);
            over_4 += usize::from(d > 4);
        }
    }
    assert!(compared > 2000, "{compared} pixels compared");
    // Shadow rays from the facets (the rule before Hanika's) left steps of
    // up to 65/255 at the terminator, 34 pixels over 4; interpolated normals
    // of a 24 x 48 sphere differ from exact ones by a few levels, which
    // sRGB magnifies in the dark (measured: 8 at most, 7 pixels over 4).
    assert!(worst <= 10, "largest difference {worst}/255");
    assert!(over_4 <= 12, "{over_4} pixels differ by more than 4/255");
}

#[test]
fn lines_points_and_short_faces_add_nothing_and_are_counted() {
    let dir = temp_dir();
    let obj = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
               l 1 2 3 4 1\nl 1 3\np 2\nf 1 2\nf 1 1 2\nf 1 2 3\n";
    write(dir.path(), "lines.obj", obj.as_bytes());
    let scene = load_file(&dir.path().join("lines.obj"));
    assert_eq!(scene.shapes.len(), 1);
    let s = &scene.skipped_elements;
    assert_eq!((s.lines, s.points, s.short_faces), (2, 1, 2));
    // `f 1 1 2` is one short face, not also a face with a repeat.
    assert_eq!(s.faces_with_repeated_vertices, 0);
    write(dir.path(), "only_lines.obj", b"v 0 0 0\nv 1 0 0\nl 1 2\n");
    let e = glint::scene::load(&dir.path().join("only_lines.obj")).unwrap_err();
    assert!(e.to_string().contains("no faces"), "{e}");
}

#[test]
fn a_face_listing_its_corners_many_times_is_one_quad() {
    let dir = temp_dir();
    let corners = " 1 2 3 4".repeat(234);
    let obj = format!("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf{corners}\n");
    write(dir.path(), "quad.obj", obj.as_bytes());
    let scene = load_file(&dir.path().join("quad.obj"));
    assert_eq!(scene.shapes.len(), 2);
    let octree = std::sync::Arc::new(scene.build_octree().unwrap());
    assert!(octree.stats().references < 100, "{:?}", octree.stats());
}

#[test]
fn exporter_quirks_load() {
    let dir = temp_dir();
    // A Latin-1 material name, an empty usemtl (Blender 2.6), `w` on `v`,
    // CRLF line ends.
    let mut obj = b"mtllib q.mtl\r\nv 0 0 0 1\r\nv 1 0 0 2\r\nv 0 1 0 0.5\r\nusemtl caf\xe9\r\nf 1 2 3\r\nusemtl\r\nf 1 3 2\r\n".to_vec();
    obj.extend_from_slice(b"# end\r\n");
    write(dir.path(), "q.obj", &obj);
    write(dir.path(), "q.mtl", b"newmtl caf\xe9\r\nKd 0.2 0.4 0.6\r\n");
    let scene = load_file(&dir.path().join("q.obj"));
    assert_eq!(scene.shapes.len(), 2);
    let mut names: Vec<&str> = scene.materials.iter().map(|m| m.name.as_str()).collect();
    names.sort();
    assert_eq!(names, ["caf\u{fffd}", "default"]);
    assert!(scene.load_notes.is_empty(), "{:?}", scene.load_notes);
    // `w` is not a divisor: the second vertex stays at x = 1.
    let bounds = scene.geometry_bounds();
    assert_eq!(bounds.max.x, 1.0);
    // A bad number names the file and the line.
    write(
        dir.path(),
        "bad.obj",
        b"v 0 0 0\nv 1 0 0\nv 0 one 0\nf 1 2 3\n",
    );
    let e = glint::scene::load(&dir.path().join("bad.obj")).unwrap_err();
    let message = e.to_string();
    assert!(
        message.contains("bad.obj") && message.contains("line 3"),
        "{message}"
    );
}

/// A model is something people share: its `mtllib` lines read libraries
/// in the model's folder tree only, and a library that is no MTL file is
/// named, never quoted.
#[test]
fn material_libraries_stay_in_the_model_folder_and_are_never_quoted() {
    let tmp = temp_dir();
    let root = tmp.path();
    std::fs::create_dir(root.join("model")).unwrap();
    std::fs::create_dir(root.join("model/materials")).unwrap();
    write(root, "secret.txt", b"root:x:0:0:root:/root:/bin/bash\n");
    write(root, "model/notes.txt", b"private words here\n");
    write(root, "model/materials/red.mtl", b"newmtl red\nKd 1 0 0\n");
    let secret = root.join("secret.txt");
    let obj = format!(
        "mtllib ../secret.txt\nmtllib {}\nmtllib notes.txt\nmtllib materials/../materials/red.mtl\n\
         v -1 -1 0\nv 1 -1 0\nv 1 1 0\nusemtl red\nf 1 2 3\n",
        secret.display()
    );
    write(root, "model/m.obj", obj.as_bytes());
    let scene = load_file(&root.join("model/m.obj"));
    let notes = scene.notes().join("\n");
    assert!(!notes.contains("root:x"), "{notes}");
    assert!(!notes.contains("private words"), "{notes}");
    assert_eq!(
        notes.matches("points outside the model's folder").count(),
        2,
        "{notes}"
    );
    assert!(notes.contains("not an MTL file"), "{notes}");
    // The library inside the folder, reached through `..` that stays in
    // it, is read.
    let red = scene.materials.iter().find(|m| m.name == "red").unwrap();
    assert_eq!(red.color, glint::math::DVec3::new(1.0, 0.0, 0.0));
}

/// An OBJ whose faces all lack area is refused like one with no faces (it
/// rendered an empty picture with exit 0); one good face among them loads.
#[test]
fn an_obj_whose_faces_all_lack_area_is_refused_like_one_without_faces() {
    let tmp = temp_dir();
    let d = tmp.path();
    write(
        d,
        "flat.obj",
        b"v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\nf 1 1 2\nf 2 2 2 2\n",
    );
    let e = glint::scene::load(&d.join("flat.obj"))
        .unwrap_err()
        .to_string();
    assert!(e.contains("no face with an area"), "{e}");
    write(
        d,
        "some.obj",
        b"v 0 0 0\nv 1 0 0\nv 2 0 0\nv 0 1 0\nf 1 2 3\nf 1 2 4\n",
    );
    let scene = load_file(&d.join("some.obj"));
    assert_eq!(scene.shapes.len(), 1);
}

/// Windows tools' encodings read as their text: a UTF-8 byte-order mark
/// or UTF-16 (either byte order, with its mark) gives the same scene as
/// plain UTF-8, in the OBJ and in its MTL; MSVC's printed NaN is refused
/// with the file and line, not read as -1.
#[test]
fn byte_order_marks_utf16_and_msvc_nan() {
    let dir = temp_dir();
    write(dir.path(), "two.obj", TWO_QUADS.as_bytes());
    let mtl = "newmtl left\nKd 1 0 0\nillum 1\nnewmtl right\nKd 0 1 0\nillum 1\n";
    write(dir.path(), "two.mtl", mtl.as_bytes());
    let plain = load_file(&dir.path().join("two.obj"));
    let utf16 = |text: &str, big_endian: bool| {
        let mut bytes = if big_endian {
            vec![0xFE, 0xFF]
        } else {
            vec![0xFF, 0xFE]
        };
        for unit in text.encode_utf16() {
            bytes.extend(if big_endian {
                unit.to_be_bytes()
            } else {
                unit.to_le_bytes()
            });
        }
        bytes
    };
    let bom = |text: &str| [&[0xEF, 0xBB, 0xBF][..], text.as_bytes()].concat();
    for (obj, lib) in [
        (bom(TWO_QUADS), bom(mtl)),
        (utf16(TWO_QUADS, false), utf16(mtl, false)),
        (utf16(TWO_QUADS, true), utf16(mtl, true)),
    ] {
        write(dir.path(), "two.obj", &obj);
        write(dir.path(), "two.mtl", &lib);
        let scene = load_file(&dir.path().join("two.obj"));
        assert_eq!(scene.shapes, plain.shapes);
        assert_eq!(scene.materials, plain.materials);
        assert_eq!(scene.load_notes, plain.load_notes);
    }
    write(
        dir.path(),
        "nan.obj",
        b"v 0 0 0\nv 1 0 0\nv -1.#IND00 1 0\nf 1 2 3\n",
    );
    let message = glint::scene::load(&dir.path().join("nan.obj"))
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("nan.obj")
            && message.contains("line 3")
            && message.contains("`-1.#IND00` is not a number"),
        "{message}"
    );
    write(dir.path(), "two.obj", TWO_QUADS.as_bytes());
    write(dir.path(), "two.mtl", b"newmtl left\nKd 1.#QNAN 0 0\n");
    // A library that cannot be read is a note (its materials fall back to
    // the default), naming its file and line.
    let scene = load_file(&dir.path().join("two.obj"));
    assert!(
        scene.load_notes[0].contains("two.mtl: line 2: `1.#QNAN` is not a number"),
        "{:?}",
        scene.load_notes
    );
}

/// An NFF with a byte-order mark loads as without it; a file with nothing
/// of OBJ's (binary, another format) opened as `.obj` is named as not an
/// OBJ file, without quoting its content.
#[test]
fn an_nff_with_a_byte_order_mark_and_an_obj_that_is_none() {
    let dir = temp_dir();
    let nff = "b 0.1 0.2 0.3\nv\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 40\nhither 0.1\n\
               resolution 8 8\nl 1 1 1\nf 1 0 0 1 0 1 0 1\ns 0 0 0 1\n";
    write(dir.path(), "plain.nff", nff.as_bytes());
    write(
        dir.path(),
        "bom.nff",
        &[&[0xEF, 0xBB, 0xBF][..], nff.as_bytes()].concat(),
    );
    let (plain, bom) = (
        load_file(&dir.path().join("plain.nff")),
        load_file(&dir.path().join("bom.nff")),
    );
    assert_eq!(
        (bom.shapes, bom.materials, bom.image),
        (plain.shapes, plain.materials, plain.image)
    );
    write(
        dir.path(),
        "junk.obj",
        b"\x7fELF\x02\x01\x01\0\0\0secret: hunter2\n\x01\x02 x y\n",
    );
    let message = glint::scene::load(&dir.path().join("junk.obj"))
        .unwrap_err()
        .to_string();
    assert!(message.contains("junk.obj: not an OBJ file"), "{message}");
    assert!(!message.contains("hunter2"), "{message}");
}

/// An OBJ opened on its own is framed from its broad side, never edge-on:
/// a square in the plane x = 0 (which the camera looking along -z saw
/// edge-on, an empty picture) and a floor flat in y fill the middle of
/// the picture; a sheet facing the front is seen square on. A render in which
/// no eye ray hits anything says so.
#[test]
fn a_model_opened_on_its_own_is_seen_from_its_broad_side() {
    let dir = temp_dir();
    for (name, obj) in [
        (
            "wall_x.obj",
            "v 0 -1 -1\nv 0 1 -1\nv 0 1 1\nv 0 -1 1\nf 1 2 3 4\n",
        ),
        (
            "floor_y.obj",
            "v -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\nf 1 2 3 4\n",
        ),
        (
            "wall_z.obj",
            "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\nf 1 2 3 4\n",
        ),
    ] {
        write(dir.path(), name, obj.as_bytes());
        let scene = load_file(&dir.path().join(name));
        let image = render(&scene, 32, 32, 1);
        let background = pixel(&image, 32, 0, 0);
        assert_ne!(
            pixel(&image, 32, 16, 16),
            background,
            "{name}: the model is in view"
        );
        if name == "wall_z.obj" {
            // A sheet facing the front is seen square on.
            let d = (scene.camera.eye - scene.camera.lookat).normalize();
            assert_eq!(d, glint::math::DVec3::Z);
        }
    }
    let toml = dir.path().join("away.toml");
    std::fs::write(
        &toml,
        facing_scene("wall_z.obj", "").replace("lookat = [0, 0, 0]", "lookat = [0, 0, 9]"),
    )
    .unwrap();
    let png = dir.path().join("away.png");
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_glint"))
        .args([
            "render",
            toml.to_str().unwrap(),
            "-o",
            png.to_str().unwrap(),
        ])
        .output()
        .unwrap();
    assert!(out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("no eye ray hit anything"), "{err}");
}

/// A folded (self-crossing) quad is split into its two triangles and
/// said; a face still dropped is named by its line.
#[test]
fn folded_quads_are_split_and_dropped_faces_named_by_line() {
    let dir = temp_dir();
    write(
        dir.path(),
        "scan.obj",
        b"v 0 1 0\nv 0.588 -0.809 0\nv -0.951 0.309 0\nv 0.951 0.309 0\nv -0.588 -0.809 0\n\
          f 1 2 3 4\nf 1 2 3 4 5\n",
    );
    let scene = load_file(&dir.path().join("scan.obj"));
    assert_eq!(scene.shapes.len(), 2, "the folded quad's two triangles");
    let notes = scene.notes().join("\n");
    assert!(
        notes.contains("1 folded (self-crossing) quads split"),
        "{notes}"
    );
    assert!(
        notes.contains("scan.obj: faces dropped at line 7"),
        "{notes}"
    );
}

/// `--stats` counts the shapes by kind and, for each mesh file, the
/// triangles read beside what was split, dropped or skipped (a face is
/// counted once: `f 1 1 2` as short, not also as repeated).
#[test]
fn stats_count_shapes_by_kind_and_each_mesh() {
    let dir = temp_dir();
    write(
        dir.path(),
        "m.obj",
        b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nf 1 2 3 4\nf 1 1 2\nl 1 2\nf 1 2 2 3\n",
    );
    let toml = dir.path().join("s.toml");
    std::fs::write(
        &toml,
        facing_scene("m.obj", "")
            + "[[objects]]\nkind = \"sphere\"\nmaterial = \"grey\"\ncenter = [0, 0, -5]\n\
               radius = 1\n[materials.grey]\ncolor = [0.5, 0.5, 0.5]\n",
    )
    .unwrap();
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_glint"))
        .args(["render", toml.to_str().unwrap(), "-o"])
        .arg(dir.path().join("s.png"))
        .args(["--width", "8", "--height", "8", "--stats"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let stats: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(stats["shapes"]["triangle"], 3);
    assert_eq!(stats["shapes"]["sphere"], 1);
    let mesh = &stats["meshes"][0];
    assert!(mesh["path"].as_str().unwrap().ends_with("m.obj"));
    assert_eq!(mesh["triangles"], 3);
    assert_eq!(mesh["skipped_elements"]["short_faces"], 1);
    assert_eq!(mesh["skipped_elements"]["faces_with_repeated_vertices"], 1);
    assert_eq!(mesh["skipped_elements"]["lines"], 1);
}

/// Vertex colours (`v x y z r g b`) are the diffuse colour, interpolated
/// across each face in place of the material's: a quad red at its left
/// corners and blue at its right shows red on the left, blue on the
/// right, a mix between; the same colours written 0-255 render the same;
/// a colour that is not finite is refused with its line.
#[test]
fn vertex_colours_are_interpolated_as_the_diffuse_colour() {
    let dir = temp_dir();
    let quad = |scale: f64| {
        format!(
            "v -1 -1 0 {r} 0 0\nv 1 -1 0 0 0 {r}\nv 1 1 0 0 0 {r}\nv -1 1 0 {r} 0 0\nf 1 2 3 4\n",
            r = scale
        )
    };
    write(dir.path(), "rgb.obj", quad(1.0).as_bytes());
    let toml = dir.path().join("rgb.toml");
    std::fs::write(&toml, facing_scene("rgb.obj", "")).unwrap();
    let image = render(&load_file(&toml), 40, 40, 1);
    let (left, middle, right) = (
        pixel(&image, 40, 8, 20),
        pixel(&image, 40, 20, 20),
        pixel(&image, 40, 31, 20),
    );
    assert!(left[0] > 100 && left[2] < left[0] / 4, "left {left:?}");
    assert!(right[2] > 100 && right[0] < right[2] / 4, "right {right:?}");
    assert!(middle[0] > 20 && middle[2] > 20, "middle {middle:?}");
    assert_eq!(left[1], 0);
    write(dir.path(), "rgb.obj", quad(255.0).as_bytes());
    assert_eq!(render(&load_file(&toml), 40, 40, 1), image, "0-255 colours");
    write(
        dir.path(),
        "bad.obj",
        b"v 0 0 0\nv 1 0 0 inf 0 0\nv 0 1 0\nf 1 2 3\n",
    );
    let message = glint::scene::load(&dir.path().join("bad.obj"))
        .unwrap_err()
        .to_string();
    assert!(
        message.contains("line 2") && message.contains("vertex colours must be finite"),
        "{message}"
    );
}

/// A face with a hole written as one bridged polygon (LightWave, 3ds Max:
/// outer loop, bridge, inner loop, bridge back) renders as the ring it
/// describes, as the same ring written as four faces does; removing the
/// repeated corners cut a wedge out of it.
#[test]
fn a_bridged_polygon_with_a_hole_renders_as_its_ring() {
    let dir = temp_dir();
    let vertices = "v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n\
                    v -0.5 -0.5 0\nv 0.5 -0.5 0\nv 0.5 0.5 0\nv -0.5 0.5 0\n";
    write(
        dir.path(),
        "keyhole.obj",
        format!("{vertices}f 1 5 8 7 6 5 1 2 3 4\n").as_bytes(),
    );
    write(
        dir.path(),
        "quads.obj",
        format!("{vertices}f 1 2 6 5\nf 2 3 7 6\nf 3 4 8 7\nf 4 1 5 8\n").as_bytes(),
    );
    let image = |obj: &str| {
        let toml = dir.path().join(format!("{obj}.toml"));
        std::fs::write(&toml, facing_scene(obj, "")).unwrap();
        let scene = load_file(&toml);
        assert!(scene.load_notes.is_empty(), "{:?}", scene.load_notes);
        render(&scene, 40, 40, 1)
    };
    let (keyhole, quads) = (image("keyhole.obj"), image("quads.obj"));
    // The hole shows the background; the ring's four sides are there.
    assert_eq!(
        pixel(&keyhole, 40, 20, 20),
        pixel(&keyhole, 40, 0, 0),
        "the hole"
    );
    for (x, y) in [(20, 8), (20, 31), (8, 20), (31, 20)] {
        assert_ne!(
            pixel(&keyhole, 40, x, y),
            pixel(&keyhole, 40, 0, 0),
            "ring at {x},{y}"
        );
    }
    let (differ, _) = common::diff(&keyhole, &quads, 0);
    assert_eq!(differ, 0, "the keyhole face renders as the four quads");
    // Written from the outer loop, the bridge back being the closing edge
    // (`1 2 3 4 1 5 ... 5`): the same ring, not a wedge cut out of it.
    write(
        dir.path(),
        "outer_first.obj",
        format!(
            "{vertices}f 1 2 3 4 1 5 8 7 6 5
"
        )
        .as_bytes(),
    );
    let (differ, _) = common::diff(&image("outer_first.obj"), &quads, 0);
    assert_eq!(
        differ, 0,
        "the outer-first keyhole renders as the four quads"
    );
}
