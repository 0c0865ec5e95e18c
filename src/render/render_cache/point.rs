//! A kept point of the render cache, the pixels of a preview, and where a
//! pixel came from: shared by the cache and its passes.

use crate::material::Material;
use crate::math::Color;
use crate::render::renderer::Renderer;

/// Where a pixel of a preview came from.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PixelSource {
    /// A fresh eye ray traced for this frame.
    Fresh,
    /// A point kept from an earlier frame, moved into this view; its age in
    /// frames since it was traced (saturating at 255).
    Reprojected { age: u8 },
    /// A point an edit changed, not yet traced again: its old colour.
    Stale,
    /// No traced point: a blend of the neighbours (now or in an earlier
    /// frame, moved with the surface it was filled from).
    Filled,
}

/// A kept point: where an eye ray hit and the colour seen there. Positions
/// are `f32` relative to the cache's anchor (the eye it was seeded from):
/// relative to the scene's own origin, a scene far from it would lose the
/// sub-pixel precision reprojection needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Point {
    /// The hit relative to the anchor; for the background, the ray's direction.
    pub(super) position: [f32; 3],
    /// The colour as displayed.
    pub(super) rgb: [u8; 3],
    /// [`Point::BACKGROUND`], [`Point::STALE`], [`Point::FILLED`].
    pub(super) flags: u8,
    /// The frame it was traced (or filled) in, wrapping.
    pub(super) born: u16,
    /// How much its colour depends on the eye ([`view_weight`]), 0 to 255.
    pub(super) view_weight: u8,
    /// The material of the eye ray's hit ([`NO_MATERIAL`]: the background).
    pub(super) material: u16,
    /// The materials its ray tree met: material `m` as bit `m % 32` (all
    /// bits: not known).
    pub(super) touched: u32,
}

/// [`Point::material`] of the background (and of materials past the
/// 65,534th, which the culling's same-surface test then takes as one).
pub(super) const NO_MATERIAL: u16 = u16::MAX;

impl Point {
    /// The eye ray left the scene: `position` is a direction.
    pub(super) const BACKGROUND: u8 = 1;
    /// An edit changed what it shows; its colour is the old one.
    pub(super) const STALE: u8 = 2;
    /// Not traced: filled from its neighbours.
    pub(super) const FILLED: u8 = 4;
    /// No point: the pixel shows a colour blended from afar.
    pub(super) const NOTHING: u8 = 8;

    pub(super) const NONE: Point = Point {
        position: [0.0; 3],
        rgb: [0; 3],
        flags: Point::NOTHING,
        born: 0,
        view_weight: 0,
        material: NO_MATERIAL,
        touched: 0,
    };

    #[inline(always)]
    pub(super) fn is(&self, flag: u8) -> bool {
        self.flags & flag != 0
    }

    /// Its age at frame `now`, in frames, at most 255.
    #[inline(always)]
    pub(super) fn age(&self, now: u16) -> u8 {
        now.wrapping_sub(self.born).min(255) as u8
    }

    /// Where a pixel showing it at frame `now` came from.
    #[inline(always)]
    pub(super) fn source(&self, now: u16) -> PixelSource {
        if self.is(Point::FILLED | Point::NOTHING) {
            PixelSource::Filled
        } else if self.is(Point::STALE) {
            PixelSource::Stale
        } else {
            match self.age(now) {
                0 => PixelSource::Fresh,
                age => PixelSource::Reprojected { age },
            }
        }
    }
}

/// A material index as a point keeps it.
pub(super) fn material_of(m: u32) -> u16 {
    m.min(u32::from(NO_MATERIAL) - 1) as u16
}

/// How much a material's colour depends on the eye, 0 to 255: the weights
/// of its mirror and refracted rays, and of its highlight.
pub(super) fn view_weight(m: &Material) -> u8 {
    let w = m.reflectivity + m.transparency + m.ks.min(1.0);
    (w * 64.0).round().clamp(0.0, 255.0) as u8
}

/// A preview's pixels (kept from frame to frame, so none of them is
/// allocated anew).
#[derive(Default)]
pub(super) struct Pixels {
    /// The point each pixel shows ([`Point::NONE`]-like, with
    /// [`Point::NOTHING`]: none, its colour blended from afar).
    pub(super) points: Vec<Point>,
    /// The depth along the view of what each pixel shows (infinite for the
    /// background).
    pub(super) depth: Vec<f32>,
    /// The picture, RGBA8.
    pub(super) rgba: Vec<u8>,
}

/// The colour of a traced sample as displayed.
pub(super) fn display_rgb(renderer: &Renderer, color: Color) -> [u8; 3] {
    let c = renderer.settings().colors;
    [c.byte(color.x), c.byte(color.y), c.byte(color.z)]
}

/// Sets `v` to `n` copies of `value`, keeping its allocation.
pub(super) fn reset<T: Clone>(v: &mut Vec<T>, n: usize, value: T) {
    v.clear();
    v.resize(n, value);
}
