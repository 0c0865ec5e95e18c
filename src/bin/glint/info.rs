//! `glint info`: how a PNG that glint wrote was made; `--simd`: which
//! instruction set this machine renders with, and why.

use std::path::PathBuf;

use std::io::Write;

use anyhow::Result;

#[derive(clap::Args)]
pub struct InfoArgs {
    /// A PNG written by glint (`glint render` or the viewer's export).
    #[arg(required_unless_present = "simd")]
    pub png: Option<PathBuf>,
    /// Say which SIMD level this machine renders with and why (the levels
    /// it runs, and whether `GLINT_SIMD` forced one), instead of reading a PNG.
    #[arg(long, conflicts_with_all = ["png", "scene_text"])]
    pub simd: bool,
    /// Print the record as one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
    /// Also print the embedded scene file's full text.
    #[arg(long)]
    pub scene_text: bool,
}

pub fn run(args: &InfoArgs) -> Result<()> {
    let mut out = std::io::stdout().lock();
    let written = match &args.png {
        Some(png) if !args.simd => {
            let record = glint::export::read_record(png)?;
            write_info(&mut out, args, png, &record)
        }
        _ => write_simd(&mut out, args.json),
    };
    match written {
        // A closed pipe (`glint info F | head`) is the reader's choice.
        Err(e) if e.kind() == std::io::ErrorKind::BrokenPipe => Ok(()),
        other => Ok(other?),
    }
}

fn write_simd(out: &mut impl Write, json: bool) -> std::io::Result<()> {
    use glint::simd::{SimdChoice, SimdLevel};
    let choice = SimdChoice::current();
    let available: Vec<&str> = SimdLevel::ALL
        .into_iter()
        .filter(|l| l.is_available())
        .map(SimdLevel::name)
        .collect();
    if json {
        let value = serde_json::json!({
            "level": choice.level,
            "lanes": choice.level.packet_width(),
            "reason": choice.reason,
            "available": available,
        });
        return writeln!(out, "{}", serde_json::to_string_pretty(&value)?);
    }
    writeln!(
        out,
        "simd       {} ({} lane{}): {}",
        choice.level.name(),
        choice.level.packet_width(),
        if choice.level.packet_width() == 1 {
            ""
        } else {
            "s"
        },
        choice.reason
    )?;
    writeln!(out, "available  {}", available.join(", "))?;
    writeln!(
        out,
        "           every level gives the same image bytes; GLINT_SIMD=scalar|avx2|avx512 forces one"
    )
}

fn write_info(
    out: &mut impl Write,
    args: &InfoArgs,
    png: &std::path::Path,
    record: &glint::export::RenderRecord,
) -> std::io::Result<()> {
    if args.json {
        let value = serde_json::json!({
            "glint_version": record.glint_version,
            "scene_path": record.scene_path,
            "scene_sha256": record.scene_sha256,
            "settings": record.settings,
            "scene_text": record.scene_text,
        });
        return writeln!(out, "{}", serde_json::to_string_pretty(&value)?);
    }
    let s = &record.settings;
    let r = &s.render;
    let v3 = |v: [f64; 3]| format!("{} {} {}", v[0], v[1], v[2]);
    writeln!(out, "file          {}", png.display())?;
    writeln!(out, "glint         {}", record.glint_version)?;
    writeln!(out, "scene         {}", record.scene_path)?;
    writeln!(out, "scene sha256  {}", record.scene_sha256)?;
    writeln!(out, "size          {}x{}", r.width, r.height)?;
    if r.corner_rays() {
        writeln!(out, "samples       pixel corners (SPD protocol)")?;
    } else {
        writeln!(
            out,
            "samples       {}{}",
            r.samples,
            if r.adaptive {
                " (adaptive: the grid only where the 1-sample picture needs it)"
            } else {
                ""
            }
        )?;
    }
    writeln!(out, "max depth     {}", r.max_depth)?;
    writeln!(out, "view          {}", r.view.name())?;
    writeln!(out, "protocol      {}", r.protocol.name())?;
    writeln!(out, "colours       {}", r.colors.name())?;
    writeln!(out, "sides         {}", r.sides.name())?;
    writeln!(
        out,
        "octree        {} (max depth {}, leaf size {}, cost-driven {}, max duplication {}, budget {} MiB)",
        match r.accel {
            glint::settings::Accel::Octree => "on",
            glint::settings::Accel::Bvh => "off, a BVH instead",
            glint::settings::Accel::BruteForce => "off",
        },
        s.octree_params.max_depth,
        s.octree_params.leaf_size,
        s.octree_params.cost_driven,
        s.octree_params.max_duplication,
        s.octree_params.memory_budget_mib
    )?;
    if let Some(depth) = s.overlay_depth {
        writeln!(out, "overlay       octree cells to depth {depth}")?;
    }
    if s.partial {
        writeln!(
            out,
            "partial       yes: exported while a pass was still sweeping in (part old, part new pixels); a re-render gives the whole pass"
        )?;
    }
    writeln!(out, "camera eye    {}", v3(s.camera.eye))?;
    writeln!(out, "camera lookat {}", v3(s.camera.lookat))?;
    writeln!(out, "camera up     {}", v3(s.camera.up))?;
    writeln!(out, "camera fov    {}", s.camera.fov)?;
    if let Some(f) = &s.frame {
        let time = f.time.map_or(" of a turntable".to_string(), |t| {
            format!(", at {t} s along the camera path")
        });
        writeln!(out, "frame         {} of {}{time}", f.index, f.count)?;
    }
    // The viewer records the lights and materials it rendered; they are
    // edits only where they differ from the recorded scene file's.
    let unedited = s.edits.as_ref().is_some_and(|e| {
        glint::scene::load_str(
            &record.scene_text,
            std::path::Path::new(&record.scene_path),
            &glint::scene::FileSystem,
        )
        .is_ok_and(|file| file.lights == e.lights && file.materials == e.materials)
    });
    if unedited {
        writeln!(
            out,
            "edits         none (the scene file's lights and materials)"
        )?;
    } else if let Some(e) = &s.edits {
        let c = |c: glint::math::DVec3| format!("{} {} {}", c.x, c.y, c.z);
        writeln!(
            out,
            "edits         {} lights and {} materials as the viewer had them, in place of the scene file's",
            e.lights.len(),
            e.materials.len()
        )?;
        for (i, l) in e.lights.iter().enumerate() {
            writeln!(
                out,
                "  light {}     position {}, colour {}",
                i + 1,
                c(l.position),
                c(l.color)
            )?;
        }
        for m in &e.materials {
            writeln!(
                out,
                "  material `{}`: colour {}, kd {}, ks {}, shininess {}, reflectivity {}, transparency {}, ior {}",
                m.name,
                c(m.color),
                m.kd,
                m.ks,
                m.shininess,
                m.reflectivity,
                m.transparency,
                m.ior
            )?;
        }
    }
    if s.scene_not_embedded {
        writeln!(
            out,
            "scene text    not embedded (over 16 MiB): --from-png reads the file at the scene path, checked against its SHA-256"
        )?;
    } else {
        writeln!(
            out,
            "scene text    {} bytes, {} lines{}",
            record.scene_text.len(),
            record.scene_text.lines().count(),
            if args.scene_text {
                ""
            } else {
                " (--scene-text prints it)"
            }
        )?;
    }
    writeln!(
        out,
        "re-render     glint render --from-png {} -o NEW.png",
        crate::common::shell_quoted(&png.display().to_string())
    )?;
    if args.scene_text {
        writeln!(out, "---")?;
        write!(out, "{}", record.scene_text)?;
        if !record.scene_text.ends_with('\n') {
            writeln!(out)?;
        }
    }
    Ok(())
}
