//! Helpers shared by the integration tests.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::sync::Arc;

use glint::accel::Octree;
use glint::render::{Accelerator, Renderer, Reuse};
use glint::scene::Scene;
use glint::settings::RenderSettings;
use glint::stats::RenderCounts;

#[cfg(feature = "gui")]
pub mod viewer;

/// Runs the `glint` binary with `args` and returns what it printed.
pub fn glint_output(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_glint"))
        .args(args)
        .output()
        .unwrap()
}

pub fn repo_path(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)
}

/// A scene from `text`; `name`'s extension picks the format and names it
/// in errors.
pub fn scene_from(text: &str, name: &str) -> Scene {
    glint::scene::load_str(text, Path::new(name), &glint::scene::FileSystem)
        .unwrap_or_else(|e| panic!("{e}"))
}

/// A fresh directory, removed when the value is dropped.
pub fn temp_dir() -> tempfile::TempDir {
    tempfile::tempdir().unwrap()
}

pub fn load(rel: &str) -> Scene {
    let path = repo_path(rel);
    glint::scene::load(&path).unwrap_or_else(|e| panic!("{e}"))
}

/// A scene of `scenes/` loaded and its octree built once per test run:
/// several tests go through every scene, and the largest take seconds to
/// load and build. (Each caller gets the same shared copy.)
pub fn loaded(rel: &str) -> std::sync::Arc<(Scene, Arc<Octree>)> {
    use std::collections::HashMap;
    use std::sync::{Mutex, OnceLock};
    type Cache = Mutex<HashMap<String, Arc<OnceLock<Arc<(Scene, Arc<Octree>)>>>>>;
    static CACHE: OnceLock<Cache> = OnceLock::new();
    // The map's lock is held only to find the scene's slot, so two scenes
    // load at once; one scene loads once.
    let slot = CACHE
        .get_or_init(Cache::default)
        .lock()
        .unwrap_or_else(|e| e.into_inner())
        .entry(rel.to_string())
        .or_default()
        .clone();
    slot.get_or_init(|| {
        let scene = load(rel);
        let octree = scene
            .build_octree()
            .unwrap_or_else(|e| panic!("{rel}: {e}"));
        Arc::new((scene, Arc::new(octree)))
    })
    .clone()
}

/// Every scene file under `scenes/` (TOML and NFF, recursively), sorted;
/// not `scenes/paths/`, which holds camera paths for scenes.
pub fn all_scenes() -> Vec<String> {
    fn walk(dir: &Path, out: &mut Vec<PathBuf>) {
        for entry in std::fs::read_dir(dir).unwrap() {
            let p = entry.unwrap().path();
            if p.ends_with("scenes/paths") {
                continue;
            }
            if p.is_dir() {
                walk(&p, out);
            } else if matches!(p.extension().and_then(|e| e.to_str()), Some("toml" | "nff")) {
                out.push(p);
            }
        }
    }
    let root = repo_path("scenes");
    let mut out = Vec::new();
    walk(&root, &mut out);
    out.sort();
    out.into_iter()
        .map(|p| {
            p.strip_prefix(repo_path(""))
                .unwrap()
                .to_string_lossy()
                .into_owned()
        })
        .collect()
}

/// Renders at `width` x `height` with the given overrides; returns the 8-bit
/// image and the counts.
pub fn render_with(
    scene: &Scene,
    octree: &Arc<Octree>,
    width: u32,
    height: u32,
    adjust: impl FnOnce(&mut RenderSettings),
) -> (Vec<u8>, RenderCounts) {
    let mut settings = scene.render_settings();
    settings.width = width;
    settings.height = height;
    adjust(&mut settings);
    // With the light buffer a release render has (it answers only where
    // an accelerator would, so octree-off renders stay brute force).
    let accel = accelerator(scene, &settings, Some(octree));
    let renderer = Renderer::new(scene, &accel, settings).unwrap();
    let (frame, counts) = renderer.render(false, None);
    (frame.to_rgb8(), counts)
}

/// The accelerator `settings` ask for over `scene`, through `octree`
/// (built over its shapes) when they ask for the octree and one is given,
/// with the light buffer a release render has.
pub fn accelerator(
    scene: &Scene,
    settings: &RenderSettings,
    octree: Option<&Arc<Octree>>,
) -> Accelerator {
    let reuse = Reuse {
        octree: octree.cloned(),
        ..Reuse::default()
    };
    Accelerator::build(scene, settings, reuse).unwrap()
}

/// Number of pixels whose channels differ by more than `tolerance`, and the
/// largest channel difference.
pub fn diff(a: &[u8], b: &[u8], tolerance: u8) -> (usize, u8) {
    assert_eq!(a.len(), b.len());
    let mut count = 0;
    let mut largest = 0;
    for (pa, pb) in a.chunks_exact(3).zip(b.chunks_exact(3)) {
        let d = pa
            .iter()
            .zip(pb)
            .map(|(x, y)| x.abs_diff(*y))
            .max()
            .unwrap();
        largest = largest.max(d);
        if d > tolerance {
            count += 1;
        }
    }
    (count, largest)
}

/// Runs `glint render --from-png first -o again` and compares the two
/// PNGs: returns the number of differing pixels and the largest difference.
pub fn rerender_from_png(first: &Path, again: &Path) -> (usize, u8) {
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_glint"))
        .args(["render", "--from-png"])
        .arg(first)
        .arg("-o")
        .arg(again)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}: {}",
        first.display(),
        String::from_utf8_lossy(&out.stderr)
    );
    let a = image::open(first).unwrap().to_rgb8();
    let b = image::open(again).unwrap().to_rgb8();
    assert_eq!(a.dimensions(), b.dimensions(), "{}", first.display());
    diff(a.as_raw(), b.as_raw(), 0)
}
