//! Image textures: OBJ `vt` and MTL `map_Kd`/`map_d` placed as the files
//! say, cut-outs that eye and shadow rays pass through as if the surface
//! were not there, every accelerator and SIMD level giving the same bytes,
//! the `textures` switch, and an export that refuses to re-render once its
//! texture changed. Expected pixels come from the texture's own colours at
//! places worked out from the camera, not from an earlier render.

use crate::common::{self, temp_dir};
use crate::obj_content::{facing_scene, load_file, pixel, write};
use glint::render::{Accelerator, Renderer};
use glint::scene::Scene;
use glint::settings::{Accel, RenderSettings};
use glint::simd::SimdLevel;

/// A PNG of `width` x `height` RGBA texels, top row first.
fn png(width: u32, height: u32, texels: &[[u8; 4]]) -> Vec<u8> {
    let bytes: Vec<u8> = texels.iter().flatten().copied().collect();
    let mut out = Vec::new();
    image::RgbaImage::from_raw(width, height, bytes)
        .unwrap()
        .write_to(&mut std::io::Cursor::new(&mut out), image::ImageFormat::Png)
        .unwrap();
    out
}

const RED: [u8; 4] = [255, 0, 0, 255];
const GREEN: [u8; 4] = [0, 255, 0, 255];
const BLUE: [u8; 4] = [0, 0, 255, 255];
const WHITE: [u8; 4] = [255, 255, 255, 255];
const GAP: [u8; 4] = [0, 0, 0, 0];

/// The unit square [-1, 1]^2 at z = 0 facing the camera, `vt` (0, 0) at
/// its bottom-left corner and (1, 1) at its top-right.
const QUAD: &str = "mtllib quad.mtl\n\
    v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n\
    vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
    usemtl skin\nf 1/1 2/2 3/3 4/4\n";

fn render(scene: &Scene, settings: RenderSettings) -> Vec<u8> {
    let accel = Accelerator::build(scene, &settings, Default::default()).unwrap();
    let renderer = Renderer::new(scene, &accel, settings).unwrap();
    renderer.render(false, None).0.to_rgb8()
}

fn settings(scene: &Scene) -> RenderSettings {
    let mut s = scene.render_settings();
    (s.width, s.height) = (40, 40);
    s
}

/// The channel of `rgb` that is largest by a margin, if one is.
fn dominant(rgb: [u8; 3]) -> Option<usize> {
    let max = *rgb.iter().max().unwrap();
    let at = rgb.iter().position(|&c| c == max)?;
    rgb.iter()
        .enumerate()
        .all(|(i, &c)| i == at || c + 60 < max)
        .then_some(at)
}

/// A 2x2 texture on the quad: its top-left texel shows at the quad's
/// top-left, rows counted up from the bottom as OBJ's `vt` counts; `-s`
/// and `-o` move it as the MTL specification says; off, the `Kd` colour
/// (white) shows everywhere.
#[test]
fn a_texture_shows_where_its_coordinates_put_it() {
    let dir = temp_dir();
    write(dir.path(), "quad.obj", QUAD.as_bytes());
    write(
        dir.path(),
        "rgbw.png",
        &png(2, 2, &[RED, GREEN, BLUE, WHITE]),
    );
    let scene_with = |map: &str| {
        write(
            dir.path(),
            "quad.mtl",
            format!("newmtl skin\nKd 1 1 1\nillum 1\nmap_Kd {map}\n").as_bytes(),
        );
        let toml = dir.path().join("scene.toml");
        std::fs::write(&toml, facing_scene("quad.obj", "")).unwrap();
        load_file(&toml)
    };
    // Pixels in the middle of each quarter of the quad (it spans about
    // pixels 8 to 31 of 40).
    let quarters = |image: &[u8]| {
        [(14, 14), (25, 14), (14, 25), (25, 25)].map(|(x, y)| pixel(image, 40, x, y))
    };
    let scene = scene_with("rgbw.png");
    assert_eq!(scene.textures.len(), 1);
    let image = render(&scene, settings(&scene));
    let [tl, tr, bl, br] = quarters(&image);
    assert_eq!(
        [dominant(tl), dominant(tr), dominant(bl)],
        [Some(0), Some(1), Some(2)]
    );
    assert!(br.iter().all(|&c| c > 150), "white: {br:?}");
    // Shifted by half the image: the quarters swap diagonally.
    let shifted = scene_with("-o 0.5 0.5 rgbw.png");
    let [tl, _, _, br] = quarters(&render(&shifted, settings(&shifted)));
    assert_eq!(dominant(br), Some(0), "{br:?}");
    assert!(tl.iter().all(|&c| c > 150), "white: {tl:?}");
    // Textures off: the material's own colour, the same in every quarter.
    let mut off = settings(&scene);
    off.textures = false;
    let plain = quarters(&render(&scene, off));
    assert!(
        plain.iter().all(|p| p.iter().all(|&c| c > 150)),
        "{plain:?}"
    );
}

/// A quad whose left half is a gap (a 4x1 texture, alpha 0, 0, 1, 1) in
/// front of a red wall, lit from the upper left. Through the gap the wall
/// looks exactly as it does with no quad at all, its shadow ray passing
/// the gap too; behind the solid half the wall lies in its shadow.
#[test]
fn cut_out_gaps_let_eye_and_shadow_rays_through() {
    let dir = temp_dir();
    write(
        dir.path(),
        "leaf.png",
        &png(4, 1, &[GAP, GAP, WHITE, WHITE]),
    );
    write(
        dir.path(),
        "quad.mtl",
        b"newmtl skin\nKd 1 1 1\nillum 1\nmap_Kd leaf.png\nnewmtl wall\nKd 1 0 0\nillum 1\n",
    );
    let wall = "v -3 -3 -1\nv 3 -3 -1\nv 3 3 -1\nv -3 3 -1\nusemtl wall\nf 5 6 7 8\n";
    write(dir.path(), "both.obj", format!("{QUAD}{wall}").as_bytes());
    write(
        dir.path(),
        "wall.obj",
        format!("mtllib quad.mtl\nv 0 0 9\nv 0 0 9\nv 0 0 9\nv 0 0 9\n{wall}").as_bytes(),
    );
    let load = |obj: &str| {
        let text = facing_scene(obj, "").replace("position = [0, 0, 3]", "position = [-2, 0, 3]");
        let toml = dir.path().join(format!("{obj}.toml"));
        std::fs::write(&toml, text).unwrap();
        load_file(&toml)
    };
    let (both, alone) = (load("both.obj"), load("wall.obj"));
    let with_quad = render(&both, settings(&both));
    let without = render(&alone, settings(&alone));
    // Pixel 15 sees the wall at x = -0.52 through the gap at x = -0.39; its
    // shadow ray crosses the quad at x = -0.9, in the gap too.
    let through = pixel(&with_quad, 40, 15, 20);
    assert_eq!(through, pixel(&without, 40, 15, 20));
    assert!(through[0] > 100, "lit red wall: {through:?}");
    // Pixel 33 sees the wall at x = 1.56 beside the quad; its shadow ray
    // crosses the quad's solid half at x = 0.67.
    assert_eq!(pixel(&with_quad, 40, 33, 20), [0, 0, 0]);
    assert!(pixel(&without, 40, 33, 20)[0] > 100);
    // Textures off: the quad is whole, hiding the wall and shadowing it.
    let mut off = settings(&both);
    off.textures = false;
    let whole = render(&both, off);
    let quad = pixel(&whole, 40, 15, 20);
    assert!(
        quad[0] > 50 && quad[0] == quad[1] && quad[1] == quad[2],
        "the white quad: {quad:?}"
    );
}

/// The same bytes through the octree, the BVH and brute force, at every
/// SIMD level, on one thread and on several, with textures and cut-outs.
#[test]
fn textured_renders_are_the_same_bytes_every_way() {
    let dir = temp_dir();
    write(
        dir.path(),
        "leaf.png",
        &png(4, 2, &[GAP, GREEN, WHITE, GAP, RED, GAP, BLUE, WHITE]),
    );
    write(
        dir.path(),
        "leaves.mtl",
        b"newmtl leaf\nKd 0.9 0.9 0.9\nmap_Kd -s 3 2 leaf.png\n",
    );
    // A stack of crossed leaves: many gaps along one ray.
    let mut obj = String::from("mtllib leaves.mtl\nusemtl leaf\n");
    for k in 0..12 {
        let (z, a) = (-0.3 * k as f64, 0.4 * k as f64);
        let (c, s) = (a.cos(), a.sin());
        obj += &format!(
            "v {} {} {z}\nv {} {} {z}\nv {} {} {z}\nv {} {} {z}\n",
            -c + s,
            -s - c,
            c + s,
            s - c,
            c - s,
            s + c,
            -c - s,
            -s + c
        );
        obj += "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n";
        let b = 4 * k + 1;
        obj += &format!(
            "f {}/{} {}/{} {}/{} {}/{}\n",
            b,
            b,
            b + 1,
            b + 1,
            b + 2,
            b + 2,
            b + 3,
            b + 3
        );
    }
    write(dir.path(), "leaves.obj", obj.as_bytes());
    let toml = dir.path().join("scene.toml");
    std::fs::write(
        &toml,
        facing_scene("leaves.obj", "").replace("position = [0, 0, 3]", "position = [1, 2, 4]"),
    )
    .unwrap();
    let scene = load_file(&toml);
    let mut base = settings(&scene);
    base.samples = 16;
    let reference = render(&scene, base);
    assert!(
        reference
            .chunks(3)
            .any(|p| dominant([p[0], p[1], p[2]]) == Some(1))
    );
    for accel in [Accel::Bvh, Accel::BruteForce] {
        let s = RenderSettings { accel, ..base };
        assert_eq!(render(&scene, s), reference, "{accel:?}");
    }
    for level in SimdLevel::ALL {
        let accel = Accelerator::build(&scene, &base, Default::default()).unwrap();
        let renderer = Renderer::new(&scene, &accel, base)
            .unwrap()
            .with_simd(level);
        assert_eq!(
            renderer.render(false, None).0.to_rgb8(),
            reference,
            "{level:?}"
        );
    }
    let one_thread = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .build()
        .unwrap();
    assert_eq!(one_thread.install(|| render(&scene, base)), reference);
}

/// One decoded copy however many materials name a file; a texture that
/// cannot be found is a note naming it and the materials (their `Kd`
/// stands in), never a refusal.
#[test]
fn textures_are_shared_and_a_missing_one_is_a_note() {
    let dir = temp_dir();
    write(
        dir.path(),
        "quad.obj",
        format!("{QUAD}usemtl other\nf 1/1 2/2 3/3\n").as_bytes(),
    );
    write(dir.path(), "t.png", &png(1, 1, &[RED]));
    write(
        dir.path(),
        "quad.mtl",
        b"newmtl skin\nmap_Kd t.png\nnewmtl other\nmap_Kd ./T.PNG\n",
    );
    let toml = dir.path().join("scene.toml");
    std::fs::write(&toml, facing_scene("quad.obj", "")).unwrap();
    let scene = load_file(&toml);
    assert_eq!(scene.textures.len(), 1);
    write(
        dir.path(),
        "quad.mtl",
        b"newmtl skin\nmap_Kd gone.png\nnewmtl other\nmap_Kd gone.png\n",
    );
    let scene = load_file(&toml);
    let notes = scene.notes().join("\n");
    assert!(
        notes.contains("texture `gone.png` (map_Kd) cannot be read: no such file")
            && notes.contains("materials `skin`, `other` are drawn in their own `Kd` colour"),
        "{notes}"
    );
    assert!(scene.textures.is_empty());
    // Several missing textures of one library: one note naming them all;
    // a texture kept in a `Textures` folder beside the MTL is found.
    std::fs::create_dir(dir.path().join("Textures")).unwrap();
    write(&dir.path().join("Textures"), "t.png", &png(1, 1, &[GREEN]));
    write(
        dir.path(),
        "quad.mtl",
        b"newmtl skin\nmap_Kd a.png\nmap_d b.png\nnewmtl other\nmap_Kd c.png\n",
    );
    let notes = load_file(&toml).notes();
    let about: Vec<&String> = notes
        .iter()
        .filter(|n| n.contains("textures it names"))
        .collect();
    assert_eq!(about.len(), 1, "{notes:?}");
    assert!(
        about[0].contains("3 textures it names are in neither its folder nor a `textures` folder")
            && about[0].contains("`b.png` (map_d)"),
        "{}",
        about[0]
    );
    write(dir.path(), "quad.mtl", b"newmtl skin\nmap_Kd t.png\n");
    std::fs::remove_file(dir.path().join("t.png")).unwrap();
    let scene = load_file(&toml);
    assert_eq!(scene.textures.len(), 1, "{:?}", scene.notes());
    assert!(scene.textures[0].path.ends_with("Textures/t.png"));
}

/// A TOML material names a texture and a TOML triangle its coordinates;
/// a texture that cannot be read is an error at its key.
#[test]
fn toml_materials_take_a_texture_and_triangles_their_coordinates() {
    let dir = temp_dir();
    write(
        dir.path(),
        "rgbw.png",
        &png(2, 2, &[RED, GREEN, BLUE, WHITE]),
    );
    let text = |texture: &str| {
        format!(
            "[camera]\neye = [0, 0, 3]\nlookat = [0, 0, 0]\nup = [0, 1, 0]\nfov = 60\n\
             [image]\nwidth = 40\nheight = 40\nbackground = [0, 0, 0]\nambient = [1, 1, 1]\n\
             [materials.skin]\ncolor = [1, 1, 1]\nkd = 0\ntexture = \"{texture}\"\n\
             [[objects]]\nkind = \"triangle\"\nmaterial = \"skin\"\n\
             vertices = [[-1, -1, 0], [1, -1, 0], [1, 1, 0]]\nuvs = [[0, 0], [1, 0], [1, 1]]\n"
        )
    };
    let toml = dir.path().join("scene.toml");
    std::fs::write(&toml, text("rgbw.png")).unwrap();
    let scene = load_file(&toml);
    let image = render(&scene, settings(&scene));
    // Below the diagonal, towards the bottom right: the white texel; above
    // it towards the right edge, the green one.
    assert!(pixel(&image, 40, 27, 27).iter().all(|&c| c > 200));
    assert_eq!(dominant(pixel(&image, 40, 26, 15)), Some(1));
    std::fs::write(&toml, text("nope.png")).unwrap();
    let e = glint::scene::load(&toml).unwrap_err().to_string();
    assert!(
        e.contains("materials.skin.texture") && e.contains("no such file"),
        "{e}"
    );
    assert!(e.contains(":14:"), "the line of the key: {e}");
}

/// An export records the texture's SHA-256 among the scene's files and
/// re-renders byte for byte from it; once the texture changes, `--from-png`
/// refuses and says why.
#[test]
fn an_export_refuses_to_rerender_once_its_texture_changed() {
    let dir = temp_dir();
    write(dir.path(), "quad.obj", QUAD.as_bytes());
    write(dir.path(), "t.png", &png(2, 1, &[RED, BLUE]));
    write(dir.path(), "quad.mtl", b"newmtl skin\nmap_Kd t.png\n");
    let toml = dir.path().join("scene.toml");
    std::fs::write(&toml, facing_scene("quad.obj", "")).unwrap();
    let first = dir.path().join("first.png");
    let again = dir.path().join("again.png");
    let run = |args: &[&str]| common::glint_output(args);
    let out = run(&[
        "render",
        toml.to_str().unwrap(),
        "-o",
        first.to_str().unwrap(),
        "-q",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert_eq!(common::rerender_from_png(&first, &again), (0, 0));
    write(dir.path(), "t.png", &png(2, 1, &[BLUE, RED]));
    let out = run(&[
        "render",
        "--from-png",
        first.to_str().unwrap(),
        "-o",
        again.to_str().unwrap(),
    ]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(
        stderr.contains("t.png has changed (its SHA-256 differs from the recorded one)"),
        "{stderr}"
    );
}
