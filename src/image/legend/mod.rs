//! Colour map and legend strip for the diagnostic views (cost, aa-need):
//! the command line writes the legend into the PNG so an exported picture
//! states its own scale. A 5x7 bitmap font keeps a font crate out of the
//! headless build (`glyphs.rs`).

mod glyphs;

/// Viridis colour of `t` in `[0, 1]` (clamped; NaN maps to the low end):
/// the perceptually ordered map of van der Walt & Smith (matplotlib 2015),
/// from the `colorous` crate's table.
pub fn viridis(t: f64) -> [u8; 3] {
    let t = if t.is_nan() { 0.0 } else { t.clamp(0.0, 1.0) };
    let c = colorous::VIRIDIS.eval_continuous(t);
    [c.r, c.g, c.b]
}

/// What a legend strip says: a colour bar from `low` to `high` labelled at
/// both ends, and a caption line.
#[derive(Clone, Debug, PartialEq)]
pub struct Legend {
    pub low: String,
    pub high: String,
    pub caption: String,
    /// Colour of a position `t` in `[0, 1]` along the bar.
    pub ramp: Ramp,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Ramp {
    Viridis,
    Grey,
}

impl Ramp {
    pub fn color(self, t: f64) -> [u8; 3] {
        match self {
            Ramp::Viridis => viridis(t),
            Ramp::Grey => [(t.clamp(0.0, 1.0) * 255.0).round() as u8; 3],
        }
    }
}

/// Height in pixels of the strip [`append_legend`] adds for an image `width` wide.
pub fn legend_height(width: u32, legend: &Legend) -> u32 {
    let s = text_scale(width, legend);
    let lines = caption_lines(width, legend, s).len() as u32;
    6 + 10 + 4 + (1 + lines) * (7 * s + 3) + 2
}

/// The caption broken at spaces into lines that fit the image's width
/// (a narrow image cut it off mid-word).
fn caption_lines(width: u32, legend: &Legend, scale: u32) -> Vec<String> {
    let room = width.saturating_sub(2 * margin(width));
    let mut lines: Vec<String> = Vec::new();
    for word in legend.caption.split(' ') {
        match lines.last_mut() {
            Some(line) if text_width(&format!("{line} {word}"), scale) <= room => {
                line.push(' ');
                line.push_str(word);
            }
            _ => lines.push(word.to_owned()),
        }
    }
    lines
}

fn margin(width: u32) -> u32 {
    4.min(width / 4)
}

/// Double-size text where the caption fits the image width, else single.
fn text_scale(width: u32, legend: &Legend) -> u32 {
    let widest = text_width(&legend.caption, 2)
        .max(text_width(&legend.low, 2) + text_width(&legend.high, 2) + 12);
    if widest + 8 <= width { 2 } else { 1 }
}

/// Appends a legend strip below an RGB8 image of `width` x `height`;
/// returns the new height.
pub fn append_legend(rgb: &mut Vec<u8>, width: u32, height: u32, legend: &Legend) -> u32 {
    let strip = legend_height(width, legend);
    let new_height = height + strip;
    rgb.resize(width as usize * new_height as usize * 3, 0);
    let mut canvas = Canvas {
        rgb,
        width,
        height: new_height,
    };
    canvas.fill(0, height, width, strip, [24, 24, 24]);
    let margin = margin(width);
    let bar_y = height + 6;
    let bar_w = width.saturating_sub(2 * margin).max(1);
    for x in 0..bar_w {
        let t = x as f64 / (bar_w - 1).max(1) as f64;
        canvas.fill(margin + x, bar_y, 1, 10, legend.ramp.color(t));
    }
    let s = text_scale(width, legend);
    let line1 = bar_y + 10 + 4;
    let white = [235, 235, 235];
    canvas.text(margin, line1, &legend.low, s, white);
    let high_w = text_width(&legend.high, s);
    canvas.text(
        (margin + bar_w).saturating_sub(high_w),
        line1,
        &legend.high,
        s,
        white,
    );
    for (k, line) in caption_lines(width, legend, s).iter().enumerate() {
        canvas.text(margin, line1 + (k as u32 + 1) * (7 * s + 3), line, s, white);
    }
    new_height
}

struct Canvas<'a> {
    rgb: &'a mut Vec<u8>,
    width: u32,
    height: u32,
}

impl Canvas<'_> {
    fn fill(&mut self, x: u32, y: u32, w: u32, h: u32, c: [u8; 3]) {
        for yy in y..(y + h).min(self.height) {
            for xx in x..(x + w).min(self.width) {
                let i = (yy as usize * self.width as usize + xx as usize) * 3;
                self.rgb[i..i + 3].copy_from_slice(&c);
            }
        }
    }

    /// Draws `text` with its top-left corner at `(x, y)`, clipped to the canvas.
    fn text(&mut self, x: u32, y: u32, text: &str, scale: u32, c: [u8; 3]) {
        let mut pen = x;
        for ch in text.chars() {
            if let Some(rows) = glyphs::glyph(ch) {
                for (r, row) in rows.iter().enumerate() {
                    for (col, bit) in row.bytes().enumerate() {
                        if bit == b'#' {
                            self.fill(
                                pen + col as u32 * scale,
                                y + r as u32 * scale,
                                scale,
                                scale,
                                c,
                            );
                        }
                    }
                }
            }
            pen += 6 * scale;
        }
    }
}

fn text_width(text: &str, scale: u32) -> u32 {
    (text.chars().count() as u32 * 6).saturating_sub(1) * scale
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn viridis_runs_dark_to_bright_and_clamps() {
        // The map's published end points: dark purple to yellow.
        assert_eq!(viridis(0.0), [68, 1, 84]);
        assert_eq!(viridis(1.0), [253, 231, 37]);
        assert_eq!(viridis(-3.0), viridis(0.0));
        assert_eq!(viridis(f64::NAN), viridis(0.0));
        // Perceptual order: luminance grows along the map.
        let luma = |c: [u8; 3]| 0.2126 * c[0] as f64 + 0.7152 * c[1] as f64 + 0.0722 * c[2] as f64;
        let mut last = -1.0;
        for k in 0..=100 {
            let l = luma(viridis(k as f64 / 100.0));
            assert!(l > last, "luminance falls at {k}%");
            last = l;
        }
    }

    #[test]
    fn legend_strip_is_appended_with_ink() {
        let (w, h) = (64u32, 8u32);
        let mut rgb = vec![7u8; (w * h * 3) as usize];
        let legend = Legend {
            low: "0".into(),
            high: "99".into(),
            caption: "tests".into(),
            ramp: Ramp::Viridis,
        };
        let new_h = append_legend(&mut rgb, w, h, &legend);
        assert_eq!(new_h, h + legend_height(w, &legend));
        assert_eq!(rgb.len(), (w * new_h * 3) as usize);
        // The image itself is untouched; the strip holds bar and text colours.
        assert!(rgb[..(w * h * 3) as usize].iter().all(|&b| b == 7));
        let strip = &rgb[(w * h * 3) as usize..];
        assert!(strip.chunks(3).any(|p| p == [235, 235, 235]));
        assert!(strip.chunks(3).any(|p| p == viridis(1.0)));
    }

    /// A caption wider than the image wraps at spaces, every line within
    /// the width (at 160 pixels it was cut off mid-word); a wide image
    /// keeps it on one line.
    #[test]
    fn a_long_caption_wraps_to_the_width() {
        let legend = Legend {
            low: "0".into(),
            high: "196".into(),
            caption: "intersection tests per pixel, mean 13.0".into(),
            ramp: Ramp::Viridis,
        };
        let s = text_scale(160, &legend);
        let lines = caption_lines(160, &legend, s);
        assert!(lines.len() > 1, "{lines:?}");
        assert!(
            lines
                .iter()
                .all(|l| text_width(l, s) <= 160 - 2 * margin(160)),
            "{lines:?}"
        );
        assert_eq!(lines.join(" "), legend.caption);
        assert_eq!(caption_lines(1000, &legend, 2).len(), 1);
    }
}
