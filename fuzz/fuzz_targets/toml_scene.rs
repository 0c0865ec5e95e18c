//! glint's TOML scene format: any bytes as a `.toml` scene, whose mesh
//! objects read a small OBJ model with its MTL library from memory.
#![no_main]

use glint_fuzz::{MemoryFiles, QUAD_MTL, QUAD_OBJ, load_and_check};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let files = MemoryFiles {
        scene: data,
        obj: QUAD_OBJ,
        mtl: QUAD_MTL,
    };
    load_and_check("fuzz.toml", &files);
});
