//! The record glint writes into its PNG exports (`glint info`,
//! `--from-png`). The first byte picks one of two inputs:
//! - even: the rest is a PNG file, read as a record and its scene loaded;
//! - odd: the rest is a record's settings (JSON), scene path and scene
//!   text, split by [`PART`]: written into a PNG, it must read back as the
//!   same record, or be refused for its settings alone.
#![no_main]

use std::path::Path;

use glint::export::{
    ExportError, KEY_SETTINGS, RecordedSettings, RenderRecord, load_recorded_scene_with, png_bytes,
    read_record_bytes, sha256_hex,
};
use glint_fuzz::{MemoryFiles, QUAD_MTL, QUAD_OBJ, check_scene};
use libfuzzer_sys::fuzz_target;

const PART: &[u8] = b"\n#--part--\n";

fn split(data: &[u8]) -> Vec<&[u8]> {
    let mut parts = Vec::new();
    let mut rest = data;
    while let Some(i) = rest.windows(PART.len()).position(|w| w == PART) {
        parts.push(&rest[..i]);
        rest = &rest[i + PART.len()..];
    }
    parts.push(rest);
    parts
}

fn read_png(png: &[u8]) {
    let Ok(record) = read_record_bytes(png, Path::new("fuzz.png")) else {
        return;
    };
    let files = MemoryFiles {
        scene: record.scene_text.as_bytes(),
        obj: QUAD_OBJ,
        mtl: QUAD_MTL,
    };
    if let Ok(mut scene) = load_recorded_scene_with(&record, &files) {
        check_scene(&mut scene);
    }
}

fn round_trip(data: &[u8]) {
    let parts = split(data);
    let [settings, scene_path, scene_text] = parts[..] else {
        return;
    };
    let (Ok(settings), Ok(scene_path), Ok(scene_text)) = (
        std::str::from_utf8(settings),
        std::str::from_utf8(scene_path),
        std::str::from_utf8(scene_text),
    ) else {
        return;
    };
    let Ok(settings) = serde_json::from_str::<RecordedSettings>(settings) else {
        return;
    };
    let record = RenderRecord {
        glint_version: env!("CARGO_PKG_VERSION").to_owned(),
        scene_path: scene_path.to_owned(),
        scene_sha256: sha256_hex(scene_text.as_bytes()),
        scene_text: scene_text.to_owned(),
        settings,
    };
    let png = png_bytes(
        Path::new("fuzz.png"),
        2,
        1,
        &[0, 64, 128, 255, 32, 16],
        Some(&record),
    )
    .expect("any record can be written");
    match read_record_bytes(&png, Path::new("fuzz.png")) {
        Ok(read) => assert_eq!(read, record, "the record read back differs"),
        Err(ExportError::Malformed { key, .. }) if key == KEY_SETTINGS => {}
        Err(e) => panic!("a record glint wrote is refused: {e}"),
    }
}

fuzz_target!(|data: &[u8]| {
    match data.split_first() {
        Some((mode, rest)) if mode % 2 == 1 => round_trip(rest),
        Some((_, rest)) => read_png(rest),
        None => {}
    }
});
