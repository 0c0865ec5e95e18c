//! The `glint` command: headless rendering and benchmarks (and, with the
//! `gui` feature, the interactive viewer).

/// `println!` returning the failure to write (standard output closed, as
/// by `| head`, or full) as an error, where `println!` would panic.
macro_rules! out {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        writeln!(std::io::stdout().lock(), $($arg)*)
            .map_err(|e| anyhow::anyhow!("cannot write to standard output: {e}"))
    }};
}

/// `print!` as [`out!`] does `println!`.
macro_rules! out_str {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        write!(std::io::stdout().lock(), $($arg)*)
            .map_err(|e| anyhow::anyhow!("cannot write to standard output: {e}"))
    }};
}

/// `eprintln!` for messages: where standard error is closed or full they
/// are lost, as they would be unread, instead of panicking after the work
/// is done.
macro_rules! say {
    ($($arg:tt)*) => {{
        use std::io::Write as _;
        let _ = writeln!(std::io::stderr().lock(), $($arg)*);
    }};
}

mod bench;
mod common;
mod info;
mod render_cmd;
mod sequence;
mod study;
#[cfg(feature = "gui")]
mod view;

use clap::{Parser, Subcommand};

#[derive(Parser)]
#[command(
    name = "glint",
    version,
    about = "An interactive Whitted-style ray tracer"
)]
#[cfg_attr(
    feature = "gui",
    command(
        after_help = "`glint SCENE` (no command) opens SCENE in the viewer, as \
                          `glint view SCENE` does; `glint` alone opens the built-in default scene."
    )
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene (TOML, NFF, or an OBJ model on its own) to a PNG file.
    Render(render_cmd::RenderArgs),
    /// Time scenes with the octree on and off, interleaved, and report medians.
    Bench(bench::BenchArgs),
    /// Measure speed against accuracy: anti-aliasing, depth, octree, preview.
    Study(study::StudyArgs),
    /// Print how a PNG that glint wrote was made (scene, settings, version).
    Info(info::InfoArgs),
    /// Open a scene in the interactive viewer (the default command).
    #[cfg(feature = "gui")]
    View(view::ViewArgs),
    /// Without the viewer compiled in, `glint view` says so (clap alone
    /// would call it an unrecognized subcommand).
    #[cfg(not(feature = "gui"))]
    #[command(hide = true)]
    View {
        #[arg(trailing_var_arg = true, allow_hyphen_values = true)]
        args: Vec<std::ffi::OsString>,
    },
}

fn main() -> std::process::ExitCode {
    // Ctrl+C (or SIGTERM, SIGHUP) still ends glint at once, but first
    // removes the hidden temporary file of an output being written, which
    // the signal would otherwise leave behind. Without a handler (an
    // unusual platform) the signal's default stands.
    let _ = ctrlc::set_handler(|| {
        glint::export::remove_unfinished_outputs();
        common::end_terminal_line();
        std::process::exit(130);
    });
    let cli = Cli::parse_from(with_default_command(std::env::args_os().collect()));
    // A GLINT_SIMD that is not taken (a typo, a level this CPU lacks) is
    // said, not ignored.
    let simd = glint::simd::SimdChoice::current();
    if std::env::var_os("GLINT_SIMD").is_some_and(|v| !v.is_empty())
        && !simd.reason.starts_with("forced")
    {
        say!("note: {}", simd.reason);
    }
    let result = match cli.command {
        Some(command) => run(command),
        #[cfg(feature = "gui")]
        None => view::run(&view::ViewArgs::default()),
        #[cfg(not(feature = "gui"))]
        None => {
            use clap::CommandFactory;
            say!("glint was built without the viewer (cargo feature `gui`); use a subcommand.\n");
            let _ = Cli::command().print_help();
            return std::process::ExitCode::from(2);
        }
    };
    match result {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            say!("error: {e:#}");
            std::process::ExitCode::FAILURE
        }
    }
}

/// Runs one subcommand.
fn run(command: Command) -> anyhow::Result<()> {
    match command {
        Command::Render(args) => render_cmd::run(&args),
        Command::Bench(args) => bench::run(&args),
        Command::Study(args) => study::run(&args),
        Command::Info(args) => info::run(&args),
        #[cfg(feature = "gui")]
        Command::View(args) => view::run(&args),
        #[cfg(not(feature = "gui"))]
        Command::View { .. } => Err(anyhow::anyhow!(
            "this glint was built without the viewer (cargo feature `gui`, on by default): \
             build it with `cargo build --release`, or render headless with `glint render`"
        )),
    }
}

/// `glint SCENE` is `glint view SCENE`: the viewer is the default command,
/// so a first argument that names a file (or a scene by its extension)
/// rather than a subcommand or a flag opens it.
fn with_default_command(mut args: Vec<std::ffi::OsString>) -> Vec<std::ffi::OsString> {
    use clap::CommandFactory;
    let names: Vec<String> = Cli::command()
        .get_subcommands()
        .map(|c| c.get_name().to_owned())
        .chain(["help".to_owned()])
        .collect();
    let opens_a_file = args.get(1).is_some_and(|first| {
        let text = first.to_string_lossy();
        !text.starts_with('-') && !names.iter().any(|n| *n == text) && {
            let path = std::path::Path::new(first);
            // A scene's name that does not exist is the viewer's to
            // refuse ("cannot read scene file"), not clap's.
            path.is_file()
                || path.extension().is_some_and(|e| {
                    ["toml", "nff", "obj"]
                        .iter()
                        .any(|x| e.eq_ignore_ascii_case(x))
                })
        }
    });
    if opens_a_file {
        args.insert(1, "view".into());
    }
    args
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::CommandFactory;

    #[test]
    fn the_command_line_definition_is_consistent() {
        Cli::command().debug_assert();
    }

    /// A build without the viewer says so for `glint view` (and for a
    /// scene given alone), rather than calling it an unknown subcommand.
    /// CI runs the no-GUI build's tests of this binary only: the library's
    /// code is the same in both builds, and its tests run in the GUI build.
    #[cfg(not(feature = "gui"))]
    #[test]
    fn a_build_without_the_viewer_says_so() {
        for args in [
            &[
                "glint",
                "view",
                "scenes/default.toml",
                "--screenshot",
                "x.png",
            ][..],
            &["glint", "scene.toml"],
        ] {
            let args = with_default_command(args.iter().map(Into::into).collect());
            let cli = Cli::try_parse_from(args).unwrap();
            let e = run(cli.command.unwrap()).unwrap_err().to_string();
            assert!(e.contains("built without the viewer"), "{e}");
        }
    }

    #[test]
    fn help_states_the_defaults_the_library_uses() {
        let mut cli = Cli::command();
        for name in ["render", "bench"] {
            let command = cli.find_subcommand_mut(name).unwrap();
            let help = command.render_long_help().to_string();
            let said = format!("Default {}", glint::accel::DEFAULT_MEMORY_BUDGET_MIB);
            assert!(help.contains(&said), "{name} --help lacks {said:?}");
        }
    }
}
