//! Where `glint render -o` writes, what it refuses, and the limits that
//! protect the machine: run through the real binary.

use crate::common;

use std::os::unix::fs::FileTypeExt;
use std::path::Path;
use std::process::{Command, Output};

const PNG_SIGNATURE: &[u8] = b"\x89PNG\r\n\x1a\n";

fn glint(args: &[&str]) -> Output {
    common::glint_output(args)
}

fn scene() -> String {
    common::repo_path("scenes/sphere.toml")
        .to_string_lossy()
        .into_owned()
}

fn small(out: &Path) -> Vec<String> {
    vec![
        "render".into(),
        scene(),
        "--width".into(),
        "16".into(),
        "--height".into(),
        "12".into(),
        "-o".into(),
        out.to_string_lossy().into_owned(),
    ]
}

fn run(args: &[String]) -> Output {
    let refs: Vec<&str> = args.iter().map(String::as_str).collect();
    glint(&refs)
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

#[test]
fn a_symbolic_link_is_written_through_to_its_target() {
    let tmp = common::temp_dir();
    let d = tmp.path();
    let target = d.join("target.png");
    std::fs::write(&target, b"old").unwrap();
    let link = d.join("link.png");
    std::os::unix::fs::symlink("target.png", &link).unwrap();
    let o = run(&small(&link));
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        std::fs::symlink_metadata(&link)
            .unwrap()
            .file_type()
            .is_symlink(),
        "still a link"
    );
    assert!(
        std::fs::read(&target).unwrap().starts_with(PNG_SIGNATURE),
        "the target holds the PNG"
    );
    // A link to a file not yet there creates the file at the link's target.
    let dangling = d.join("dangling.png");
    std::os::unix::fs::symlink("new.png", &dangling).unwrap();
    let o = run(&small(&dangling));
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(
        std::fs::read(d.join("new.png"))
            .unwrap()
            .starts_with(PNG_SIGNATURE)
    );
    // No temporary file is left behind.
    let names: Vec<String> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    assert!(names.iter().all(|n| !n.contains(".tmp")), "{names:?}");
}

#[test]
fn a_fifo_is_written_not_replaced() {
    let tmp = common::temp_dir();
    let d = tmp.path();
    let fifo = d.join("pipe");
    let status = Command::new("mkfifo").arg(&fifo).status().unwrap();
    assert!(status.success());
    let reader = {
        let fifo = fifo.clone();
        std::thread::spawn(move || std::fs::read(fifo).unwrap())
    };
    let o = run(&small(&fifo));
    if !o.status.success() {
        // Unblock the reader before failing.
        let _ = std::fs::OpenOptions::new().write(true).open(&fifo);
        panic!("{}", stderr(&o));
    }
    let bytes = reader.join().unwrap();
    assert!(
        bytes.starts_with(PNG_SIGNATURE),
        "the reader got {} bytes",
        bytes.len()
    );
    assert!(
        std::fs::metadata(&fifo).unwrap().file_type().is_fifo(),
        "still a FIFO"
    );
}

#[test]
fn dash_writes_the_png_to_standard_output() {
    let tmp = common::temp_dir();
    let d = tmp.path();
    let o = Command::new(env!("CARGO_BIN_EXE_glint"))
        .current_dir(d)
        .args([
            "render",
            &scene(),
            "--width",
            "16",
            "--height",
            "12",
            "-o",
            "-",
        ])
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(o.stdout.starts_with(PNG_SIGNATURE));
    let image = image::load_from_memory(&o.stdout).unwrap();
    assert_eq!((image.width(), image.height()), (16, 12));
    assert!(!d.join("-").exists(), "no file named -");
    // Standard output cannot carry the image and JSON at once.
    let o = glint(&["render", &scene(), "-o", "-", "--stats"]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("standard output"), "{}", stderr(&o));
}

#[test]
fn other_extensions_and_the_input_scene_are_refused() {
    let tmp = common::temp_dir();
    let d = tmp.path();
    for name in ["out.jpg", "out", "scene.toml"] {
        let out = d.join(name);
        let o = run(&small(&out));
        assert!(!o.status.success(), "{name} accepted");
        assert!(
            stderr(&o).contains("name the output .png"),
            "{name}: {}",
            stderr(&o)
        );
        assert!(!out.exists(), "{name} was written");
    }
    // The scene being rendered, even under a .png name (a re-render).
    let first = d.join("first.png");
    assert!(run(&small(&first)).status.success());
    let before = std::fs::read(&first).unwrap();
    let o = glint(&[
        "render",
        "--from-png",
        first.to_str().unwrap(),
        "-o",
        first.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("is the scene being rendered"),
        "{}",
        stderr(&o)
    );
    assert_eq!(std::fs::read(&first).unwrap(), before, "left untouched");
}

/// A folder that is not there is found before the render, and the message
/// names the user's path, not the temporary file the write goes through;
/// nothing is left behind.
#[test]
fn a_missing_output_folder_is_refused_before_rendering() {
    let tmp = common::temp_dir();
    let out = tmp.path().join("no/such/folder/a.png");
    // With --trace-pixel the tree is printed only after the checks: no
    // tree on standard output shows that nothing was traced.
    let mut args = small(&out);
    args.extend(["--trace-pixel".into(), "1,1".into()]);
    let o = run(&args);
    assert!(!o.status.success());
    let text = stderr(&o);
    assert!(
        text.contains(&format!("cannot write {}", out.display())),
        "{text}"
    );
    assert!(
        !text.contains(".glint-") && !text.contains("wrote"),
        "{text}"
    );
    assert!(o.stdout.is_empty(), "traced before refusing");
    let left: Vec<_> = std::fs::read_dir(tmp.path()).unwrap().collect();
    assert!(left.is_empty(), "{left:?}");
}

/// A file that describes nothing to see says so instead of rendering a
/// blank picture without a word.
#[test]
fn an_empty_scene_is_said_to_be_empty() {
    let tmp = common::temp_dir();
    let nff = tmp.path().join("empty.nff");
    std::fs::write(
        &nff,
        "v\nfrom 0 0 5\nat 0 0 0\nup 0 1 0\nangle 40\nhither 1\nresolution 8 8\n",
    )
    .unwrap();
    let out = tmp.path().join("empty.png");
    let o = glint(&["render", nff.to_str().unwrap(), "-o", out.to_str().unwrap()]);
    assert!(o.status.success(), "{}", stderr(&o));
    let text = stderr(&o);
    assert!(
        text.contains("no objects") && text.contains("no lights"),
        "{text}"
    );
}

#[test]
fn success_is_one_line_on_stderr_unless_quiet() {
    let tmp = common::temp_dir();
    let d = tmp.path();
    let out = d.join("a.png");
    let o = run(&small(&out));
    let text = stderr(&o);
    assert_eq!(text.lines().count(), 1, "{text}");
    assert!(
        text.starts_with(&format!("wrote {} (16x12, ", out.display())),
        "{text}"
    );
    let mut quiet = small(&out);
    quiet.push("--quiet".into());
    let o = run(&quiet);
    assert!(o.status.success() && o.stderr.is_empty(), "{}", stderr(&o));
}

#[test]
fn trace_pixel_with_an_output_writes_both() {
    let tmp = common::temp_dir();
    let d = tmp.path();
    let out = d.join("a.png");
    let mut args = small(&out);
    args.extend(["--trace-pixel".into(), "8,6".into()]);
    let o = run(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let tree: serde_json::Value = serde_json::from_slice(&o.stdout).unwrap();
    assert_eq!(tree["pixel"], serde_json::json!([8, 6]));
    assert!(std::fs::read(&out).unwrap().starts_with(PNG_SIGNATURE));
}

#[test]
fn limits_are_stated_when_refused() {
    let o = glint(&[
        "render",
        &scene(),
        "--threads",
        "100000",
        "-o",
        "/tmp/never.png",
    ]);
    assert!(!o.status.success());
    assert!(stderr(&o).contains("per core"), "{}", stderr(&o));
    let o = glint(&[
        "render",
        &scene(),
        "--width",
        "20000",
        "--height",
        "20000",
        "-o",
        "/tmp/never.png",
    ]);
    assert!(!o.status.success());
    assert!(
        stderr(&o).contains("at most 268435456 pixels"),
        "{}",
        stderr(&o)
    );
    assert!(!Path::new("/tmp/never.png").exists());
    // The memory estimate, against a machine with 1 GiB available.
    let mut settings = common::load("scenes/sphere.toml").render_settings();
    (settings.width, settings.height) = (8192, 8192);
    let e = glint::render::memory::check_memory_against(&settings, 0, 1 << 30)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("8192x8192 render needs about 1920 MiB") && e.contains("819 MiB"),
        "{e}"
    );
    (settings.width, settings.height) = (1024, 1024);
    assert!(glint::render::memory::check_memory_against(&settings, 0, 1 << 30).is_ok());
}

/// `glint view` refuses what it cannot show, before opening a window, as
/// `glint render` refuses what it cannot render.
#[cfg(feature = "gui")]
#[test]
fn the_viewer_refuses_sizes_windows_and_pixels_it_cannot_show() {
    let s = scene();
    for (args, needle) in [
        (vec!["--size", "100000x100"], "outside the limits"),
        (vec!["--size", "9000x100"], "at most 8192 pixels a side"),
        (
            vec!["--window", "10x10"],
            "smaller than the viewer can show",
        ),
        (
            vec!["--size", "64x48", "--inspect", "70,1"],
            "outside the 64x48 image",
        ),
    ] {
        let mut all = vec!["view", s.as_str()];
        all.extend(args.iter().copied());
        let o = glint(&all);
        assert!(!o.status.success(), "{args:?} accepted");
        assert!(stderr(&o).contains(needle), "{args:?}: {}", stderr(&o));
    }
}

/// The closing line gives the written file's size, legend strip included.
#[test]
fn the_reported_size_is_the_files() {
    let tmp = common::temp_dir();
    let out = tmp.path().join("cost.png");
    let mut args = small(&out);
    args.extend(["--view".into(), "cost".into()]);
    let o = run(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    let (w, h) = image::image_dimensions(&out).unwrap();
    assert!(h > 12, "the legend is under the image");
    assert!(
        stderr(&o).contains(&format!("({w}x{h}, ")),
        "{}",
        stderr(&o)
    );
}

/// Ctrl+C while the PNG is being written leaves no temporary file behind
/// (and no output): the write is large enough to be caught in the act.
#[test]
fn an_interrupted_write_leaves_no_temporary_file() {
    let tmp = common::temp_dir();
    let out = tmp.path().join("big.png");
    let temporaries = || -> Vec<String> {
        std::fs::read_dir(tmp.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.starts_with(".glint-"))
            .collect()
    };
    // A plain scene at 1 sample renders quickly; 24 million pixels take a
    // while to encode.
    let mut child = Command::new(env!("CARGO_BIN_EXE_glint"))
        .args([
            "render",
            &scene(),
            "--width",
            "6000",
            "--height",
            "4000",
            "--samples",
            "1",
            "-q",
            "-o",
        ])
        .arg(&out)
        .spawn()
        .unwrap();
    let start = std::time::Instant::now();
    let mut seen = false;
    while start.elapsed() < std::time::Duration::from_secs(120) {
        if !temporaries().is_empty() {
            seen = true;
            break;
        }
        if child.try_wait().unwrap().is_some() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(5));
    }
    assert!(
        seen,
        "the write was not caught: the test needs a larger image"
    );
    let kill = Command::new("kill")
        .args(["-INT", &child.id().to_string()])
        .status()
        .unwrap();
    assert!(kill.success());
    let status = child.wait().unwrap();
    assert_eq!(status.code(), Some(130), "{status:?}");
    assert_eq!(temporaries(), Vec::<String>::new());
    assert!(!out.exists(), "no half-written output");
}

/// One set of limits: every extreme value `glint render` accepts is read
/// back by `glint info` and `--from-png` (which renders the same pixels),
/// and one step past it is refused before anything is written.
#[test]
fn every_value_the_cli_accepts_is_read_back_and_one_past_it_refused() {
    let tmp = common::temp_dir();
    let first = tmp.path().join("first.png");
    let again = tmp.path().join("again.png");
    let scene = scene();
    let render = |extra: &[&str], out: &Path| {
        let mut args = vec!["render", "-q"];
        args.extend(extra);
        if !extra.contains(&"--from-png") {
            args.push(&scene);
            if !extra.contains(&"--width") {
                args.extend(["--width", "8", "--height", "6"]);
            }
        }
        args.extend(["-o", out.to_str().unwrap()]);
        glint(&args)
    };
    let pixels = |p: &Path| image::open(p).unwrap().to_rgb8().into_raw();
    let max_side = glint::limits::MAX_IMAGE_SIDE.to_string();
    let max_depth = glint::limits::MAX_RAY_DEPTH.to_string();
    let max_octree = glint::limits::MAX_OCTREE_DEPTH.to_string();
    let max_budget = glint::limits::MAX_MEMORY_BUDGET_MIB.to_string();
    let accepted: Vec<Vec<&str>> = vec![
        vec!["--width", &max_side, "--height", "1"],
        vec!["--width", "1", "--height", &max_side],
        vec!["--max-depth", &max_depth],
        vec!["--max-depth", "1"],
        vec!["--samples", "16"],
        vec!["--aa", "adaptive"],
        vec!["--octree-max-depth", &max_octree],
        vec!["--octree-max-depth", "0"],
        vec!["--octree-leaf-size", "4294967295"],
        vec!["--octree-leaf-size", "1"],
        vec!["--octree-max-duplication", "1"],
        vec!["--octree-max-duplication", "8"],
        vec!["--octree-memory-budget", "1"],
        vec!["--octree-memory-budget", &max_budget],
        vec!["--overlay", "octree", "--overlay-depth", &max_octree],
        vec!["--view", "cost", "--legend", "off"],
    ];
    for extra in &accepted {
        let _ = std::fs::remove_file(&first);
        let o = render(extra, &first);
        assert!(o.status.success(), "{extra:?}: {}", stderr(&o));
        let info = glint(&["info", first.to_str().unwrap()]);
        assert!(info.status.success(), "{extra:?}: info: {}", stderr(&info));
        let o = render(&["--from-png", first.to_str().unwrap()], &again);
        assert!(o.status.success(), "{extra:?}: --from-png: {}", stderr(&o));
        assert!(pixels(&first) == pixels(&again), "{extra:?}: other pixels");
    }
    let past_side = (glint::limits::MAX_IMAGE_SIDE + 1).to_string();
    let past_depth = (glint::limits::MAX_RAY_DEPTH + 1).to_string();
    let past_octree = (glint::limits::MAX_OCTREE_DEPTH + 1).to_string();
    let past_budget = (glint::limits::MAX_MEMORY_BUDGET_MIB + 1).to_string();
    let refused: Vec<Vec<&str>> = vec![
        vec!["--width", &past_side, "--height", "1"],
        vec!["--max-depth", &past_depth],
        vec!["--max-depth", "0"],
        vec!["--octree-max-depth", &past_octree],
        vec!["--octree-leaf-size", "0"],
        vec!["--octree-max-duplication", "0"],
        vec!["--octree-max-duplication", "9"],
        vec!["--octree-memory-budget", "0"],
        vec!["--octree-memory-budget", &past_budget],
        vec!["--overlay", "octree", "--overlay-depth", &past_octree],
        vec!["--samples", "4"],
    ];
    for extra in &refused {
        let _ = std::fs::remove_file(&first);
        let o = render(extra, &first);
        assert!(!o.status.success(), "{extra:?} accepted");
        assert!(!stderr(&o).is_empty(), "{extra:?}: refused without a word");
        assert!(!first.exists(), "{extra:?}: a file was written");
    }
}

/// `glint view --screenshot` checks its path as `glint render -o` does,
/// before any window opens (so no display is needed here): a name that is
/// not `.png`, or a folder that does not exist, is refused with exit 1,
/// and an existing file is left as it was, a new name never created.
#[cfg(feature = "gui")]
#[test]
fn a_screenshot_path_is_checked_before_the_window_and_no_file_is_touched() {
    let tmp = common::temp_dir();
    let d = tmp.path();
    let keep = d.join("keep.jpg");
    std::fs::write(&keep, b"precious").unwrap();
    let fresh = d.join("fresh.bmp");
    let missing = d.join("no such folder").join("shot.png");
    for path in [&keep, &fresh, &missing] {
        let o = Command::new(env!("CARGO_BIN_EXE_glint"))
            .args(["view", &scene(), "--screenshot"])
            .arg(path)
            .env_remove("DISPLAY")
            .env_remove("WAYLAND_DISPLAY")
            .env_remove("WAYLAND_SOCKET")
            .output()
            .unwrap();
        let err = stderr(&o);
        assert_eq!(o.status.code(), Some(1), "{}: {err}", path.display());
        assert!(err.contains("--screenshot"), "{err}");
        if path == &missing {
            // The reason, as `glint render -o` gives it.
            assert!(err.contains("No such file or directory"), "{err}");
        }
        assert!(
            !err.contains("no display"),
            "refused before the window: {err}"
        );
    }
    assert_eq!(std::fs::read(&keep).unwrap(), b"precious");
    assert!(!fresh.exists(), "no empty file left behind");
}

/// A flag that would have no effect is refused with the reason, not
/// accepted silently: `--overlay-depth` without an overlay to draw, and
/// `--compare-difference` without `--compare`.
#[test]
fn flags_without_effect_are_refused() {
    let tmp = common::temp_dir();
    let mut args = small(&tmp.path().join("x.png"));
    args.extend(["--overlay-depth".into(), "3".into()]);
    let o = run(&args);
    assert_eq!(o.status.code(), Some(1), "{}", stderr(&o));
    assert!(stderr(&o).contains("--overlay octree"), "{}", stderr(&o));
    assert!(!tmp.path().join("x.png").exists());
    args.extend(["--overlay".into(), "octree".into()]);
    let o = run(&args);
    assert!(o.status.success(), "{}", stderr(&o));
    #[cfg(feature = "gui")]
    {
        let o = glint(&["view", &scene(), "--compare-difference"]);
        assert_eq!(o.status.code(), Some(2), "{}", stderr(&o));
        assert!(stderr(&o).contains("--compare"), "{}", stderr(&o));
    }
}

/// Multi-scene commands check every scene file before timing any (a
/// missing last one failed after the others were measured, with no
/// results), and `study` keeps two scenes of one name apart.
#[test]
fn multi_scene_commands_check_first_and_keep_same_names_apart() {
    let tmp = common::temp_dir();
    let sphere = common::repo_path("scenes/sphere.toml");
    let missing = tmp.path().join("missing.toml");
    // A file that exists but is not a scene: found only by reading it.
    let broken = tmp.path().join("broken.toml");
    std::fs::write(&broken, "[camera]\neye = [0, 0\n").unwrap();
    for (command, bad) in [
        ("bench", &missing),
        ("study", &missing),
        ("bench", &broken),
        ("study", &broken),
    ] {
        let mut cmd = Command::new(env!("CARGO_BIN_EXE_glint"));
        cmd.args([command, sphere.to_str().unwrap(), bad.to_str().unwrap()])
            .args(["--size", "8x6", "--repeat", "1"]);
        if command == "study" {
            cmd.arg("--out").arg(tmp.path().join("study"));
        }
        let out = cmd.output().unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        let name = bad.file_name().unwrap().to_str().unwrap();
        assert_eq!(out.status.code(), Some(1), "{command} {name}: {err}");
        assert!(err.contains(name), "{command}: {err}");
        assert!(
            !err.contains(&format!("{command} {}", sphere.display())),
            "{command} timed first: {err}"
        );
    }
    for folder in ["a", "b"] {
        std::fs::create_dir(tmp.path().join(folder)).unwrap();
        std::fs::copy(&sphere, tmp.path().join(folder).join("sphere.toml")).unwrap();
    }
    let out_dir = tmp.path().join("two");
    let out = Command::new(env!("CARGO_BIN_EXE_glint"))
        .arg("study")
        .args([
            tmp.path().join("a/sphere.toml"),
            tmp.path().join("b/sphere.toml"),
        ])
        .args(["--size", "8x6", "--repeat", "1", "--out"])
        .arg(&out_dir)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(out_dir.join("sphere-aa-need.png").exists());
    assert!(out_dir.join("sphere-2-aa-need.png").exists());
}

/// `-o` onto an existing file that is not a PNG replaces it, saying so
/// first.
#[test]
fn replacing_a_file_that_is_not_a_png_is_said() {
    let tmp = common::temp_dir();
    let out_path = tmp.path().join("out.png");
    std::fs::write(&out_path, "not an image\n").unwrap();
    let out = glint(&[
        "render",
        &scene(),
        "--width",
        "8",
        "--height",
        "6",
        "-o",
        out_path.to_str().unwrap(),
    ]);
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(out.status.success(), "{err}");
    assert!(
        err.contains("out.png is not a PNG image (13 bytes of text); the render replaces it"),
        "{err}"
    );
    assert!(std::fs::read(&out_path).unwrap().starts_with(b"\x89PNG"));
}

/// `glint --help` says that a scene alone opens the viewer.
#[cfg(feature = "gui")]
#[test]
fn help_says_a_scene_alone_opens_the_viewer() {
    let out = glint(&["--help"]);
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("`glint SCENE` (no command) opens SCENE in the viewer"),
        "{text}"
    );
}

/// A negative number where a positive one is asked for is refused as a
/// value, not taken for an unknown flag.
#[test]
fn negative_numbers_are_refused_as_values() {
    let sphere = scene();
    for flags in [
        &["render", &sphere, "--width", "-5", "-o", "-"][..],
        &["render", &sphere, "--samples", "-1", "-o", "-"][..],
        &["bench", &sphere, "--repeat", "-2"][..],
    ] {
        let out = glint(flags);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{flags:?}: {err}");
        assert!(err.contains("got `-"), "{flags:?}: {err}");
        assert!(!err.contains("use '--"), "{flags:?}: {err}");
    }
}

/// Flags that would have no effect are refused with the flag they need,
/// and a GLINT_SIMD that is not taken is said.
#[test]
fn flags_without_effect_are_refused_and_a_bad_simd_level_is_said() {
    let sphere = scene();
    let out = glint(&["bench", &sphere, "--sweep-depths", "2,4", "--size", "8x8"]);
    assert_eq!(out.status.code(), Some(2));
    assert!(String::from_utf8_lossy(&out.stderr).contains("--sweep"));
    let tmp = common::temp_dir();
    let png = tmp.path().join("a.png");
    let out = Command::new(env!("CARGO_BIN_EXE_glint"))
        .env("GLINT_SIMD", "avx9")
        .args([
            "render",
            &sphere,
            "-o",
            png.to_str().unwrap(),
            "--width",
            "8",
            "--height",
            "8",
        ])
        .output()
        .unwrap();
    assert!(out.status.success());
    assert!(
        String::from_utf8_lossy(&out.stderr).contains("GLINT_SIMD=avx9 is not a level"),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
}

/// `glint SCENE` is `glint view SCENE` (the default command): without a
/// display it says the viewer needs one (or, built without the viewer,
/// that it is not compiled in), never "unrecognized subcommand".
#[test]
fn a_scene_as_the_first_argument_opens_the_viewer() {
    let out = Command::new(env!("CARGO_BIN_EXE_glint"))
        .env("DISPLAY", "")
        .env("WAYLAND_DISPLAY", "")
        .arg(scene())
        .output()
        .unwrap();
    let err = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(!err.contains("unrecognized subcommand"), "{err}");
    assert!(
        err.contains("display") || err.contains("without the viewer"),
        "{err}"
    );
}

/// `--max-depth` outside 1 to 64 is refused alike at both ends (0 was a
/// usage error, exit 2; 65 a render error, exit 1).
#[test]
fn max_depth_is_refused_alike_at_both_ends() {
    for depth in ["0", "65"] {
        let out = glint(&["render", &scene(), "-o", "x.png", "--max-depth", depth]);
        assert_eq!(out.status.code(), Some(2), "--max-depth {depth}");
        assert!(String::from_utf8_lossy(&out.stderr).contains("expected a ray depth from 1 to 64"));
    }
}

/// Ctrl+C during a render on a terminal ends the progress bar's line, so
/// the shell's prompt starts on a line of its own. `script` gives glint a
/// terminal; the byte 0x03 typed into it is the terminal's Ctrl+C.
#[test]
fn ctrl_c_on_a_terminal_ends_the_progress_line() {
    use std::io::{Read, Write};
    use std::process::Stdio;
    if Command::new("script").arg("--version").output().is_err() {
        eprintln!("skipped: no `script` (util-linux) to give glint a terminal");
        return;
    }
    let tmp = common::temp_dir();
    let out = tmp.path().join("big.png");
    let line = format!(
        "{} render {} --width 1600 --height 1200 --aa full --threads 1 -o {}",
        env!("CARGO_BIN_EXE_glint"),
        common::repo_path("scenes/default.toml").display(),
        out.display()
    );
    let mut child = Command::new("script")
        .args(["-qfec", &line, "/dev/null"])
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::null())
        .spawn()
        .unwrap();
    let mut stdout = child.stdout.take().unwrap();
    // Wait for the bar, then type Ctrl+C.
    let mut seen = Vec::new();
    let mut buf = [0u8; 4096];
    while !String::from_utf8_lossy(&seen).contains("rendering") {
        let n = stdout.read(&mut buf).unwrap();
        assert!(
            n > 0,
            "glint ended before its progress bar: {}",
            String::from_utf8_lossy(&seen)
        );
        seen.extend_from_slice(&buf[..n]);
    }
    child.stdin.as_mut().unwrap().write_all(b"\x03").unwrap();
    stdout.read_to_end(&mut seen).unwrap();
    let status = child.wait().unwrap();
    assert!(!status.success(), "interrupted");
    let text = String::from_utf8_lossy(&seen);
    let last = text.rfind("rendering").unwrap();
    assert!(
        text[last..].contains('\n'),
        "the progress line was left open: {:?}",
        &text[last..]
    );
    assert!(!out.exists(), "no partial image");
}
