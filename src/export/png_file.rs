//! The PNG file itself: the record's text chunks and the private `glSc`
//! chunk written before the image data, and read back without decoding
//! the pixels.

use std::path::Path;

use super::error::ExportError;
use super::record::{
    KEY_SCENE, KEY_SCENE_PATH, KEY_SCENE_SHA256, KEY_SETTINGS, KEY_VERSION, MAX_SCENE_TEXT,
    RecordedSettings, RenderRecord, SCENE_CHUNK, sha256_hex, validate,
};

/// Encodes the PNG into `out`; errors name `path`, the file the user asked for.
pub(super) fn write_png(
    out: impl std::io::Write,
    path: &Path,
    width: u32,
    height: u32,
    rgb: &[u8],
    record: Option<&RenderRecord>,
) -> Result<(), ExportError> {
    let mut writer = start_png(out, path, (width, height), record, None)?;
    writer.write_image_data(rgb).map_err(encode_error(path))?;
    writer.finish().map_err(encode_error(path))
}

/// The frames of an animated PNG (APNG): how many, and each one's
/// display time as a fraction of a second (numerator, denominator).
#[derive(Clone, Copy, Debug)]
pub(super) struct Animation {
    pub frames: u32,
    pub delay: (u16, u16),
}

/// Encodes an animated PNG into `out`: `frames` gives each frame's RGB8
/// pixels in order (the first is also the still image viewers without
/// APNG support show); it loops forever.
pub(super) fn write_animated_png(
    out: impl std::io::Write,
    path: &Path,
    size: (u32, u32),
    animation: Animation,
    frames: &mut dyn Iterator<Item = Result<Vec<u8>, ExportError>>,
    record: Option<&RenderRecord>,
) -> Result<(), ExportError> {
    let mut writer = start_png(out, path, size, record, Some(animation))?;
    for rgb in frames {
        writer.write_image_data(&rgb?).map_err(encode_error(path))?;
    }
    writer.finish().map_err(encode_error(path))
}

fn encode_error(path: &Path) -> impl Fn(png::EncodingError) -> ExportError + '_ {
    move |e| ExportError::Encode {
        path: path.to_owned(),
        message: e.to_string(),
    }
}

/// The PNG's header and record chunks, up to its image data.
fn start_png<W: std::io::Write>(
    out: W,
    path: &Path,
    (width, height): (u32, u32),
    record: Option<&RenderRecord>,
    animation: Option<Animation>,
) -> Result<png::Writer<W>, ExportError> {
    let encode = encode_error(path);
    let mut encoder = png::Encoder::new(out, width, height);
    // fdeflate: at the default level, writing a render took more
    // instructions than tracing it; the fast level takes a tenth of that
    // for somewhat larger files (docs/notes/experiments.md, "Figures
    // behind constants").
    // An animation is written once from finished frames and kept or
    // shared as one file: it takes the balanced level.
    encoder.set_compression(if animation.is_some() {
        png::Compression::Balanced
    } else {
        png::Compression::Fast
    });
    if let Some(a) = animation {
        encoder.set_animated(a.frames, 0).map_err(&encode)?;
        encoder
            .set_frame_delay(a.delay.0, a.delay.1)
            .map_err(&encode)?;
    }
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    encoder
        .add_text_chunk(
            "Software".into(),
            format!("glint {}", env!("CARGO_PKG_VERSION")),
        )
        .map_err(&encode)?;
    let mut writer = encoder.write_header().map_err(&encode)?;
    if let Some(r) = record {
        let settings = serde_json::to_string(&r.settings).map_err(|e| ExportError::Encode {
            path: path.to_owned(),
            message: e.to_string(),
        })?;
        for (key, text) in [
            (KEY_VERSION, r.glint_version.as_str()),
            (KEY_SCENE_PATH, r.scene_path.as_str()),
            (KEY_SCENE_SHA256, r.scene_sha256.as_str()),
            (KEY_SETTINGS, settings.as_str()),
        ] {
            let mut chunk = png::text_metadata::ITXtChunk::new(key, text);
            // Settings with many edited materials can grow; compressed they
            // stay far below what readers accept.
            chunk.compressed = text.len() > 1024;
            writer.write_text_chunk(&chunk).map_err(&encode)?;
        }
        if !r.settings.scene_not_embedded {
            let scene = compress(r.scene_text.as_bytes()).map_err(|e| ExportError::Encode {
                path: path.to_owned(),
                message: e.to_string(),
            })?;
            writer
                .write_chunk(png::chunk::ChunkType(SCENE_CHUNK), &scene)
                .map_err(&encode)?;
        }
    }
    Ok(writer)
}

/// Reads the record glint wrote into a PNG.
pub fn read_record(path: &Path) -> Result<RenderRecord, ExportError> {
    let file = std::fs::File::open(path).map_err(|source| ExportError::Read {
        path: path.to_owned(),
        source,
    })?;
    read_record_from(std::io::BufReader::new(file), path)
}

/// Reads the record from PNG bytes in memory; `path` names them in errors.
pub fn read_record_bytes(bytes: &[u8], path: &Path) -> Result<RenderRecord, ExportError> {
    read_record_from(std::io::Cursor::new(bytes), path)
}

fn read_record_from<R: std::io::BufRead + std::io::Seek>(
    mut source: R,
    path: &Path,
) -> Result<RenderRecord, ExportError> {
    let decode = |message: String| ExportError::Decode {
        path: path.to_owned(),
        message,
    };
    let read_error = |source| ExportError::Read {
        path: path.to_owned(),
        source,
    };
    let scene_chunk = private_chunk(&mut source, path, SCENE_CHUNK)?;
    source
        .seek(std::io::SeekFrom::Start(0))
        .map_err(read_error)?;
    // glint writes its text chunks before the image data, so reading the
    // header chunks is enough: the pixels are never decoded (a crafted
    // header cannot make this allocate).
    let reader = png::Decoder::new(source).read_info().map_err(|e| match e {
        png::DecodingError::IoError(io) if io.kind() == std::io::ErrorKind::UnexpectedEof => {
            decode(TRUNCATED.to_owned())
        }
        e => decode(e.to_string()),
    })?;
    let info = reader.info();
    let text = |key: &'static str| -> Result<String, ExportError> {
        let chunk = info
            .utf8_text
            .iter()
            .find(|c| c.keyword == key)
            .ok_or_else(|| ExportError::Missing {
                path: path.to_owned(),
                key,
            })?;
        chunk.get_text().map_err(|e| ExportError::Malformed {
            path: path.to_owned(),
            key,
            message: e.to_string(),
        })
    };
    let settings_json = text(KEY_SETTINGS)?;
    let settings: RecordedSettings =
        serde_json::from_str(&settings_json).map_err(|e| ExportError::Malformed {
            path: path.to_owned(),
            key: KEY_SETTINGS,
            message: e.to_string(),
        })?;
    // Records written before the private chunk existed keep the scene in
    // an iTXt chunk.
    let scene_text = match scene_chunk {
        Some(data) => decompress(&data).map_err(|message| ExportError::Malformed {
            path: path.to_owned(),
            key: KEY_SCENE,
            message,
        })?,
        None if settings.scene_not_embedded => String::new(),
        None => text(KEY_SCENE)?,
    };
    let record = RenderRecord {
        glint_version: text(KEY_VERSION)?,
        scene_path: text(KEY_SCENE_PATH)?,
        scene_sha256: text(KEY_SCENE_SHA256)?,
        scene_text,
        settings,
    };
    validate(&record.settings).map_err(|message| ExportError::Malformed {
        path: path.to_owned(),
        key: KEY_SETTINGS,
        message,
    })?;
    let computed = sha256_hex(record.scene_text.as_bytes());
    if !record.settings.scene_not_embedded && computed != record.scene_sha256 {
        return Err(ExportError::Checksum {
            path: path.to_owned(),
            recorded: record.scene_sha256,
            computed,
        });
    }
    Ok(record)
}

fn compress(data: &[u8]) -> std::io::Result<Vec<u8>> {
    use std::io::Write;
    let mut encoder = flate2::write::ZlibEncoder::new(Vec::new(), flate2::Compression::default());
    encoder.write_all(data)?;
    encoder.finish()
}

/// Inflates a zlib stream into UTF-8 text of at most [`MAX_SCENE_TEXT`] bytes.
fn decompress(data: &[u8]) -> Result<String, String> {
    use std::io::Read;
    let mut out = Vec::new();
    flate2::read::ZlibDecoder::new(data)
        .take(MAX_SCENE_TEXT as u64 + 1)
        .read_to_end(&mut out)
        .map_err(|e| format!("cannot decompress: {e}"))?;
    if out.len() > MAX_SCENE_TEXT {
        return Err(format!("scene text exceeds {MAX_SCENE_TEXT} bytes"));
    }
    String::from_utf8(out).map_err(|e| format!("not UTF-8 text: {e}"))
}

/// The data of the first chunk of type `kind` before the image data, if
/// any. The png crate skips chunks it does not know, so glint walks the
/// chunk list itself (PNG spec, section 5.3: length, type, data, CRC).
/// What a PNG that ends early is called (the reader's own words, "failed
/// to fill whole buffer", say nothing to a user).
const TRUNCATED: &str = "the file is truncated: it ends before the PNG's header chunks do (an interrupted copy or download?)";

fn private_chunk(
    mut file: impl std::io::Read,
    path: &Path,
    kind: [u8; 4],
) -> Result<Option<Vec<u8>>, ExportError> {
    use std::io::Read;
    let decode = |message: &str| ExportError::Decode {
        path: path.to_owned(),
        message: message.to_owned(),
    };
    let read_error = |source: std::io::Error| {
        if source.kind() == std::io::ErrorKind::UnexpectedEof {
            decode(TRUNCATED)
        } else {
            ExportError::Read {
                path: path.to_owned(),
                source,
            }
        }
    };
    let mut signature = [0u8; 8];
    file.read_exact(&mut signature).map_err(read_error)?;
    if signature != *b"\x89PNG\r\n\x1a\n" {
        return Err(decode("not a PNG file"));
    }
    let mut first = true;
    loop {
        let mut header = [0u8; 8];
        if file.read_exact(&mut header).is_err() {
            return Ok(None);
        }
        let length = u32::from_be_bytes([header[0], header[1], header[2], header[3]]);
        let chunk_type = [header[4], header[5], header[6], header[7]];
        // A PNG's first chunk is its image header (PNG specification,
        // 5.6); anything else is not a PNG, whatever its first bytes say.
        if first && &chunk_type != b"IHDR" {
            return Err(decode(
                "damaged or not a PNG: it starts like one, but its first chunk is not the image header (IHDR)",
            ));
        }
        first = false;
        if &chunk_type == b"IDAT" || &chunk_type == b"IEND" {
            return Ok(None);
        }
        if chunk_type != kind {
            // Skip the data and the CRC.
            std::io::copy(
                &mut (&mut file).take(length as u64 + 4),
                &mut std::io::sink(),
            )
            .map_err(read_error)?;
            continue;
        }
        let mut data = Vec::new();
        (&mut file)
            .take(length as u64)
            .read_to_end(&mut data)
            .map_err(read_error)?;
        let mut crc = [0u8; 4];
        file.read_exact(&mut crc).map_err(read_error)?;
        if data.len() != length as usize {
            return Err(decode("the file ends inside a chunk"));
        }
        let mut hasher = crc32fast::Hasher::new();
        hasher.update(&chunk_type);
        hasher.update(&data);
        if hasher.finalize() != u32::from_be_bytes(crc) {
            return Err(decode("the scene chunk is corrupt (CRC mismatch)"));
        }
        return Ok(Some(data));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scene_text_compresses_losslessly_and_garbage_is_refused() {
        let text = "[camera]\neye = [0, 1, 2]\n# ünïcödé\n".repeat(100);
        let packed = compress(text.as_bytes()).unwrap();
        assert!(packed.len() < text.len() / 10);
        assert_eq!(decompress(&packed).unwrap(), text);
        assert!(decompress(b"not zlib").is_err());
        let not_utf8 = compress(&[0xff, 0xfe, 0x00]).unwrap();
        assert!(decompress(&not_utf8).unwrap_err().contains("UTF-8"));
    }

    #[test]
    fn a_png_that_ends_early_is_called_truncated() {
        let path = Path::new("t.png");
        let mut bytes = Vec::new();
        write_png(&mut bytes, path, 4, 3, &[7u8; 4 * 3 * 3], None).unwrap();
        for cut in [0, 5, 8, 20, 40] {
            let e = read_record_bytes(&bytes[..cut], path)
                .unwrap_err()
                .to_string();
            assert!(e.contains("truncated"), "{cut} bytes: {e}");
        }
        // Whole, it reads on to the missing record: not truncated.
        let e = read_record_bytes(&bytes, path).unwrap_err().to_string();
        assert!(!e.contains("truncated"), "{e}");
    }

    #[test]
    fn a_file_that_only_starts_like_a_png_is_said_in_words() {
        // The signature, then text: no chunk type in Rust's debug form.
        let mut bytes = b"\x89PNG\r\n\x1a\n".to_vec();
        bytes.extend_from_slice(b"this is really not an image at all");
        let e = read_record_bytes(&bytes, Path::new("fake.png"))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("fake.png is not a readable PNG: damaged or not a PNG"),
            "{e}"
        );
        assert!(!e.contains('{'), "{e}");
    }
}
