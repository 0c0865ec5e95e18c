//! MTL materials as exporters mean them: dissolve, `Tr`, `Ns`, and the
//! notes that explain a picture (several materials' notes said once, a
//! fully transparent material named).

use std::path::Path;

use crate::common::temp_dir;
use crate::obj_content::{facing_scene, load_file, pixel, render, write};
use glint::scene::Scene;

/// A grey quad in front of a red one, with `front`'s MTL lines.
fn dissolve_scene(dir: &Path, front: &str) -> Scene {
    write(
        dir,
        "layers.obj",
        b"mtllib layers.mtl\n\
          v -1 -1 0\nv 1 -1 0\nv 1 1 0\nv -1 1 0\n\
          v -3 -3 -1\nv 3 -3 -1\nv 3 3 -1\nv -3 3 -1\n\
          usemtl front\nf 1 2 3 4\nusemtl back\nf 5 6 7 8\n",
    );
    write(
        dir,
        "layers.mtl",
        format!("newmtl front\nKd 0.5 0.5 0.5\n{front}\nnewmtl back\nKd 1 0 0\nillum 1\n")
            .as_bytes(),
    );
    let toml = dir.join("scene.toml");
    std::fs::write(&toml, facing_scene("layers.obj", "")).unwrap();
    load_file(&toml)
}

/// MTL's dissolve blends the surface with what lies behind it: `d 0`
/// shows the red quad behind exactly as if the grey one were not there,
/// and the grey quad never brightens as `d` falls. `d` wins over a `Tr`
/// that disagrees and `Tr 1` alone reads as opaque, each with a note
/// naming the library and line; `Ns 0` (Blender's fully rough) is no
/// highlight, so `Ks 0.9` does not wash out `Kd`.
#[test]
fn mtl_dissolve_tr_and_ns_mean_what_exporters_mean() {
    let dir = temp_dir();
    let centre = |scene: &Scene| pixel(&render(scene, 40, 40, 1), 40, 20, 20);
    let behind = centre(&dissolve_scene(dir.path(), "d 0\nillum 1"));
    write(
        dir.path(),
        "alone.obj",
        b"mtllib layers.mtl\nv -3 -3 -1\nv 3 -3 -1\nv 3 3 -1\nv -3 3 -1\nusemtl back\nf 1 2 3 4\n",
    );
    let toml = dir.path().join("alone.toml");
    std::fs::write(&toml, facing_scene("alone.obj", "")).unwrap();
    assert_eq!(
        behind,
        centre(&load_file(&toml)),
        "d 0 shows what lies behind"
    );
    let mut last = behind;
    for d in [0.25, 0.5, 0.75, 1.0] {
        let seen = centre(&dissolve_scene(dir.path(), &format!("d {d}\nillum 1")));
        // The grey quad's share (the green channel: the red quad has
        // none) grows as it becomes opaque; before, it was full at any d.
        assert!(seen[1] > last[1], "d {d}: {seen:?} after {last:?}");
        last = seen;
    }
    assert_eq!(last[0], last[1], "d 1 is the grey quad alone");

    let both = dissolve_scene(dir.path(), "d 1\nTr 1\nillum 1");
    assert_eq!(centre(&both), last, "d wins: opaque");
    assert!(
        both.load_notes
            .iter()
            .any(|n| n.contains("layers.mtl: line 3") && n.contains("disagree")),
        "{:?}",
        both.load_notes
    );
    let tr = dissolve_scene(dir.path(), "Tr 1\nillum 1");
    assert_eq!(centre(&tr), last, "Tr 1 alone: opaque");
    assert!(
        tr.load_notes
            .iter()
            .any(|n| n.contains("layers.mtl: line 3") && n.contains("read as opaque")),
        "{:?}",
        tr.load_notes
    );
    assert_eq!(
        centre(&dissolve_scene(dir.path(), "Tr 0.75\nillum 1")),
        centre(&dissolve_scene(dir.path(), "d 0.25\nillum 1"))
    );

    let rough = dissolve_scene(dir.path(), "Ks 0.9 0.9 0.9\nNs 0\nillum 2");
    assert_eq!(centre(&rough), last, "Ns 0: Kd as without a highlight");
    let negative = dissolve_scene(dir.path(), "Ks 0.9 0.9 0.9\nNs -5\nillum 2");
    assert_eq!(centre(&negative), last);
    assert!(
        negative
            .load_notes
            .iter()
            .any(|n| n.contains("Ns -5 used as no highlight")),
        "{:?}",
        negative.load_notes
    );
}

/// Notes many materials share are said once, naming them (a file with
/// `Ns -1.96` in 17 materials had 17 notes), and a material with `d 0`
/// on a surface that does not refract is named: its faces show only
/// their highlights, which looks like a ghost with nothing said. Glass
/// (`illum 7`) is meant to be see-through and is not named.
#[test]
fn shared_material_notes_are_grouped_and_ghosts_named() {
    let dir = tempfile::tempdir().unwrap();
    write(
        dir.path(),
        "many.obj",
        b"mtllib many.mtl\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n\
          usemtl a\nf 1 2 3\nusemtl b\nf 1 3 4\nusemtl c\nf 2 3 4\n\
          usemtl ghost\nf 1 2 4\nusemtl glass\nf 4 3 1\n",
    );
    write(
        dir.path(),
        "many.mtl",
        b"newmtl a\nNs -1.96\nTr 1\nnewmtl b\nNs -1.96\nTr 1\nnewmtl c\nNs -1.96\nTr 1\n\
          newmtl ghost\nKd 0.5 0.5 0.5\nd 0\n\
          newmtl glass\nillum 7\nd 0\nNi 1.5\n",
    );
    let toml = dir.path().join("scene.toml");
    std::fs::write(&toml, facing_scene("many.obj", "")).unwrap();
    let notes = load_file(&toml).load_notes;
    let highlight: Vec<_> = notes.iter().filter(|n| n.contains("Ns -1.96")).collect();
    assert_eq!(highlight.len(), 1, "{notes:?}");
    assert!(
        highlight[0].contains("3 materials (`a`, `b`, `c`)"),
        "{notes:?}"
    );
    // MeshLab's `Tr 1` on every material: one note, not one a material.
    let tr: Vec<_> = notes
        .iter()
        .filter(|n| n.contains("`Tr 1` alone"))
        .collect();
    assert_eq!(tr.len(), 1, "{notes:?}");
    assert!(tr[0].contains("3 materials (`a`, `b`, `c`)"), "{notes:?}");
    let ghosts: Vec<_> = notes
        .iter()
        .filter(|n| n.contains("fully transparent"))
        .collect();
    assert_eq!(ghosts.len(), 1, "{notes:?}");
    assert!(
        ghosts[0].contains("material `ghost`") && !ghosts[0].contains("glass"),
        "{notes:?}"
    );
}
