//! `--accel`: the octree, a BVH or brute force answer every query alike,
//! so the pixels are the same; the statistics say which one answered, and
//! a re-render from the PNG takes the same one.

use crate::common;

fn glint(args: &[&str]) -> std::process::Output {
    common::glint_output(args)
}

fn pixels(path: &std::path::Path) -> Vec<u8> {
    image::open(path).unwrap().to_rgb8().into_raw()
}

fn stats(out: &std::process::Output) -> serde_json::Value {
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    serde_json::from_slice(&out.stdout).unwrap()
}

#[test]
fn every_accelerator_gives_the_same_pixels_and_says_which_answered() {
    let tmp = common::temp_dir();
    let scene = common::repo_path("scenes/glass.toml");
    let scene = scene.to_str().unwrap();
    let mut images = Vec::new();
    for accel in ["octree", "bvh", "none"] {
        let png = tmp.path().join(format!("{accel}.png"));
        let out = glint(&[
            "render",
            scene,
            "--width",
            "64",
            "--height",
            "48",
            "--accel",
            accel,
            "--stats",
            "-q",
            "-o",
            png.to_str().unwrap(),
        ]);
        let s = stats(&out);
        assert_eq!(s["accel"], accel);
        assert_eq!(s["octree"], accel == "octree");
        assert_eq!(s["octree_stats"].is_object(), accel == "octree");
        assert_eq!(s["bvh_stats"].is_object(), accel == "bvh");
        if accel == "bvh" {
            let shapes: u64 = s["shapes"]
                .as_object()
                .unwrap()
                .iter()
                .filter(|(kind, _)| *kind != "plane")
                .map(|(_, n)| n.as_u64().unwrap())
                .sum();
            assert_eq!(
                s["bvh_stats"]["references"], shapes,
                "one reference per bounded shape"
            );
            assert!(s["traversal_steps_per_ray"].as_f64().unwrap() > 0.0);
        }
        images.push(pixels(&png));
    }
    assert!(
        images[0] == images[1],
        "the BVH's pixels differ from the octree's"
    );
    assert!(
        images[0] == images[2],
        "brute force's pixels differ from the octree's"
    );

    // A re-render from the PNG goes through a BVH again, unless told otherwise.
    let first = tmp.path().join("bvh.png");
    let again = tmp.path().join("again.png");
    let rerender = |extra: &[&str]| {
        let mut args = vec![
            "render",
            "--from-png",
            first.to_str().unwrap(),
            "--stats",
            "-q",
        ];
        args.extend_from_slice(extra);
        args.extend_from_slice(&["-o", again.to_str().unwrap()]);
        stats(&glint(&args))["accel"].clone()
    };
    assert_eq!(rerender(&[]), "bvh");
    assert_eq!(rerender(&["--octree", "on"]), "octree");
    assert_eq!(pixels(&again), images[0]);
}

#[test]
fn accel_and_octree_flags_that_disagree_are_refused() {
    let scene = common::repo_path("scenes/sphere.toml");
    let tmp = common::temp_dir();
    let png = tmp.path().join("x.png");
    for (accel, octree) in [
        ("bvh", "on"),
        ("none", "on"),
        ("octree", "off"),
        ("bvh", "off"),
    ] {
        let out = glint(&[
            "render",
            scene.to_str().unwrap(),
            "--accel",
            accel,
            "--octree",
            octree,
            "-o",
            png.to_str().unwrap(),
        ]);
        assert_eq!(
            out.status.code(),
            Some(1),
            "--accel {accel} --octree {octree}"
        );
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains("disagree"), "{err}");
        assert!(!png.exists());
    }
    // Agreeing ones are fine.
    let out = glint(&[
        "render",
        scene.to_str().unwrap(),
        "--accel",
        "none",
        "--octree",
        "off",
        "--width",
        "16",
        "--height",
        "16",
        "-q",
        "-o",
        png.to_str().unwrap(),
    ]);
    assert!(out.status.success());
}

#[test]
fn bench_times_a_bvh_beside_the_octree_when_asked() {
    let scene = common::repo_path("scenes/glass.toml");
    let scene = scene.to_str().unwrap();
    let bench = |accel: &str| {
        glint(&[
            "bench", scene, "--size", "32x24", "--repeat", "1", "--format", "json", "--accel",
            accel,
        ])
    };
    let json = |out: std::process::Output| -> serde_json::Value {
        assert!(
            out.status.success(),
            "{}",
            String::from_utf8_lossy(&out.stderr)
        );
        serde_json::from_slice::<serde_json::Value>(&out.stdout).unwrap()[0].clone()
    };
    let with = json(bench("octree,bvh"));
    let bvh = &with["bvh"];
    assert!(bvh["build_s"].as_f64().unwrap() >= 0.0);
    assert!(bvh["render_s"].as_f64().unwrap() > 0.0);
    assert!(bvh["intersection_tests_per_ray"].as_f64().unwrap() > 0.0);
    assert!(bvh["bvh_stats"]["nodes"].as_u64().unwrap() >= 1);
    assert!(
        with.get("octree_off").is_none(),
        "brute force was not asked for"
    );
    let plain = json(bench("octree,none"));
    assert!(plain.get("bvh").is_none());
    assert!(plain["octree_off"].is_object());
    let refused = bench("bvh");
    assert_eq!(refused.status.code(), Some(1));
    assert!(String::from_utf8_lossy(&refused.stderr).contains("always times the octree"));
}
