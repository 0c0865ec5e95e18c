//! Wavefront MTL material libraries, mapped onto glint's Whitted/Phong
//! material. The mapping (also a table in scenes/README.md):
//!
//! | MTL | glint |
//! |---|---|
//! | `Kd` | `color` (clamped to [0, 1]), with `kd = d` |
//! | `Ks` | `ks` = `d` x mean of `Ks` where the `illum` model has a highlight (2 to 9) |
//! | `Ns` | `shininess`; below 1 no highlight (`ks = 0`): Blender writes `Ns 0` for a fully rough surface, 3ds Max for glossiness 0; a negative `Ns` gets a note |
//! | `d` (dissolve) | a blend: the surface terms (`ka`, `kd`, `ks`) scaled by `d`, `transparency = 1 - d` straight through (refracting only for `illum 6, 7`), so `d 0` shows what lies behind |
//! | `Tr` | `1 - d` where no `d` is written (`d` wins, with a note, when both are and disagree); `Tr 1` alone, which would make the material invisible, is read as opaque (MeshLab and others write it meaning opaque), with a note |
//! | OBJ vertex colours | the diffuse colour in place of `Kd`, interpolated across the face (`scene::mesh`) |
//! | `Tf` | `transparency` = mean of `Tf` for refracting models (6, 7) when `d` is 1 |
//! | `Ni` | `ior` for refracting models (6, 7), brought within 0.01 to 100 with a load note; `illum 4` and `9` are glass without refraction (`ior = 1`) |
//! | `illum 0, 1` | diffuse only (`ks = 0`); 0 also without ambient (`ka = 0`) |
//! | `illum 2` | diffuse and Phong highlight |
//! | `illum 3, 5, 8` | also mirror reflection, `reflectivity` = mean of `Ks` (5's Fresnel term is not modelled) |
//! | `illum 4, 6, 7, 9` | also reflection and transparency; 6 and 7 refract (7's Fresnel term is not modelled) |
//! | `illum 10` | as 1 |
//!
//! | `map_Kd` | `color_map`: the texture's colour multiplies `Kd` (as the specification says), its alpha (where it has one) cuts the surface away ([`crate::texture`]) |
//! | `map_d` | `cutout_map`: the surface is cut away where the map's alpha (or grey level) is below one half |
//! | `-s`, `-o`, `-clamp` of a map | the lookup at `uv * s + o`; one copy of the image, not repeated, with `-clamp on` |
//!
//! Other texture maps, bump and displacement, emission (`Ke`) and the PBR
//! extension keys are not rendered: they are listed, never dropped silently.

use std::collections::{BTreeMap, BTreeSet};

use crate::material::Material;
use crate::math::{Color, DVec3};

use super::obj::ObjError;

/// One `newmtl` block as written.
#[derive(Clone, Debug, Default, PartialEq)]
pub(super) struct MtlEntry {
    pub name: String,
    pub kd: Option<Color>,
    pub ks: Option<Color>,
    pub tf: Option<Color>,
    pub ns: Option<f64>,
    pub ni: Option<f64>,
    /// `d` (dissolve, the opacity) and `Tr` as written, each with its
    /// line: [`MtlEntry::opacity`] reads them together.
    pub d: Option<(f64, usize)>,
    pub tr: Option<(f64, usize)>,
    /// The library file the entry is in, for notes.
    pub library: std::path::PathBuf,
    pub illum: Option<u32>,
    /// `map_Kd` and `map_d` as written.
    pub map_kd: Option<MapSpec>,
    pub map_d: Option<MapSpec>,
    /// Keywords glint does not render, as written (`map_Kd`, `bump`, ...).
    pub not_rendered: BTreeSet<String>,
}

/// A texture map statement: the file it names (as written) and its options.
#[derive(Clone, Debug, PartialEq)]
pub(super) struct MapSpec {
    pub file: String,
    pub scale: [f64; 2],
    pub offset: [f64; 2],
    pub clamp: bool,
}

impl MapSpec {
    /// Reads `[options] file` of a map statement. Options glint does not
    /// use are skipped with their arguments; the file name is the rest of
    /// the line, spaces and all.
    fn parse(rest: &str) -> Result<Self, String> {
        let mut spec = MapSpec {
            file: String::new(),
            scale: [1.0, 1.0],
            offset: [0.0, 0.0],
            clamp: false,
        };
        let mut rest = rest.trim();
        // Whether `word` opens an option (a dash and a letter, not `-0.5`).
        let is_option = |word: &str| {
            word.starts_with('-') && word[1..].starts_with(|c: char| c.is_ascii_alphabetic())
        };
        while let Some(word) = rest.split_whitespace().next().filter(|w| is_option(w)) {
            rest = rest[word.len()..].trim_start();
            // How many words follow it: up to three numbers for `-s`, `-o`,
            // `-t`, `-mm`, one word for the rest.
            let takes_numbers = matches!(word, "-s" | "-o" | "-t" | "-mm");
            let mut args = Vec::new();
            while let Some(next) = rest.split_whitespace().next() {
                let number = next.parse::<f64>().ok();
                let wanted = if takes_numbers {
                    number.is_some() && args.len() < 3
                } else {
                    args.is_empty()
                };
                if !wanted {
                    break;
                }
                args.push(next.to_owned());
                rest = rest[next.len()..].trim_start();
            }
            let numbers: Vec<f64> = args.iter().filter_map(|a| a.parse().ok()).collect();
            let pair = |default: f64| -> Result<[f64; 2], String> {
                let first = *numbers
                    .first()
                    .ok_or_else(|| format!("`{word}` needs a number"))?;
                let v = [first, numbers.get(1).copied().unwrap_or(default)];
                if v.iter().all(|x| x.is_finite()) {
                    Ok(v)
                } else {
                    Err(format!("`{word}` needs finite numbers"))
                }
            };
            match word {
                "-s" => spec.scale = pair(1.0)?,
                "-o" => spec.offset = pair(0.0)?,
                "-clamp" => spec.clamp = args.first().is_some_and(|a| a == "on"),
                _ => {}
            }
        }
        if rest.is_empty() {
            return Err("names no file".into());
        }
        spec.file = rest.to_owned();
        Ok(spec)
    }
}

/// Keywords read but deliberately without effect: ambient colour (glint's
/// ambient term is the scene's ambient light times the diffuse colour) and
/// the sharpness of reflection maps.
const IGNORED: [&str; 2] = ["Ka", "sharpness"];

/// Parses an MTL file: its materials in order.
pub(super) fn parse(bytes: &[u8]) -> Result<Vec<MtlEntry>, ObjError> {
    let mut entries: Vec<MtlEntry> = Vec::new();
    let text = super::text::utf8_text(bytes);
    for (index, raw) in text.split(|&b| b == b'\n').enumerate() {
        let line = index + 1;
        let err = |message: String| ObjError { line, message };
        let content = match super::text::comment_start(raw).map_err(err)? {
            Some(hash) => &raw[..hash],
            None => raw,
        }
        .trim_ascii();
        if content.is_empty() {
            continue;
        }
        let keyword_len = content
            .iter()
            .position(u8::is_ascii_whitespace)
            .unwrap_or(content.len());
        let keyword = String::from_utf8_lossy(&content[..keyword_len]).into_owned();
        let rest = content[keyword_len..].trim_ascii();
        if keyword == "newmtl" {
            entries.push(MtlEntry {
                name: String::from_utf8_lossy(rest).into_owned(),
                ..MtlEntry::default()
            });
            continue;
        }
        let Some(entry) = entries.last_mut() else {
            // A file that is no MTL at all (a library path pointing at
            // anything else) is not quoted back: only MTL's own keywords are.
            return Err(err(if is_mtl_keyword(&keyword) {
                format!("`{keyword}` before the first `newmtl`")
            } else {
                "not an MTL file: its first statement is not an MTL keyword".to_owned()
            }));
        };
        let numbers = || -> Result<Vec<f64>, ObjError> {
            rest.split(u8::is_ascii_whitespace)
                .filter(|t| !t.is_empty())
                // `d -halo 0.5`: options start with a dash and a letter.
                .filter(|t| {
                    !(t.first() == Some(&b'-') && t.get(1).is_some_and(u8::is_ascii_alphabetic))
                })
                .map(|t| {
                    std::str::from_utf8(t)
                        .ok()
                        .and_then(|s| s.parse::<f64>().ok())
                        .filter(|x| x.is_finite())
                        .ok_or_else(|| {
                            err(format!(
                                "`{keyword}`: `{}` is not a finite number",
                                String::from_utf8_lossy(t)
                            ))
                        })
                })
                .collect()
        };
        let one = || -> Result<f64, ObjError> {
            numbers()?
                .first()
                .copied()
                .ok_or_else(|| err(format!("`{keyword}` needs a number")))
        };
        // `Kd r [g b]`: g and b default to r. `Kd spectral ...` and
        // `Kd xyz ...` are colours glint cannot read.
        let color = || -> Result<Option<Color>, ObjError> {
            if rest.starts_with(b"spectral") || rest.starts_with(b"xyz") {
                return Ok(None);
            }
            let v = numbers()?;
            match v.as_slice() {
                [r] => Ok(Some(DVec3::splat(*r))),
                [r, g, b, ..] => Ok(Some(DVec3::new(*r, *g, *b))),
                _ => Err(err(format!("`{keyword}` needs one or three numbers"))),
            }
        };
        match keyword.as_str() {
            "Kd" | "Ks" | "Tf" => match color()? {
                Some(c) => match keyword.as_str() {
                    "Kd" => entry.kd = Some(c),
                    "Ks" => entry.ks = Some(c),
                    _ => entry.tf = Some(c),
                },
                None => {
                    entry.not_rendered.insert(format!("{keyword} spectral/xyz"));
                }
            },
            "Ns" => entry.ns = Some(one()?),
            "Ni" => entry.ni = Some(one()?),
            "d" => entry.d = Some((one()?, line)),
            "Tr" => entry.tr = Some((one()?, line)),
            "illum" => {
                let i = one()?;
                if !(0.0..=10.0).contains(&i) || i.fract() != 0.0 {
                    return Err(err(format!(
                        "`illum` must be a whole number 0 to 10, got {i}"
                    )));
                }
                entry.illum = Some(i as u32);
            }
            "map_Kd" | "map_d" => {
                let spec = MapSpec::parse(&String::from_utf8_lossy(rest))
                    .map_err(|e| err(format!("`{keyword}` {e}")))?;
                if keyword == "map_Kd" {
                    entry.map_kd = Some(spec);
                } else {
                    entry.map_d = Some(spec);
                }
            }
            // Emission of zero is what most exporters write for "none".
            "Ke" if color()?.is_some_and(|c| c == DVec3::ZERO) => {}
            k if IGNORED.contains(&k) => {}
            _ => {
                entry.not_rendered.insert(keyword);
            }
        }
    }
    Ok(entries)
}

fn mean(c: Color) -> f64 {
    (c.x + c.y + c.z) / 3.0
}

impl MtlEntry {
    /// glint's material for this entry, named `name` (the mapping in the
    /// module docs).
    pub fn to_material(&self, name: String) -> Material {
        let illum = self.illum.unwrap_or(2);
        let unit = |x: f64| x.clamp(0.0, 1.0);
        let ks = self.ks.map_or(0.0, |c| unit(mean(c)));
        let reflects = matches!(illum, 3..=9);
        let refracts = matches!(illum, 6 | 7);
        let opacity = unit(self.opacity().0);
        let mut transparency = 1.0 - opacity;
        if refracts && opacity == 1.0 {
            transparency = self.tf.map_or(1.0, |c| unit(mean(c)));
        }
        let reflectivity = if reflects { ks } else { 0.0 };
        // What is reflected is not also transmitted.
        transparency = transparency.min(1.0 - reflectivity);
        Material {
            name,
            color: self.kd.map_or(Material::default().color, |c| {
                c.clamp(DVec3::ZERO, DVec3::ONE)
            }),
            // Dissolve blends the surface with what lies behind it.
            ka: if illum == 0 { 0.0 } else { opacity },
            kd: opacity,
            ks: if matches!(illum, 0 | 1 | 10) || self.ns.is_some_and(|n| n < 1.0) {
                0.0
            } else {
                opacity * ks
            },
            shininess: self.ns.map_or(Material::default().shininess, |n| {
                n.clamp(1.0, *crate::limits::SHININESS_RANGE.end())
            }),
            reflectivity,
            transparency,
            ior: if refracts {
                self.ni.map_or(Material::default().ior, |n| {
                    n.clamp(
                        *crate::limits::IOR_RANGE.start(),
                        *crate::limits::IOR_RANGE.end(),
                    )
                })
            } else {
                1.0
            },
            // The maps are files: `mesh_materials` reads them.
            color_map: None,
            cutout_map: None,
        }
    }
}

impl MtlEntry {
    /// The values [`MtlEntry::to_material`] had to bring into glint's
    /// limits, each said as `Ni 0 used as 0.01`: a refracting model's
    /// `Ni` outside the index-of-refraction range, and `Ns` past the
    /// largest shininess. A scene file refuses such values; an MTL file
    /// comes from other tools, so the model renders and the load notes say
    /// what changed.
    pub fn clamped(&self) -> Vec<String> {
        let mut out = Vec::new();
        let illum = self.illum.unwrap_or(2);
        if let Some(n) = self.ni.filter(|_| matches!(illum, 6 | 7)) {
            let (lo, hi) = (
                *crate::limits::IOR_RANGE.start(),
                *crate::limits::IOR_RANGE.end(),
            );
            if !(lo..=hi).contains(&n) {
                out.push(format!("Ni {n} used as {}", n.clamp(lo, hi)));
            }
        }
        if let Some(n) = self.ns {
            let hi = *crate::limits::SHININESS_RANGE.end();
            if n < 0.0 {
                out.push(format!("Ns {n} used as no highlight"));
            } else if n > hi {
                out.push(format!("Ns {n} used as {hi}"));
            }
        }
        out
    }

    /// The opacity `d` and `Tr` say together, and a note where reading
    /// them took a choice: `d` is the standard key and wins over a `Tr`
    /// that disagrees (3ds Max writes `d 1` then `Tr 1`, meaning opaque);
    /// `Tr` alone is `1 - d`, except that a `Tr` making the material fully
    /// invisible is read as opaque (MeshLab and others write `Tr 1` for
    /// opaque; an invisible material would be pointless to export).
    pub fn opacity(&self) -> (f64, Option<String>) {
        let at = |line: usize| format!("{}: line {line}", self.library.display());
        match (self.d, self.tr) {
            (Some((d, d_line)), Some((tr, tr_line))) => {
                let note = (1.0 - tr != d).then(|| {
                    format!(
                        "{}: material `{}` has `d {d}` and `Tr {tr}` (line {tr_line}), which \
                         disagree: `d` is the standard key, opacity {d} used",
                        at(d_line),
                        self.name
                    )
                });
                (d, note)
            }
            (Some((d, _)), None) => (d, None),
            (None, Some((tr, line))) if tr >= 1.0 => (
                1.0,
                Some(format!(
                    "{}: material `{}` has `Tr {tr}` alone, which would make it invisible: \
                     read as opaque, as MeshLab and other exporters mean it",
                    at(line),
                    self.name
                )),
            ),
            (None, Some((tr, _))) => (1.0 - tr, None),
            (None, None) => (1.0, None),
        }
    }
}

/// Keywords not rendered, with the number of materials that use each.
pub(super) fn not_rendered(entries: &[MtlEntry]) -> BTreeMap<String, usize> {
    let mut out = BTreeMap::new();
    for e in entries {
        for k in &e.not_rendered {
            *out.entry(k.clone()).or_default() += 1;
        }
    }
    out
}

/// MTL's statements (the Wavefront MTL specification, and what exporters
/// add: `Ke`, `Pr`, `Pm`, PBR maps), by keyword.
fn is_mtl_keyword(keyword: &str) -> bool {
    matches!(
        keyword,
        "newmtl"
            | "Ka"
            | "Kd"
            | "Ks"
            | "Ke"
            | "Tf"
            | "Ns"
            | "Ni"
            | "d"
            | "Tr"
            | "illum"
            | "sharpness"
            | "Pr"
            | "Pm"
            | "Ps"
            | "Pc"
            | "Pcr"
            | "aniso"
            | "anisor"
            | "norm"
            | "bump"
            | "disp"
            | "decal"
            | "refl"
    ) || keyword.starts_with("map_")
}

#[cfg(test)]
mod tests {
    use super::*;

    const LIBRARY: &str = "\
# Cornell box style
newmtl red
Kd 0.63 0.065 0.05
Ka 0.63 0.065 0.05
illum 1

newmtl mirror
Kd 0 0 0
Ks 0.9 0.9 0.9
Ns 1000
illum 3

newmtl glass
Kd 0.05 0.05 0.05
Ks 0.1 0.1 0.1
Ni 1.5
d 0.1
illum 7
map_Kd glass.png
Ke 0 0 0

newmtl tinted
Kd 0.5
Tr 0.25
map_Kd tint.png
bump tint_n.png
";

    #[test]
    fn the_mapping_of_the_module_docs() {
        let entries = parse(LIBRARY.as_bytes()).unwrap();
        let m: Vec<Material> = entries
            .iter()
            .map(|e| e.to_material(e.name.clone()))
            .collect();
        assert_eq!(m[0].color, DVec3::new(0.63, 0.065, 0.05));
        assert_eq!(
            (m[0].ks, m[0].reflectivity, m[0].transparency),
            (0.0, 0.0, 0.0)
        );
        assert_eq!(m[1].reflectivity, 0.9);
        assert_eq!(m[1].shininess, 1000.0);
        assert_eq!(m[1].transparency, 0.0);
        assert!((m[2].transparency - 0.9).abs() < 1e-12);
        assert_eq!(m[2].ior, 1.5);
        assert!((m[2].reflectivity - 0.1).abs() < 1e-12);
        assert_eq!(m[3].color, DVec3::splat(0.5));
        assert_eq!(m[3].transparency, 0.25);
        assert_eq!(m[3].ior, 1.0, "not a refracting illum model");
        for material in &m {
            material.validate().unwrap();
        }
        let listed = not_rendered(&entries);
        assert!(!listed.contains_key("map_Kd"));
        assert_eq!(entries[3].map_kd.as_ref().unwrap().file, "tint.png");
        assert_eq!(listed["bump"], 1);
        assert!(!listed.contains_key("Ke") && !listed.contains_key("Ka"));
    }

    #[test]
    fn map_options_are_read_and_the_file_is_the_rest_of_the_line() {
        let entries = parse(
            b"newmtl a\nmap_Kd -s 2 3 1 -o 0.5 -bm 0.2 -clamp on -imfchan m my wood.jpg\n\
              map_d -o -0.25 0.5 leaf.tga\n",
        )
        .unwrap();
        let kd = entries[0].map_kd.as_ref().unwrap();
        assert_eq!(kd.file, "my wood.jpg");
        assert_eq!(
            (kd.scale, kd.offset, kd.clamp),
            ([2.0, 3.0], [0.5, 0.0], true)
        );
        let d = entries[0].map_d.as_ref().unwrap();
        assert_eq!((d.file.as_str(), d.offset), ("leaf.tga", [-0.25, 0.5]));
        let e = parse(b"newmtl a\nmap_Kd -s 2\n").unwrap_err();
        assert_eq!(e.line, 2);
        assert!(e.message.contains("names no file"), "{e}");
        let e = parse(b"newmtl a\nmap_Kd -o x.png\n").unwrap_err();
        assert!(e.message.contains("`-o` needs a number"), "{e}");
    }

    #[test]
    fn refracting_glass_with_opacity_one_uses_its_filter() {
        let entries = parse(b"newmtl g\nKs 0.05 0.05 0.05\nNi 1.33\nillum 7\n").unwrap();
        let m = entries[0].to_material("g".into());
        assert_eq!((m.transparency, m.ior), (0.95, 1.33));
        let entries = parse(b"newmtl g\nTf 0.5 0.5 0.5\nillum 6\n").unwrap();
        assert_eq!(entries[0].to_material("g".into()).transparency, 0.5);
    }

    #[test]
    fn refusals_name_the_line() {
        let e = parse(b"newmtl a\nKd 1 x 0\n").unwrap_err();
        assert_eq!(e.line, 2);
        let e = parse(b"Kd 1 1 1\n").unwrap_err();
        assert!(e.message.contains("before the first `newmtl`"), "{e}");
        let e = parse(b"newmtl a\nillum 2.5\n").unwrap_err();
        assert_eq!(e.line, 2);
    }

    #[test]
    fn values_past_the_limits_are_said() {
        let entries =
            parse(b"newmtl glass\nNi 0\nillum 7\nnewmtl shiny\nNs 1e9\nnewmtl fine\nNi 0\nNs 10\n")
                .unwrap();
        let glass = &entries[0];
        assert_eq!(glass.clamped(), ["Ni 0 used as 0.01"]);
        assert_eq!(glass.to_material("g".into()).ior, 0.01);
        assert_eq!(entries[1].clamped().len(), 1, "{:?}", entries[1].clamped());
        assert!(entries[1].clamped()[0].starts_with("Ns 1000000000 used as "));
        // Ni is not used by a model that does not refract: nothing to say.
        assert!(entries[2].clamped().is_empty());
    }
}
