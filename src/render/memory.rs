//! What a render needs in memory, checked before it starts.

use crate::render::RenderError;
use crate::settings::{AntiAliasing, RenderSettings, ViewMode};

/// Memory a render of `settings` needs for its own buffers, in bytes: the
/// frame (a `DVec3` a pixel; each tile's values are freed once copied in), the
/// encoded picture (3 bytes a pixel, twice while a PNG is built), and the
/// extra frames of adaptive anti-aliasing, the aa-need view and the SPD
/// protocol's corners. The scene and its octree come on top.
pub fn estimated_bytes(settings: &RenderSettings) -> u64 {
    let pixels = settings.width as u64 * settings.height as u64;
    let mut per_pixel = 24 + 2 * 3;
    if settings.anti_aliasing() == AntiAliasing::Adaptive {
        per_pixel += 24 + 8 + 1 + 3;
    }
    if settings.view == ViewMode::AaNeed {
        per_pixel += 2 * 24;
    }
    let corners = if settings.corner_rays() {
        (settings.width as u64 + 1) * (settings.height as u64 + 1) * 24
    } else {
        0
    };
    pixels * per_pixel + corners
}

/// Memory this machine has available now (`MemAvailable` of
/// `/proc/meminfo`), or `None` where that cannot be read.
pub fn available_memory() -> Option<u64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: u64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024)
}

/// Refuses a render whose buffers (plus `other` bytes already held, such
/// as the octree) would not fit in 80% of the available memory.
pub fn check_memory(settings: &RenderSettings, other: u64) -> Result<(), RenderError> {
    match available_memory() {
        Some(available) => check_memory_against(settings, other, available),
        None => Ok(()),
    }
}

/// [`check_memory`] against a given amount of available memory.
pub fn check_memory_against(
    settings: &RenderSettings,
    other: u64,
    available: u64,
) -> Result<(), RenderError> {
    let needed = estimated_bytes(settings) + other;
    let limit = available / 10 * 8;
    if needed > limit {
        return Err(RenderError::OutOfMemory {
            width: settings.width,
            height: settings.height,
            needed,
            available: limit,
        });
    }
    Ok(())
}
