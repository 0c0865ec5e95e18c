//! Eric Haines's NFF (the SPD scenes): any bytes as a `.nff` scene.
#![no_main]

use glint_fuzz::{MemoryFiles, load_and_check};
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let files = MemoryFiles {
        scene: data,
        ..MemoryFiles::default()
    };
    load_and_check("fuzz.nff", &files);
});
