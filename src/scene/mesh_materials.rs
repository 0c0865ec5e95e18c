//! A mesh's materials in the scene: its MTL libraries read, each material
//! it uses added once under a name no other scene material has, and the
//! names a scene file knows them by. Everything that names a mesh material
//! is here; `toml_format` records where each came from and `save` writes
//! edits back under the same names.

use std::path::Path;

use super::file_source::{FileSource, inside_folder};
use super::mesh::LoadedMesh;
use super::model::Scene;
use super::mtl::{self, MtlEntry};
use crate::material::Material;
use crate::texture::{Channel, TextureMap};

/// The materials of an OBJ file's `mtllib` libraries, read through `files`
/// relative to `obj_path`'s folder; a library that cannot be read or parsed
/// is a note (its materials fall back to the default), not a refusal.
pub(super) fn read_libraries(
    libraries: &[String],
    obj_path: &Path,
    files: &dyn FileSource,
    notes: &mut Vec<String>,
) -> Vec<MtlEntry> {
    let folder = obj_path.parent().unwrap_or(Path::new(""));
    let mut entries = Vec::new();
    for written in libraries {
        // Written on Windows: `\` (or a doubled `\\`) separates folders.
        let written = &written.replace('\\', "/");
        // One file name with spaces, or several names.
        let whole = inside_folder(folder, written);
        let names: Vec<(&str, Option<std::path::PathBuf>)> =
            if whole.as_ref().is_some_and(|p| files.read(p).is_ok()) {
                vec![(written.as_str(), whole)]
            } else {
                written
                    .split_whitespace()
                    .map(|n| (n, inside_folder(folder, n)))
                    .collect()
            };
        for (name, path) in names {
            let Some(path) = path else {
                notes.push(format!(
                    "{}: `mtllib {name}` points outside the model's folder and is not read; \
                     its materials are shown in the default material",
                    obj_path.display()
                ));
                continue;
            };
            match files.read(&path) {
                Ok(bytes) => match mtl::parse(&bytes) {
                    Ok(mut found) => {
                        for entry in &mut found {
                            entry.library.clone_from(&path);
                        }
                        entries.append(&mut found)
                    }
                    Err(e) => notes.push(format!(
                        "{}: {e}; its materials are shown in the default material",
                        path.display()
                    )),
                },
                Err(e) => notes.push(format!(
                    "{}: cannot read ({e}); its materials are shown in the default material",
                    path.display()
                )),
            }
        }
    }
    entries
}

/// The scene's material index for each of `mesh`'s `usemtl` slots: its
/// libraries' materials, added to the scene once each (named after the
/// MTL, made unique), and the default material for faces with none or
/// with a name no library defines (returned too, if any face uses it).
pub(super) fn mesh_materials(
    scene: &mut Scene,
    mesh: &LoadedMesh,
    mesh_path: &Path,
    files: &dyn FileSource,
) -> (Vec<u32>, Option<u32>) {
    let notes_before = scene.load_notes.len();
    let entries = read_libraries(&mesh.libraries, mesh_path, files, &mut scene.load_notes);
    // A library not read explains the names it would have defined.
    let unread = scene.load_notes.len() > notes_before;
    for (k, n) in mtl::not_rendered(&entries) {
        *scene.not_rendered.entry(k).or_default() += n;
    }
    let add = |scene: &mut Scene, material: Material| -> u32 {
        let mut name = material.name.clone();
        let mut k = 2;
        while scene.materials.iter().any(|m| m.name == name) {
            name = format!("{} ({k})", material.name);
            k += 1;
        }
        scene.materials.push(Material { name, ..material });
        scene.materials.len() as u32 - 1
    };
    let mut default = None;
    let mut slots = Vec::with_capacity(mesh.material_names.len());
    // Notes many materials share ("Ns -1.96 used as no highlight" for 17
    // of them) are said once, naming the materials.
    let mut grouped: std::collections::BTreeMap<String, Vec<String>> = Default::default();
    // Textures that could not be read, said once each with the materials
    // that name them.
    #[allow(clippy::type_complexity)]
    let mut unread_textures: std::collections::BTreeMap<
        (String, String),
        (String, Vec<String>),
    > = Default::default();
    let mut textured_without_uvs = Vec::new();
    let mut tr_alone: Vec<(String, String)> = Vec::new();
    let used: Vec<bool> = {
        let mut used = vec![false; mesh.material_names.len()];
        for &m in &mesh.triangle_materials {
            used[m as usize] = true;
        }
        used
    };
    for (slot, name) in mesh.material_names.iter().enumerate() {
        let entry = (slot > 0)
            .then(|| entries.iter().find(|e| e.name == *name))
            .flatten();
        let index = match entry {
            Some(e) if used[slot] => {
                match e.opacity() {
                    // MeshLab's habit, often on every material: said once.
                    (_, Some(note)) if e.d.is_none() => tr_alone.push((e.name.clone(), note)),
                    (_, Some(note)) => scene.load_notes.push(note),
                    _ => {}
                }
                let clamped = e.clamped();
                if !clamped.is_empty() {
                    grouped
                        .entry(format!(
                            "brought within glint's limits: {}",
                            clamped.join(", ")
                        ))
                        .or_default()
                        .push(e.name.clone());
                }
                let mut material = e.to_material(e.name.clone());
                let folder = e.library.parent().unwrap_or(Path::new(""));
                for (spec, channel) in [(&e.map_kd, Channel::Color), (&e.map_d, Channel::Value)] {
                    let Some(spec) = spec else { continue };
                    let keyword = match channel {
                        Channel::Color => "map_Kd",
                        Channel::Value => "map_d",
                    };
                    match super::textures::texture_index(
                        scene,
                        folder,
                        &spec.file,
                        super::textures::Namer::Model,
                        files,
                    ) {
                        Ok(texture) => {
                            let map = TextureMap {
                                texture,
                                name: spec.file.clone(),
                                scale: spec.scale,
                                offset: spec.offset,
                                clamp: spec.clamp,
                                channel,
                            };
                            if channel == Channel::Value {
                                material.cutout_map = Some(map);
                            } else {
                                // A colour map's alpha cuts out unless a
                                // `map_d` says what does.
                                if scene.textures[texture as usize].has_alpha && e.map_d.is_none() {
                                    material.cutout_map = Some(map.clone());
                                }
                                material.color_map = Some(map);
                            }
                            if mesh.uvs.is_empty() && textured_without_uvs.last() != Some(&e.name) {
                                textured_without_uvs.push(e.name.clone());
                            }
                        }
                        Err(reason) => unread_textures
                            .entry((
                                e.library.display().to_string(),
                                format!("`{}` ({keyword})", spec.file),
                            ))
                            .or_insert_with(|| (reason, Vec::new()))
                            .1
                            .push(e.name.clone()),
                    }
                }
                // `d 0` on a surface that does not refract: a ghost (glass,
                // `illum 6` or `7`, is meant to be see-through).
                let refracts = matches!(e.illum, Some(6 | 7));
                if e.opacity().0 <= 0.0 && !refracts {
                    grouped
                        .entry(
                            "fully transparent (`d 0`): its faces show only their \
                             highlights and reflections"
                                .into(),
                        )
                        .or_default()
                        .push(e.name.clone());
                }
                add(scene, material)
            }
            _ if !used[slot] => u32::MAX,
            _ => {
                if slot > 0 {
                    scene.load_notes.push(format!(
                        "{}: no material library {}defines `{name}`; its faces use the default material",
                        mesh_path.display(),
                        if unread { "that could be read " } else { "" }
                    ));
                }
                *default.get_or_insert_with(|| {
                    add(
                        scene,
                        Material {
                            name: "default".into(),
                            ..Material::default()
                        },
                    )
                })
            }
        };
        slots.push(index);
    }
    // Textures not found: one note per library. Those found but not
    // decoded: one note each, with the reason.
    let drawn_plain = |names: &[String]| {
        let one = names.len() == 1;
        format!(
            "{} {} {} drawn in {} own `Kd` colour",
            if one { "material" } else { "materials" },
            listed(names),
            if one { "is" } else { "are" },
            if one { "its" } else { "their" },
        )
    };
    let mut missing: std::collections::BTreeMap<String, Vec<(String, String, Vec<String>)>> =
        Default::default();
    for ((library, texture), (reason, names)) in unread_textures {
        if reason.starts_with("no such file") {
            missing
                .entry(library)
                .or_default()
                .push((texture, reason, names));
        } else {
            scene.load_notes.push(format!(
                "{library}: texture {texture} cannot be read: {reason}; {}",
                drawn_plain(&names)
            ));
        }
    }
    for (library, textures) in missing {
        scene.load_notes.push(match textures.as_slice() {
            [(texture, reason, names)] => format!(
                "{library}: texture {texture} cannot be read: {reason}; {}",
                drawn_plain(names)
            ),
            _ => {
                let files: Vec<String> = textures.iter().map(|(t, ..)| t.clone()).collect();
                let mut names: Vec<String> = textures.into_iter().flat_map(|(.., n)| n).collect();
                names.sort();
                names.dedup();
                format!(
                    "{library}: {} textures it names are in neither its folder nor a \
                     `textures` folder beside it ({}); {}",
                    files.len(),
                    files.join(", "),
                    drawn_plain(&names)
                )
            }
        });
    }
    match tr_alone.as_slice() {
        [] => {}
        // One: where it is written.
        [(_, note)] => scene.load_notes.push(note.clone()),
        _ => grouped
            .entry(
                "with `Tr 1` alone, which would make them invisible: read as opaque, as \
                 MeshLab and other exporters mean it"
                    .into(),
            )
            .or_default()
            .extend(tr_alone.into_iter().map(|(name, _)| name)),
    }
    if !textured_without_uvs.is_empty() {
        grouped
            .entry(
                "textured, but the mesh has no texture coordinates (`vt`): drawn untextured".into(),
            )
            .or_default()
            .extend(textured_without_uvs);
    }
    for (note, names) in grouped {
        let named = listed(&names);
        scene.load_notes.push(match names.len() {
            1 => format!("{}: material {named} {note}", mesh_path.display()),
            n => format!("{}: {n} materials ({named}) {note}", mesh_path.display()),
        });
    }
    (slots, default)
}

/// Names in backquotes, the first six of them and how many more.
fn listed(names: &[String]) -> String {
    const SHOWN: usize = 6;
    let mut out: Vec<String> = names.iter().take(SHOWN).map(|n| format!("`{n}`")).collect();
    if names.len() > SHOWN {
        out.push(format!("and {} more", names.len() - SHOWN));
    }
    out.join(", ")
}

/// Each scene material `mesh_materials` gave `mesh`, once, with the name a
/// scene file uses for it: its MTL name, or `default` for faces with none
/// or with a name no library defines (`default (2)` and on where the MTL
/// names a material `default` too, so each keeps its own key).
pub(super) fn slot_names(
    mesh: &LoadedMesh,
    slots: &[u32],
    default: Option<u32>,
) -> Vec<(u32, String)> {
    let taken = |name: &str| {
        slots.iter().enumerate().any(|(slot, &index)| {
            index != u32::MAX && Some(index) != default && mesh.material_names[slot] == name
        })
    };
    let mut default_name = "default".to_owned();
    let mut k = 2;
    while taken(&default_name) {
        default_name = format!("default ({k})");
        k += 1;
    }
    let mut names: Vec<(u32, String)> = Vec::new();
    for (slot, &index) in slots.iter().enumerate() {
        if index == u32::MAX || names.iter().any(|(i, _)| *i == index) {
            continue;
        }
        let name = if Some(index) == default {
            default_name.clone()
        } else {
            mesh.material_names[slot].clone()
        };
        names.push((index, name));
    }
    names
}
