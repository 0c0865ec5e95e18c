//! What glint's fuzz targets share: input files held in memory, and the
//! checks every scene that loads must then pass (it renders, octree on and
//! off give the same bytes, no pixel is NaN or infinite).
//!
//! The targets are in `fuzz_targets/`; README.md, "Fuzzing", says how to
//! run them.

use std::path::Path;
use std::sync::OnceLock;

use glint::accel::{Octree, OctreeError};
use glint::render::{Accelerator, Renderer, Reuse};
use glint::settings::{Accel, RenderSettings};
use glint::scene::{FileSource, Scene};

/// Files by extension: the scene (`.toml`, `.nff`), the model (`.obj`) and
/// its material library (`.mtl`). Any other path is not found, so a fuzzed
/// scene never reaches the real file system.
#[derive(Default)]
pub struct MemoryFiles<'a> {
    pub scene: &'a [u8],
    pub obj: &'a [u8],
    pub mtl: &'a [u8],
}

impl FileSource for MemoryFiles<'_> {
    fn read(&self, path: &Path) -> std::io::Result<Vec<u8>> {
        let extension = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match extension.as_deref() {
            Some("toml" | "nff") => Ok(self.scene.to_vec()),
            Some("obj") => Ok(self.obj.to_vec()),
            Some("mtl") => Ok(self.mtl.to_vec()),
            _ => Err(std::io::ErrorKind::NotFound.into()),
        }
    }
}

/// A small model for scenes that name a mesh: a quad with normals and a
/// material library.
pub const QUAD_OBJ: &[u8] = b"mtllib quad.mtl\nv -1 0 -1\nv 1 0 -1\nv 1 0 1\nv -1 0 1\n\
vn 0 1 0\nusemtl red\nf 1//1 2//1 3//1 4//1\n";
pub const QUAD_MTL: &[u8] = b"newmtl red\nKd 0.8 0.1 0.1\nKs 0.2 0.2 0.2\nNs 20\n";

/// Runs `work` on one worker thread: rayon's global pool would spawn one per core for
/// every input, and the fuzzer runs one input at a time anyway.
pub fn single_thread<R: Send>(work: impl FnOnce() -> R + Send) -> R {
    static POOL: OnceLock<rayon::ThreadPool> = OnceLock::new();
    POOL.get_or_init(|| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(1)
            .build()
            .expect("a one-thread pool")
    })
    .install(work)
}

/// Largest scene the checks render: bigger ones (possible from a few
/// kilobytes of NFF) are only built, to keep the fuzzer fast.
const RENDER_SHAPES: usize = 200;

/// What every loaded scene must do: build its octree within its memory
/// budget, and, when small, render a few pixels with finite values that
/// are byte-identical with the octree on and off.
pub fn check_scene(scene: &mut Scene) {
    // The fuzzer's inputs may ask for 4 GiB: the budget is what is being
    // checked, not how much the machine has.
    // Depth 6 keeps a build fast (the geometry target goes deeper).
    scene.octree_params.memory_budget_mib = scene.octree_params.memory_budget_mib.min(1);
    scene.octree_params.max_depth = scene.octree_params.max_depth.min(6);
    let octree = match single_thread(|| Octree::build(&scene.shapes, scene.octree_params)) {
        Ok(o) => o,
        Err(OctreeError::OutOfMemory { .. }) => return,
        // Loading checks the parameters: a loaded scene past them is a bug.
        Err(e @ OctreeError::Limit(_)) => panic!("a loaded scene's octree parameters: {e}"),
    };
    let stats = octree.stats();
    // A split is taken only if it fits the budget; the slack is for the
    // root, always built with every reference (a few hundred here).
    assert!(
        stats.memory_bytes <= stats.memory_budget_bytes + 4096,
        "octree took {} bytes of a {} budget",
        stats.memory_bytes,
        stats.memory_budget_bytes
    );
    if scene.shapes.len() > RENDER_SHAPES {
        return;
    }
    let mut settings = scene.render_settings();
    // Twelve eye rays and their trees: enough to reach shading, shadows,
    // reflection and refraction, few enough for thousands of inputs a second.
    settings.width = 4;
    settings.height = 3;
    settings.samples = 1;
    settings.adaptive = false;
    settings.max_depth = settings.max_depth.min(4);
    // The octree's render asks the light buffer too: its answers must be
    // brute force's.
    let octree = std::sync::Arc::new(octree);
    let render = |accel: Accel| {
        let s = RenderSettings { accel, ..settings };
        let reuse = Reuse {
            octree: Some(std::sync::Arc::clone(&octree)),
            ..Reuse::default()
        };
        let built = single_thread(|| Accelerator::build(scene, &s, reuse)).ok()?;
        let renderer = Renderer::new(scene, &built, s).ok()?;
        Some(single_thread(|| renderer.render(false, None)).0)
    };
    let Some(on) = render(Accel::Octree) else {
        return;
    };
    for p in &on.pixels {
        assert!(p.is_finite(), "a pixel is {p}");
    }
    let off = render(Accel::BruteForce).expect("the same settings render");
    assert_eq!(
        on.to_rgb8(),
        off.to_rgb8(),
        "octree on and off give different pixels"
    );
}

/// Loads `files.scene` as `name` (its extension picks the format); a
/// scene that loads is checked, and its text loads again to the same scene.
pub fn load_and_check(name: &str, files: &MemoryFiles) {
    let path = Path::new(name);
    let Ok(mut scene) = glint::scene::load_with(path, files) else {
        return;
    };
    let again = glint::scene::load_str(&scene.source_text, path, files)
        .expect("the scene's own text loads");
    assert_same_scene(&scene, &again);
    check_scene(&mut scene);
}

/// Everything a scene file says, compared.
pub fn assert_same_scene(a: &Scene, b: &Scene) {
    assert_eq!(a.camera, b.camera);
    assert_eq!(a.image, b.image);
    assert_eq!(a.octree_enabled, b.octree_enabled);
    assert_eq!(a.octree_params, b.octree_params);
    assert_eq!(a.materials, b.materials);
    assert_eq!(a.lights, b.lights);
    assert_eq!(a.shapes, b.shapes);
    assert_eq!(a.shape_materials, b.shape_materials);
    assert_eq!(a.vertex_normals, b.vertex_normals);
}
