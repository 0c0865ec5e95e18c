//! A Wavefront OBJ model opened on its own, with its MTL library: the
//! input is the OBJ text, then [`SEPARATOR`], then the MTL text (which
//! every `mtllib` of the model reads). glint frames the model in a scene
//! it writes; that text must load back to the same scene.
#![no_main]

use glint_fuzz::{MemoryFiles, load_and_check};
use libfuzzer_sys::fuzz_target;

/// Between the two files (also in the dictionary and the seeds).
const SEPARATOR: &[u8] = b"\n#--mtl--\n";

fuzz_target!(|data: &[u8]| {
    let (obj, mtl) = match data.windows(SEPARATOR.len()).position(|w| w == SEPARATOR) {
        Some(i) => (&data[..i], &data[i + SEPARATOR.len()..]),
        None => (data, &[][..]),
    };
    let files = MemoryFiles {
        scene: &[],
        obj,
        mtl,
    };
    load_and_check("fuzz.obj", &files);
});
