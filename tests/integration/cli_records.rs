//! What `glint render` records and how it survives the world around it:
//! meshes read from any folder and checked, scenes too large to embed,
//! closed output streams.

use crate::common;

use std::path::Path;
use std::process::{Command, Output};

fn glint(args: &[&str]) -> Output {
    common::glint_output(args)
}

/// A closed standard error (`glint render ... 2>&1 | true`) loses the
/// messages, not the render: exit 0 with the file written. A closed
/// standard output under `--stats` is an error (exit 1), never a panic.
#[test]
fn closed_output_streams_do_not_panic() {
    use std::process::Stdio;
    let tmp = common::temp_dir();
    let png = tmp.path().join("a.png");
    let scene = common::repo_path("scenes/glass.toml");
    let run = |stats: bool| {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_glint"));
        cmd.args(["render", scene.to_str().unwrap(), "-o"])
            .arg(&png)
            .args(["--width", "32", "--height", "24"])
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped());
        if stats {
            cmd.arg("--stats");
        }
        let mut child = cmd.spawn().unwrap();
        // Both readers gone before glint writes a byte.
        drop(child.stdout.take());
        drop(child.stderr.take());
        child.wait().unwrap()
    };
    let status = run(false);
    assert!(status.success(), "{status:?}");
    assert!(png.exists());
    let status = run(true);
    assert_eq!(status.code(), Some(1), "{status:?}");
}

/// A render's record names its scene by absolute path and lists the mesh
/// files it read with their SHA-256: `--from-png` from another folder
/// finds them and gives the same pixels, and says when a mesh has changed
/// since (the picture may then differ) instead of passing it off as the
/// same render.
#[test]
fn from_png_finds_meshes_from_any_folder_and_says_when_one_changed() {
    let tmp = common::temp_dir();
    let dir = tmp.path().join("project");
    std::fs::create_dir_all(dir.join("mesh")).unwrap();
    std::fs::write(
        dir.join("mesh/tri.obj"),
        "v -1 -1 0\nv 1 -1 0\nv 0 1 0\nf 1 2 3\n",
    )
    .unwrap();
    std::fs::write(
        dir.join("scene.toml"),
        "[camera]\neye = [0, 0, 3]\nlookat = [0, 0, 0]\nup = [0, 1, 0]\nfov = 60\n\
         [[lights]]\nposition = [0, 0, 3]\n\
         [[objects]]\nkind = \"mesh\"\npath = \"mesh/tri.obj\"\n",
    )
    .unwrap();
    let first = tmp.path().join("first.png");
    let out = Command::new(env!("CARGO_BIN_EXE_glint"))
        .current_dir(&dir)
        .args(["render", "scene.toml", "-o"])
        .arg(&first)
        .args(["--width", "24", "--height", "24"])
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let record = glint::export::read_record(&first).unwrap();
    assert!(
        Path::new(&record.scene_path).is_absolute(),
        "{}",
        record.scene_path
    );
    assert_eq!(record.settings.files.len(), 1);
    assert!(record.settings.files[0].path.ends_with("tri.obj"));
    // From another folder: the same pixels, no note.
    let again = tmp.path().join("again.png");
    let from_png = || {
        Command::new(env!("CARGO_BIN_EXE_glint"))
            .current_dir(tmp.path())
            .args(["render", "--from-png"])
            .arg(&first)
            .arg("-o")
            .arg(&again)
            .output()
            .unwrap()
    };
    let out = from_png();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(!err.contains("has changed"), "{err}");
    let pixels = |p: &Path| image::open(p).unwrap().to_rgb8().into_raw();
    assert_eq!(pixels(&first), pixels(&again));
    // The mesh edited since: said.
    std::fs::write(
        dir.join("mesh/tri.obj"),
        "v -1 -1 0\nv 1 -1 0\nv 0 0.5 0\nf 1 2 3\n",
    )
    .unwrap();
    let out = from_png();
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("tri.obj has changed since"), "{err}");
}

/// A scene past 16 MiB is not embedded in the PNG (an 8x6 render's PNG
/// was megabytes, and compressing it took seconds outside the reported
/// time): the record keeps its path and SHA-256, `--from-png` renders it
/// again from the file while it is unchanged and refuses, saying why,
/// once it has changed. Writing counts in the reported time.
#[test]
fn a_scene_too_large_to_embed_is_recorded_by_path_and_hash() {
    use std::fmt::Write as _;
    let tmp = common::temp_dir();
    let nff = tmp.path().join("big.nff");
    let mut text = String::from(
        "v\nfrom 0 0 60\nat 0 0 0\nup 0 1 0\nangle 40\nhither 0.1\nresolution 8 6\n\
         b 0.1 0.1 0.1\nl 10 10 10\nf 0.8 0.2 0.2 0.8 0.2 10 0 1\n",
    );
    let mut k = 0u64;
    while text.len() <= glint::export::MAX_EMBEDDED_SCENE {
        k += 1;
        let c = |m: u64| ((k * m) % 4001) as f64 / 100.0 - 20.0;
        writeln!(
            text,
            "s {:.4} {:.4} {:.4} 0.01",
            c(7919),
            c(104729),
            c(1299709)
        )
        .unwrap();
    }
    std::fs::write(&nff, &text).unwrap();
    let (first, again) = (tmp.path().join("big.png"), tmp.path().join("again.png"));
    let out = glint(&[
        "render",
        nff.to_str().unwrap(),
        "-o",
        first.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(err.contains(", write "), "{err}");
    assert!(
        std::fs::metadata(&first).unwrap().len() < 100_000,
        "the scene is not embedded"
    );
    let from_png = || {
        glint(&[
            "render",
            "--from-png",
            first.to_str().unwrap(),
            "-o",
            again.to_str().unwrap(),
        ])
    };
    let out = from_png();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let pixels = |p: &Path| image::open(p).unwrap().to_rgb8().into_raw();
    assert_eq!(pixels(&first), pixels(&again));
    std::fs::write(&nff, text + "# edited\n").unwrap();
    let out = from_png();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1));
    assert!(
        err.contains("too large to embed") && err.contains("has changed"),
        "{err}"
    );
}

/// A sweep marks as `suggested` the setting whose build plus render
/// predicted from a sample of its rays is least (glint's suggestion, also
/// `suggested_from_rays`), the tree-alone model's pick as
/// `suggested_from_tree`, and the measured best as `fastest`: one row each.
/// The suggested and the fastest carry `timed_again_s` when they differ.
#[test]
fn a_sweep_suggests_what_its_ray_sample_predicts_is_fastest() {
    let scene = common::repo_path("scenes/spd/tetra.nff");
    let out = glint(&[
        "bench",
        scene.to_str().unwrap(),
        "--size",
        "24x24",
        "--samples",
        "1",
        "--octree-only",
        "--repeat",
        "1",
        "--sweep",
        "--sweep-depths",
        "2,6",
        "--sweep-leaf-sizes",
        "2,8",
        "--format",
        "json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let rows: Vec<serde_json::Value> = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(
        rows.len(),
        8,
        "two depths, two leaf sizes, cost-driven on and off"
    );
    let marked = |key: &str| {
        let at: Vec<usize> = (0..rows.len()).filter(|&i| rows[i][key] == true).collect();
        assert_eq!(at.len(), 1, "{key}: {at:?}");
        at[0]
    };
    let cost = |i: usize, prediction: &str| {
        rows[i]["build_s"].as_f64().unwrap() + rows[i][prediction]["render_s"].as_f64().unwrap()
    };
    let least = |prediction: &str| {
        (0..rows.len())
            .min_by(|&a, &b| cost(a, prediction).total_cmp(&cost(b, prediction)))
            .unwrap()
    };
    assert_eq!(marked("suggested"), least("predicted_from_rays"));
    assert_eq!(marked("suggested_from_rays"), marked("suggested"));
    assert_eq!(marked("suggested_from_tree"), least("predicted"));
    let (suggested, fastest) = (marked("suggested"), marked("fastest"));
    // Where they differ, both are timed again side by side; no other row is.
    for (i, row) in rows.iter().enumerate() {
        let again = &row["timed_again_s"];
        if suggested != fastest && (i == suggested || i == fastest) {
            assert!(again.as_f64().is_some_and(|t| t > 0.0), "row {i}: {again}");
        } else {
            assert!(again.is_null(), "row {i}: {again}");
        }
    }
}
