//! `gnomon-fuzz`: runs the fuzz targets for a while and reports executions, outcomes
//! and crashes. Exits with 1 if any input panicked (saved under `--crashes`).
//!
//! ```sh
//! cargo run --release -p gnomon-fuzz -- --seconds 60            # every target, 60 s each (CI)
//! cargo run --release -p gnomon-fuzz -- gltf --seconds 3600     # one target for an hour
//! ```

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::time::Duration;

use clap::Parser;
use gnomon_fuzz::{Target, files_under};

/// Fuzz Gnomon's inputs (no GPU needed).
#[derive(Parser)]
#[command(name = "gnomon-fuzz")]
struct Args {
    /// Targets to run: scene-file, gltf, flags [default: all three].
    targets: Vec<String>,
    /// Seconds to run each target.
    #[arg(long, default_value_t = 60)]
    seconds: u64,
    /// The mutator's seed: a run repeats from it.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// More seed files or folders, for every target [default: the examples, the
    /// broken glTF test files, and ../shared/scenes/assimp-gltf2 when present].
    #[arg(long = "seeds", value_name = "PATH")]
    seeds: Vec<PathBuf>,
    /// Where inputs that panic are written.
    #[arg(long, default_value = "fuzz-crashes")]
    crashes: PathBuf,
}

/// The seed files a target starts from, besides its built-in seeds.
fn default_seeds(target: Target) -> Vec<PathBuf> {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    let with_extension = |dir: PathBuf, extensions: &[&str]| -> Vec<PathBuf> {
        files_under(&dir)
            .into_iter()
            .filter(|p| p.extension().and_then(|e| e.to_str()).is_some_and(|e| extensions.contains(&e)))
            .collect()
    };
    match target {
        Target::SceneFile => with_extension(root.join("examples"), &["toml"]),
        Target::Gltf => [
            root.join("examples/data"),
            root.join("crates/scene/tests/data/broken"),
            root.join("../shared/scenes/assimp-gltf2"),
        ]
        .into_iter()
        .flat_map(|dir| with_extension(dir, &["gltf", "glb"]))
        .filter(|p| std::fs::metadata(p).is_ok_and(|m| m.len() < 1 << 20))
        .collect(),
        Target::Flags => Vec::new(),
    }
}

fn main() -> ExitCode {
    let args = Args::parse();
    let targets: Vec<Target> = if args.targets.is_empty() {
        Target::ALL.to_vec()
    } else {
        let mut chosen = Vec::new();
        for name in &args.targets {
            match Target::named(name) {
                Some(t) => chosen.push(t),
                None => {
                    eprintln!("gnomon-fuzz: error: no target `{name}`: choose scene-file, gltf or flags");
                    return ExitCode::FAILURE;
                }
            }
        }
        chosen
    };
    println!(
        "| target | seconds | executions | per second | distinct outcomes | corpus | slowest input | crashes | caught panics |"
    );
    println!("|---|---|---|---|---|---|---|---|---|");
    let mut crashed = false;
    for target in targets {
        let seed_dir = tempfile::tempdir().expect("a temporary directory");
        let mut seeds: Vec<PathBuf> = default_seeds(target);
        seeds.extend(
            args.seeds.iter().flat_map(|p| if p.is_dir() { files_under(p) } else { vec![p.clone()] }),
        );
        for (i, seed) in target.builtin_seeds().iter().enumerate() {
            let path = seed_dir.path().join(format!("builtin-{i}"));
            if std::fs::write(&path, seed).is_ok() {
                seeds.push(path);
            }
        }
        let report =
            gnomon_fuzz::run(target, &seeds, Duration::from_secs(args.seconds), args.seed, &args.crashes);
        println!(
            "| {} | {} | {} | {:.0} | {} | {} | {:.0} ms | {} | {} |",
            target.name(),
            args.seconds,
            report.executions,
            report.executions as f64 / args.seconds.max(1) as f64,
            report.outcomes,
            report.corpus,
            report.slowest.as_secs_f64() * 1e3,
            report.crashes.len(),
            report.caught.len()
        );
        for crash in &report.crashes {
            eprintln!("gnomon-fuzz: {} panicked on {}", target.name(), crash.display());
            crashed = true;
        }
        if let Some(first) = report.caught.first() {
            eprintln!(
                "gnomon-fuzz: {} caught {} panic(s), e.g. on {}",
                target.name(),
                report.caught.len(),
                first.display()
            );
        }
    }
    if crashed { ExitCode::FAILURE } else { ExitCode::SUCCESS }
}
