//! `gnomon`: the command-line front end. Parses flags (generated from the typed
//! settings in `gnomon-scene`), runs the renderer, and writes images and float outputs.

mod bench_cmd;
mod bench_lights;
mod bench_moving;
mod bench_report;
mod cache;
mod calibrate;
mod compare_cmd;
mod compare_motion;
mod compare_outputs;
mod compare_report;
mod grid;
mod lab;
mod output;
mod reference_cmd;
mod render_cmd;
mod surfaces_in;
mod view_cmd;

use std::process::ExitCode;

use clap::{Parser, Subcommand};

/// Gnomon: a real-time shadow-mapping engine and lab.
#[derive(Parser)]
#[command(name = "gnomon", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Render a scene with a shadow technique to a PNG (the default command).
    Render(Box<render_cmd::RenderArgs>),
    /// Ray-trace the exact (or Monte Carlo area-light) visibility of the light.
    Reference(Box<reference_cmd::ReferenceArgs>),
    /// Render techniques and the reference; write metrics, heat-maps and a grid.
    Compare(Box<compare_cmd::CompareArgs>),
    /// Time every pass (median and p95) per technique, with optional setting sweeps
    /// and the depth-only baseline; write bench.json and bench.md.
    Bench(Box<bench_cmd::BenchArgs>),
    /// Sweep a technique's bias settings against the reference over several views;
    /// plot the Pareto front of false shadow against false lit and pick the setting
    /// with the least mismatch, checked on held-out views.
    Calibrate(Box<calibrate::CalibrateArgs>),
    /// Open the interactive viewer: every technique and setting live, with debug views.
    View(Box<view_cmd::ViewArgs>),
    /// List the cached ray-traced references (size, last use), or clear them.
    Cache(cache::CacheArgs),
    /// List the built-in scenes.
    Scenes,
    /// List the shadow techniques.
    Techniques,
}

/// The command line, with the registry's techniques as the choices of every
/// `--technique` and `--techniques` (the settings crate does not know them).
fn parse_cli(techniques: &gnomon_render::techniques::TechniqueRegistry) -> Cli {
    use clap::{CommandFactory, FromArgMatches};
    let command = gnomon_scene::settings::settings_command(Cli::command(), &techniques.choices());
    let command = gnomon_scene::settings::accept_negative_values(command);
    let matches = command.get_matches();
    Cli::from_arg_matches(&matches).unwrap_or_else(|e| e.exit())
}

/// Points `XDG_RUNTIME_DIR` at a private directory when it is unset or not a
/// directory: Mesa's Vulkan window-system code prints "XDG_RUNTIME_DIR is invalid or
/// not set" on every run otherwise, though a headless run never needs it. The folder
/// `$TMPDIR/gnomon-runtime-UID` is used only if it is a real directory (not a link)
/// that the user owns and no one else may enter; anything else there, perhaps planted
/// by another user to receive a window-system connection, is left alone and a fresh
/// private folder is made instead, removed when the returned guard drops.
fn quiet_runtime_dir() -> Option<tempfile::TempDir> {
    let valid = std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| std::path::Path::new(&d).is_dir());
    if valid {
        return None;
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::{DirBuilderExt, MetadataExt};
        // SAFETY: getuid has no preconditions and cannot fail.
        let user = unsafe { libc::getuid() };
        let dir = std::env::temp_dir().join(format!("gnomon-runtime-{user}"));
        let _ = std::fs::DirBuilder::new().mode(0o700).create(&dir);
        let private = std::fs::symlink_metadata(&dir)
            .is_ok_and(|m| m.is_dir() && m.uid() == user && m.mode() & 0o077 == 0);
        let (dir, guard) = if private {
            (dir, None)
        } else {
            // tempfile makes its folders 0700 under an unpredictable name.
            let fresh = tempfile::Builder::new().prefix("gnomon-runtime-").tempdir().ok()?;
            (fresh.path().to_path_buf(), Some(fresh))
        };
        // SAFETY: called first thing in `main`, before any thread exists that
        // could read the environment concurrently.
        unsafe { std::env::set_var("XDG_RUNTIME_DIR", &dir) };
        guard
    }
    #[cfg(not(unix))]
    None
}

fn main() -> ExitCode {
    let _runtime_dir = quiet_runtime_dir();
    let techniques = gnomon_render::techniques::TechniqueRegistry::builtin();
    let cli = parse_cli(&techniques);
    output::remove_temporaries_on_interrupt();
    let result = match cli.command {
        None => render_cmd::run(&render_cmd::RenderArgs::default_from_cli()),
        Some(Command::Render(args)) => render_cmd::run(&args),
        Some(Command::Reference(args)) => reference_cmd::run(&args),
        Some(Command::Compare(args)) => compare_cmd::run(&args),
        Some(Command::View(args)) => view_cmd::run(&args),
        Some(Command::Bench(args)) => bench_cmd::run(&args),
        Some(Command::Calibrate(args)) => calibrate::run(&args),
        Some(Command::Cache(args)) => cache::run(&args),
        Some(Command::Scenes) => {
            for b in gnomon_scene::builtin::BUILTINS {
                println!("{:<10} {}", b.name, b.description);
            }
            Ok(())
        }
        Some(Command::Techniques) => {
            for (name, summary) in techniques.choices() {
                println!("{name:<14} {summary}");
            }
            Ok(())
        }
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let message = format!("{}{e:#}", flag_of(&e).unwrap_or_default());
            eprintln!("gnomon: error: {}", gnomon_scene::settings::in_flags(&message));
            ExitCode::FAILURE
        }
    }
}

/// The command-line flag behind a library error that names a setting: the library
/// speaks in settings, the user typed flags.
fn flag_of(e: &anyhow::Error) -> Option<String> {
    use gnomon_render::RenderError;
    let render = e.chain().find_map(|cause| cause.downcast_ref::<RenderError>())?;
    match render {
        RenderError::ShadowMapTooLarge { requested, .. } => Some(format!("--shadow-res = {requested}: ")),
        RenderError::PagePoolTooLarge { pages_per_side, .. } => {
            Some(format!("--page-pool {pages_per_side}: "))
        }
        RenderError::MomentFormatUnsupported { .. } => Some("--moment-format rgba32float: ".into()),
        RenderError::RaysUnavailable(_) => Some("--refine: ".into()),
        RenderError::RayQueriesUnavailable(_) => Some("--tracer ray-query: ".into()),
        RenderError::ImageTooLarge { width, height, .. }
        | RenderError::ImageTooManyBytes { width, height, .. } => {
            Some(format!("--width {width} --height {height}: "))
        }
        RenderError::NoAdapter { .. }
        | RenderError::DeviceRequest { .. }
        | RenderError::AttachmentsTooLarge { .. }
        | RenderError::ReceiverNeedsMapPath
        | RenderError::ReceiverCannotTrace { .. }
        | RenderError::TechniqueNeedsRays { .. }
        | RenderError::Settings(_)
        | RenderError::Scene(_)
        | RenderError::EmptyScene(_)
        | RenderError::SceneTooLarge { .. }
        | RenderError::OverBudget { .. }
        | RenderError::MemoryBudget(_)
        | RenderError::UnknownInstance { .. }
        | RenderError::InstancesChanged { .. }
        | RenderError::Gpu { .. } => None,
    }
}

#[cfg(test)]
mod tests {
    use clap::CommandFactory;

    use super::Cli;

    /// Every option of every subcommand explains itself in `--help`, in words a
    /// user reads: no rustdoc link (``[`NAME`]``) leaks in from the settings' doc
    /// comments, which clap prints as they are.
    #[test]
    fn every_option_has_help_text() {
        let mut command = Cli::command();
        command.build();
        for sub in command.get_subcommands() {
            for arg in sub.get_arguments() {
                let short = arg.get_help().map(|h| h.to_string()).unwrap_or_default();
                let long = arg.get_long_help().map(|h| h.to_string()).unwrap_or_default();
                assert!(!short.trim().is_empty(), "`{} --{}` has no help", sub.get_name(), arg.get_id());
                for help in [short, long] {
                    assert!(
                        !help.contains("[`"),
                        "`{} --{}`'s help has a rustdoc link: {help}",
                        sub.get_name(),
                        arg.get_id()
                    );
                }
            }
        }
    }
}
