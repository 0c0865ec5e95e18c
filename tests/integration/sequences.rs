//! `glint render --turntable` and `--path`: numbered frames with their
//! records, the animated PNG, and a re-run that renders only what is
//! missing.

use crate::common;

use std::path::Path;
use std::process::Output;

fn glint(args: &[&str]) -> Output {
    common::glint_output(args)
}

fn ok(out: &Output) -> String {
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "{stderr}");
    stderr
}

/// A PNG's RGB8 pixels.
fn pixels(path: &Path) -> Vec<u8> {
    image::open(path)
        .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
        .to_rgb8()
        .into_raw()
}

#[test]
fn a_turntable_writes_frames_that_render_again_byte_for_byte_and_an_animation() {
    let tmp = common::temp_dir();
    let scene = common::repo_path("scenes/default.toml");
    let scene = scene.to_str().unwrap();
    let pattern = tmp.path().join("frames/turn_###.png");
    let animation = tmp.path().join("turn.png");
    let size = ["--width", "48", "--height", "36"];
    let mut args = vec!["render", scene, "--turntable", "4", "-o"];
    args.push(pattern.to_str().unwrap());
    args.extend(["--animation", animation.to_str().unwrap()]);
    args.extend(size);
    let said = ok(&glint(&args));
    assert!(said.contains("wrote 4 frames"), "{said}");
    let frame = |k: u32| tmp.path().join(format!("frames/turn_{k:03}.png"));

    // Frame 0 is the scene's own camera: the plain render's pixels.
    let plain = tmp.path().join("plain.png");
    let mut single = vec!["render", scene, "-o", plain.to_str().unwrap()];
    single.extend(size);
    ok(&glint(&single));
    assert_eq!(pixels(&frame(0)), pixels(&plain));
    assert_ne!(pixels(&frame(1)), pixels(&frame(0)), "the camera turns");

    // Each frame records its camera and number: --from-png makes the same file.
    for k in 0..4 {
        let again = tmp.path().join(format!("again_{k}.png"));
        ok(&glint(&[
            "render",
            "--from-png",
            frame(k).to_str().unwrap(),
            "-o",
            again.to_str().unwrap(),
        ]));
        assert_eq!(
            std::fs::read(&again).unwrap(),
            std::fs::read(frame(k)).unwrap()
        );
        let info = glint(&["info", frame(k).to_str().unwrap()]);
        let info = String::from_utf8_lossy(&info.stdout).into_owned();
        assert!(
            info.contains(&format!("frame         {k} of 4 of a turntable")),
            "{info}"
        );
    }

    // The animation holds the four frames, in order, looping.
    let decoder = png::Decoder::new(std::io::BufReader::new(
        std::fs::File::open(&animation).unwrap(),
    ));
    let mut reader = decoder.read_info().unwrap();
    let control = reader.info().animation_control.unwrap();
    assert_eq!((control.num_frames, control.num_plays), (4, 0));
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    for k in 0..4 {
        let info = reader.next_frame(&mut buf).unwrap();
        assert_eq!(
            &buf[..info.buffer_size()],
            pixels(&frame(k)).as_slice(),
            "frame {k}"
        );
        let fc = reader.info().frame_control.unwrap();
        assert_eq!((fc.delay_num, fc.delay_den), (1, 24), "24 fps");
    }
}

#[test]
fn a_second_run_renders_only_frames_missing_or_made_otherwise() {
    let tmp = common::temp_dir();
    let scene = common::repo_path("scenes/sphere.toml");
    let pattern = tmp.path().join("s_##.png");
    let run = |samples: &str| {
        ok(&glint(&[
            "render",
            scene.to_str().unwrap(),
            "--turntable",
            "5",
            "-o",
            pattern.to_str().unwrap(),
            "--width",
            "24",
            "--height",
            "16",
            "--samples",
            samples,
        ]))
    };
    run("1");
    let frame = |k: u32| tmp.path().join(format!("s_{k:02}.png"));
    let written = |k| std::fs::metadata(frame(k)).unwrap().modified().unwrap();
    let before: Vec<_> = (0..5).map(written).collect();
    std::fs::remove_file(frame(3)).unwrap();
    // A damaged frame is not kept either.
    std::fs::write(frame(1), b"\x89PNG\r\n\x1a\n").unwrap();
    std::thread::sleep(std::time::Duration::from_millis(20));
    let said = run("1");
    assert!(said.contains("3 of 5 frames are already there"), "{said}");
    for k in [0, 2, 4] {
        assert_eq!(written(k), before[k as usize], "frame {k} was kept");
    }
    assert!(frame(3).exists());
    assert!(image::open(frame(1)).is_ok());
    // Other settings: another record, so every frame is made again.
    let said = run("16");
    assert!(!said.contains("already there"), "{said}");
}

#[test]
fn an_interrupted_sequence_leaves_whole_frames_and_resumes() {
    use std::process::{Command, Stdio};
    let tmp = common::temp_dir();
    let scene = common::repo_path("scenes/default.toml");
    let pattern = tmp.path().join("f_####.png");
    let args = [
        "render",
        scene.to_str().unwrap(),
        "--turntable",
        "40",
        "-o",
        pattern.to_str().unwrap(),
        "--width",
        "160",
        "--height",
        "120",
        "--threads",
        "1",
    ];
    let mut child = Command::new(env!("CARGO_BIN_EXE_glint"))
        .args(args)
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let count = || {
        std::fs::read_dir(tmp.path())
            .unwrap()
            .filter(|e| {
                e.as_ref()
                    .unwrap()
                    .file_name()
                    .to_string_lossy()
                    .starts_with("f_")
            })
            .count()
    };
    let deadline = std::time::Instant::now() + std::time::Duration::from_secs(60);
    while count() < 2 && std::time::Instant::now() < deadline {
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    let interrupt = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(interrupt.success());
    let status = child.wait().unwrap();
    assert!(!status.success(), "interrupted before the 40th frame");
    let done = count();
    assert!((2..40).contains(&done), "{done} frames");
    // Only whole frames: every file there decodes, none is a temporary.
    for entry in std::fs::read_dir(tmp.path()).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        assert!(
            name.starts_with("f_") && name.ends_with(".png"),
            "{name} left behind"
        );
        image::open(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
    }
    let said = ok(&glint(&args));
    assert!(
        said.contains(&format!("{done} of 40 frames are already there")),
        "{said}"
    );
    assert_eq!(count(), 40);
}

const PATH_SCENE: &str = r#"
[camera]
eye = [0, 1, 6]
lookat = [0, 0, 0]
up = [0, 1, 0]
fov = 40

[[camera.keyframes]]
time = 0
eye = [0, 1, 6]
lookat = [0, 0, 0]

[[camera.keyframes]]
time = 1
eye = [6, 2, 0]
lookat = [0, 0, 0]
fov = 30

[[camera.keyframes]]
time = 2
eye = [0, 4, -6]
lookat = [0, 0.5, 0]

[materials.red]
color = [0.8, 0.2, 0.1]

[[lights]]
position = [5, 8, 5]

[[objects]]
kind = "sphere"
material = "red"
center = [0, 0, 0]
radius = 1

[[objects]]
kind = "plane"
material = "red"
point = [0, -1, 0]
normal = [0, 1, 0]
"#;

#[test]
fn a_camera_path_renders_its_keys_and_records_their_times() {
    let tmp = common::temp_dir();
    let scene = tmp.path().join("path.toml");
    std::fs::write(&scene, PATH_SCENE).unwrap();
    let pattern = tmp.path().join("fly_#.png");
    let said = ok(&glint(&[
        "render",
        scene.to_str().unwrap(),
        "--path",
        "--fps",
        "2",
        "-o",
        pattern.to_str().unwrap(),
        "--width",
        "40",
        "--height",
        "30",
    ]));
    assert!(said.contains("wrote 5 frames"), "{said}");
    // The last frame is the last key: the scene rendered with that camera.
    let last_key = PATH_SCENE.replacen(
        "eye = [0, 1, 6]\nlookat = [0, 0, 0]\nup",
        "eye = [0, 4, -6]\nlookat = [0, 0.5, 0]\nup",
        1,
    );
    let still = tmp.path().join("last.toml");
    std::fs::write(&still, last_key).unwrap();
    let plain = tmp.path().join("last.png");
    ok(&glint(&[
        "render",
        still.to_str().unwrap(),
        "-o",
        plain.to_str().unwrap(),
        "--width",
        "40",
        "--height",
        "30",
    ]));
    assert_eq!(pixels(&tmp.path().join("fly_4.png")), pixels(&plain));
    let info = glint(&["info", tmp.path().join("fly_3.png").to_str().unwrap()]);
    let info = String::from_utf8_lossy(&info.stdout).into_owned();
    assert!(
        info.contains("frame         3 of 5, at 1.5 s along the camera path"),
        "{info}"
    );
}

#[test]
fn sequence_flags_say_what_they_need() {
    let tmp = common::temp_dir();
    let scene = common::repo_path("scenes/sphere.toml");
    let scene = scene.to_str().unwrap();
    let out = tmp.path().join("x_#.png");
    let out = out.to_str().unwrap();
    let error = |args: &[&str]| {
        let o = glint(args);
        assert!(!o.status.success(), "{args:?} succeeded");
        String::from_utf8_lossy(&o.stderr).into_owned()
    };
    let e = error(&["render", scene, "--path", "-o", out]);
    assert!(
        e.contains("has no camera path") && e.contains("--turntable"),
        "{e}"
    );
    let e = error(&["render", scene, "--turntable", "3"]);
    assert!(e.contains("--output"), "{e}");
    let e = error(&["render", scene, "--turntable", "3", "-o", "-"]);
    assert!(e.contains("one file per frame"), "{e}");
    let e = error(&["render", scene, "--fps", "3", "-o", out]);
    assert!(e.contains("belong to a sequence"), "{e}");
    let e = error(&["render", scene, "--turntable", "0", "-o", out]);
    assert!(e.contains("from 1 to 1,000,000"), "{e}");
    let e = error(&["render", scene, "--turntable", "3", "--fps", "0", "-o", out]);
    assert!(e.contains("--fps"), "{e}");
}

#[test]
fn an_nff_scene_flies_along_a_keyframes_file_and_a_bad_one_names_its_place() {
    let tmp = common::temp_dir();
    let scene = common::repo_path("scenes/spd/balls.nff");
    let keys = common::repo_path("scenes/paths/balls_flight.toml");
    let pattern = tmp.path().join("b_##.png");
    let said = ok(&glint(&[
        "render",
        scene.to_str().unwrap(),
        "--path-file",
        keys.to_str().unwrap(),
        "--frames",
        "3",
        "-o",
        pattern.to_str().unwrap(),
        "--width",
        "32",
        "--height",
        "24",
    ]));
    assert!(said.contains("wrote 3 frames"), "{said}");
    let info = glint(&["info", tmp.path().join("b_01.png").to_str().unwrap()]);
    let info = String::from_utf8_lossy(&info.stdout).into_owned();
    assert!(
        info.contains("frame         1 of 3, at 4 s along the camera path"),
        "{info}"
    );
    // The first frame is the SPD view itself: the plain render's pixels.
    let plain = tmp.path().join("plain.png");
    ok(&glint(&[
        "render",
        scene.to_str().unwrap(),
        "-o",
        plain.to_str().unwrap(),
        "--width",
        "32",
        "--height",
        "24",
    ]));
    assert_eq!(pixels(&tmp.path().join("b_00.png")), pixels(&plain));

    let bad = tmp.path().join("bad.toml");
    std::fs::write(
        &bad,
        "[[keyframes]]\ntime = 0\neye = [1, 1, 1]\nlookat = [0, 0, 0]\n\n\
         [[keyframes]]\ntime = 1\neye = [2, 2, 2]\nlookat = [0, 0]\n",
    )
    .unwrap();
    let out = glint(&[
        "render",
        scene.to_str().unwrap(),
        "--path-file",
        bad.to_str().unwrap(),
        "-o",
        pattern.to_str().unwrap(),
    ]);
    let e = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success());
    assert!(
        e.contains("bad.toml:9:10") && e.contains("keyframes[1].lookat"),
        "{e}"
    );
}

#[test]
fn an_animation_named_as_a_frame_and_a_missing_keyframes_file_are_refused() {
    let tmp = common::temp_dir();
    let scene = common::repo_path("scenes/sphere.toml");
    let frame0 = tmp.path().join("t_0.png");
    // A two-frame turntable written to `frames`, animated into `animation`.
    let turntable = |frames: &Path, animation: &Path| {
        glint(&[
            "render",
            scene.to_str().unwrap(),
            "--turntable",
            "2",
            "-o",
            frames.to_str().unwrap(),
            "--animation",
            animation.to_str().unwrap(),
        ])
    };
    let o = turntable(&tmp.path().join("t_#.png"), &frame0);
    let e = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(
        !o.status.success() && e.contains("also the name of frame 0"),
        "{e}"
    );
    assert!(!frame0.exists(), "refused before any frame");
    // The same file by another spelling, in a folder not there yet.
    let fresh = tmp.path().join("new");
    let o = turntable(&fresh.join("t_#.png"), &fresh.join("../new/t_1.png"));
    let e = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(
        !o.status.success() && e.contains("also the name of frame 1"),
        "{e}"
    );
    let o = glint(&[
        "render",
        scene.to_str().unwrap(),
        "--path-file",
        tmp.path().join("nope.toml").to_str().unwrap(),
        "-o",
        tmp.path().join("p_#.png").to_str().unwrap(),
    ]);
    let e = String::from_utf8_lossy(&o.stderr).into_owned();
    assert!(
        e.contains("cannot read the camera path file") && e.contains("No such file"),
        "{e}"
    );
}
