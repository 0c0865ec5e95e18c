//! Image textures on OBJ/MTL and TOML materials: each file decoded once
//! into 8-bit RGBA, sampled bilinearly, repeating past the unit square
//! (or, with MTL's `-clamp on`, one copy with the material's own colour
//! around it).
//!
//! Colour channels hold display values (sRGB-encoded, as image files do):
//! a linear render decodes each of the four texels it blends before
//! blending, so filtering averages light, not encoded numbers. There are no
//! mip-maps: a texture seen smaller than its texels takes four texels per
//! ray, and the 16 rays of a pixel's 4x4 grid average what they find.

use std::path::{Path, PathBuf};

use crate::color::{ColorConvention, srgb_to_linear};
use crate::math::{Color, DVec3};

/// A decoded image.
#[derive(Clone, PartialEq)]
pub struct Texture {
    /// The file the image was read from.
    pub path: PathBuf,
    pub width: u32,
    pub height: u32,
    /// RGBA from the top row down; colour display-encoded, alpha linear.
    texels: Vec<[u8; 4]>,
    /// Whether any texel is less than fully opaque.
    pub has_alpha: bool,
}

impl std::fmt::Debug for Texture {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "Texture({}, {}x{})",
            self.path.display(),
            self.width,
            self.height
        )
    }
}

/// Which value of a texture a map reads.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Channel {
    /// The colour (and, for a cut-out, its alpha).
    #[default]
    Color,
    /// One value: the alpha where the image has one, else its grey level
    /// (MTL's `map_d`).
    Value,
}

/// A texture placed on a material: which one, how its coordinates are
/// scaled and offset (MTL's `-s` and `-o`: the image is looked up at
/// `uv * scale + offset`), and whether it repeats.
#[derive(Clone, Debug, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct TextureMap {
    /// Index into the scene's textures.
    pub texture: u32,
    /// The name the scene file gave it (for notes, panels and saving).
    pub name: String,
    pub scale: [f64; 2],
    pub offset: [f64; 2],
    /// One copy on the unit square instead of repeating copies.
    pub clamp: bool,
    pub channel: Channel,
}

impl TextureMap {
    /// `texture`, named `name`, unscaled and repeating.
    pub fn new(texture: u32, name: String) -> Self {
        Self {
            texture,
            name,
            scale: [1.0, 1.0],
            offset: [0.0, 0.0],
            clamp: false,
            channel: Channel::Color,
        }
    }

    /// Where the image is looked up for the surface coordinates `uv`;
    /// `None` off the single copy of a clamped map.
    #[inline]
    pub fn lookup(&self, uv: [f64; 2]) -> Option<[f64; 2]> {
        let s = [
            uv[0] * self.scale[0] + self.offset[0],
            uv[1] * self.scale[1] + self.offset[1],
        ];
        if self.clamp && !(s.iter().all(|x| (0.0..=1.0).contains(x))) {
            return None;
        }
        s.iter().all(|x| x.is_finite()).then_some(s)
    }
}

/// Texels as a render shades them: display values decoded into linear
/// light for a linear render, as they are for a display render.
pub struct TexelValues {
    table: [f64; 256],
}

impl TexelValues {
    pub fn new(render: ColorConvention) -> Self {
        let mut table = [0.0; 256];
        for (i, v) in table.iter_mut().enumerate() {
            let x = i as f64 / 255.0;
            *v = match render {
                ColorConvention::Linear => srgb_to_linear(x),
                ColorConvention::Display => x,
            };
        }
        Self { table }
    }

    #[inline]
    fn color(&self, t: [u8; 4]) -> Color {
        DVec3::new(
            self.table[t[0] as usize],
            self.table[t[1] as usize],
            self.table[t[2] as usize],
        )
    }
}

impl Texture {
    /// Decodes `bytes` (PNG, JPEG, TGA or BMP; the format from the content,
    /// or for TGA, which has no signature, from `path`'s extension).
    pub fn decode(path: &Path, bytes: &[u8]) -> Result<Self, String> {
        use image::ImageFormat;
        if bytes.is_empty() {
            return Err("the file is empty".into());
        }
        // TGA alone has no signature: only its extension names it.
        let tga = ImageFormat::from_path(path).ok() == Some(ImageFormat::Tga);
        let format = image::guess_format(bytes)
            .ok()
            .or(tga.then_some(ImageFormat::Tga))
            .ok_or("not an image glint reads (PNG, JPEG, TGA or BMP)")?;
        if !matches!(
            format,
            ImageFormat::Png | ImageFormat::Jpeg | ImageFormat::Tga | ImageFormat::Bmp
        ) {
            return Err(format!(
                "a {} image, which glint does not read (PNG, JPEG, TGA or BMP)",
                format
                    .extensions_str()
                    .first()
                    .unwrap_or(&"?")
                    .to_uppercase()
            ));
        }
        let image = image::load_from_memory_with_format(bytes, format)
            .map_err(|e| format!("cannot decode it: {e}"))?
            .into_rgba8();
        let (width, height) = image.dimensions();
        if width == 0 || height == 0 {
            return Err("the image has no pixels".into());
        }
        let texels: Vec<[u8; 4]> = image.pixels().map(|p| p.0).collect();
        Ok(Self {
            path: path.to_path_buf(),
            width,
            height,
            has_alpha: texels.iter().any(|t| t[3] < 255),
            texels,
        })
    }

    /// A texture made of `texels` (RGBA, top row first), for tests.
    #[cfg(test)]
    pub(crate) fn from_texels(name: &str, width: u32, height: u32, texels: Vec<[u8; 4]>) -> Self {
        assert_eq!(texels.len(), width as usize * height as usize);
        Self {
            path: PathBuf::from(name),
            width,
            height,
            has_alpha: texels.iter().any(|t| t[3] < 255),
            texels,
        }
    }

    /// Bytes the decoded image holds.
    pub fn memory_bytes(&self) -> u64 {
        self.texels.len() as u64 * 4
    }

    /// The four texels nearest image coordinates `st` (`[0, 1]` across
    /// the image, `t` up from its bottom row as OBJ's `vt` counts) with
    /// their bilinear weights; `clamp` keeps the edge texels at the border
    /// instead of wrapping around to the other side.
    #[inline]
    fn nearest_four(&self, st: [f64; 2], clamp: bool) -> [([u8; 4], f64); 4] {
        let (w, h) = (self.width as i64, self.height as i64);
        // Texel centres sit at half-integers; image rows count down.
        let x = st[0] * w as f64 - 0.5;
        let y = (1.0 - st[1]) * h as f64 - 0.5;
        let (x0, y0) = (x.floor(), y.floor());
        let (fx, fy) = (x - x0, y - y0);
        // Past the image (a huge scale), float-to-int saturates and NaN
        // gives 0; wrapping and clamping keep every index inside.
        let index = |i: f64, n: i64| -> usize {
            let i = i as i64;
            (if clamp {
                i.clamp(0, n - 1)
            } else {
                i.rem_euclid(n)
            }) as usize
        };
        let (fx, fy) = if fx.is_finite() && fy.is_finite() {
            (fx, fy)
        } else {
            (0.0, 0.0)
        };
        let (xa, xb) = (index(x0, w), index(x0 + 1.0, w));
        let (ya, yb) = (index(y0, h), index(y0 + 1.0, h));
        let at = |x: usize, y: usize| self.texels[y * w as usize + x];
        [
            (at(xa, ya), (1.0 - fx) * (1.0 - fy)),
            (at(xb, ya), fx * (1.0 - fy)),
            (at(xa, yb), (1.0 - fx) * fy),
            (at(xb, yb), fx * fy),
        ]
    }

    /// The colour and alpha at image coordinates `st`, blended from the
    /// four nearest texels.
    #[inline]
    pub fn sample(&self, st: [f64; 2], clamp: bool, values: &TexelValues) -> (Color, f64) {
        let mut color = DVec3::ZERO;
        let mut alpha = 0.0;
        for (t, weight) in self.nearest_four(st, clamp) {
            color += weight * values.color(t);
            alpha += weight * t[3] as f64 / 255.0;
        }
        (color, alpha)
    }

    /// How much of the surface is there at `st`, from 0 (a gap) to 1:
    /// for a colour map its alpha, for a `map_d` its alpha where the image
    /// has one, else its grey level (the mean of the three channels).
    #[inline]
    pub fn coverage(&self, st: [f64; 2], clamp: bool, channel: Channel) -> f64 {
        let grey = channel == Channel::Value && !self.has_alpha;
        self.nearest_four(st, clamp)
            .iter()
            .map(|&(t, weight)| {
                let v = if grey {
                    (t[0] as f64 + t[1] as f64 + t[2] as f64) / 3.0
                } else {
                    t[3] as f64
                };
                weight * v / 255.0
            })
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn checker() -> Texture {
        // 2x2: top row red, white; bottom row black (half transparent), blue.
        Texture::from_texels(
            "checker",
            2,
            2,
            vec![
                [255, 0, 0, 255],
                [255, 255, 255, 255],
                [0, 0, 0, 128],
                [0, 0, 255, 255],
            ],
        )
    }

    #[test]
    fn texel_centres_give_their_texel_and_rows_count_up_from_the_bottom() {
        let t = checker();
        let display = TexelValues::new(ColorConvention::Display);
        // (0.25, 0.75) is the centre of the top-left texel.
        assert_eq!(
            t.sample([0.25, 0.75], false, &display).0,
            DVec3::new(1.0, 0.0, 0.0)
        );
        assert_eq!(
            t.sample([0.75, 0.25], false, &display).0,
            DVec3::new(0.0, 0.0, 1.0)
        );
        let (black, alpha) = t.sample([0.25, 0.25], false, &display);
        assert_eq!((black, alpha), (DVec3::ZERO, 128.0 / 255.0));
        assert_eq!(t.coverage([0.25, 0.25], false, Channel::Color), alpha);
        assert_eq!(t.coverage([0.25, 0.25], false, Channel::Value), alpha);
        let opaque = Texture::from_texels("o", 1, 1, vec![[30, 60, 90, 255]]);
        assert_eq!(opaque.coverage([0.5, 0.5], false, Channel::Color), 1.0);
        assert!((opaque.coverage([0.5, 0.5], false, Channel::Value) - 60.0 / 255.0).abs() < 1e-12);
    }

    #[test]
    fn between_centres_the_four_texels_blend_and_the_edges_wrap_or_clamp() {
        let t = checker();
        let display = TexelValues::new(ColorConvention::Display);
        // The image's centre: a quarter of each texel.
        let (c, a) = t.sample([0.5, 0.5], false, &display);
        assert!((c - DVec3::new(0.5, 0.25, 0.5)).abs().max_element() < 1e-12);
        assert!((a - (3.0 + 128.0 / 255.0) / 4.0).abs() < 1e-12);
        // The left edge's midpoint: half red, half white wrapped round.
        let (wrapped, _) = t.sample([0.0, 0.75], false, &display);
        assert!((wrapped - DVec3::new(1.0, 0.5, 0.5)).abs().max_element() < 1e-12);
        let (clamped, _) = t.sample([0.0, 0.75], true, &display);
        assert_eq!(clamped, DVec3::new(1.0, 0.0, 0.0));
        // Repeat: one image further along is the same place.
        assert_eq!(
            t.sample([3.25, -1.25], false, &display),
            t.sample([0.25, 0.75], false, &display)
        );
        // Far away and non-finite coordinates stay in the image.
        let _ = t.sample([1e300, -1e300], false, &display);
        let _ = t.sample([f64::NAN, f64::INFINITY], false, &display);
    }

    #[test]
    fn a_linear_render_decodes_each_texel_before_blending() {
        let grey = Texture::from_texels("g", 2, 1, vec![[0, 0, 0, 255], [255, 255, 255, 255]]);
        let linear = TexelValues::new(ColorConvention::Linear);
        let (c, _) = grey.sample([0.5, 0.5], false, &linear);
        // Half of white's light, not sRGB 0.5 (0.214).
        assert!((c.x - 0.5).abs() < 1e-12);
        let half = Texture::from_texels("h", 1, 1, vec![[128, 128, 128, 255]]);
        let (c, _) = half.sample([0.5, 0.5], false, &linear);
        assert!((c.x - srgb_to_linear(128.0 / 255.0)).abs() < 1e-12);
    }

    #[test]
    fn maps_scale_offset_and_clamp_as_mtl_says() {
        let mut map = TextureMap::new(0, "t.png".into());
        map.scale = [2.0, 3.0];
        map.offset = [0.5, 0.25];
        assert_eq!(map.lookup([0.25, 0.25]), Some([1.0, 1.0]));
        map.clamp = true;
        assert_eq!(map.lookup([0.25, 0.25]), Some([1.0, 1.0]));
        assert_eq!(map.lookup([0.5, 0.0]), None);
        assert_eq!(map.lookup([f64::NAN, 0.0]), None);
    }

    #[test]
    fn decoding_reads_the_four_formats_and_names_what_it_refuses() {
        let mut png = Vec::new();
        image::RgbaImage::from_raw(1, 1, vec![10, 20, 30, 40])
            .unwrap()
            .write_to(&mut std::io::Cursor::new(&mut png), image::ImageFormat::Png)
            .unwrap();
        let t = Texture::decode(Path::new("a.png"), &png).unwrap();
        assert_eq!((t.width, t.height, t.has_alpha), (1, 1, true));
        let e = Texture::decode(Path::new("a.png"), b"not an image").unwrap_err();
        assert!(e.contains("PNG, JPEG, TGA or BMP"), "{e}");
        let gif = b"GIF89a\x01\x00\x01\x00\x00\x00\x00;";
        let e = Texture::decode(Path::new("a.gif"), gif).unwrap_err();
        assert!(e.contains("GIF image"), "{e}");
    }
}
