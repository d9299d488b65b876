//! Fuzzing Gnomon's inputs on stable Rust, with no GPU: the targets (bytes in, any
//! error out, never a panic or a hang), a mutator, and the loop that drives them.
//!
//! cargo-fuzz needs a nightly compiler for its coverage instrumentation; Gnomon builds
//! on stable, so this harness guides itself by *outcomes* instead of coverage: an
//! input whose result (success, or the first words of its error) has not been seen
//! joins the corpus and is mutated further. That finds the many distinct ways a file
//! can be refused, which is where panics hide, though not every branch that
//! coverage would reach.

pub mod mutate;
pub mod targets;

use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

pub use targets::Target;

/// What a run found.
#[derive(Debug, Default)]
pub struct Report {
    /// Inputs tried.
    pub executions: u64,
    /// Distinct outcomes seen (success, or each error's first words): the stand-in
    /// for coverage.
    pub outcomes: usize,
    /// Inputs in the corpus at the end (seeds and the inputs that found new outcomes).
    pub corpus: usize,
    /// Inputs that panicked, saved under the crash directory.
    pub crashes: Vec<PathBuf>,
    /// Inputs that raised a panic Gnomon caught and turned into an error: not a crash,
    /// but the panic's message reaches the user's terminal. Saved beside the crashes.
    pub caught: Vec<PathBuf>,
    /// The slowest single input, to show that none hung.
    pub slowest: Duration,
}

/// Where the input being tried is kept while it runs: a file opened once and
/// rewritten in place before each execution, so that when the process dies on an
/// input (an allocation over the memory cap aborts it), the supervisor finds the
/// input that killed it (`gnomon-fuzz` without `--worker`).
pub struct CurrentInput(std::fs::File);

impl CurrentInput {
    /// Opens (creates or truncates) the file at `path`.
    pub fn create(path: &Path) -> std::io::Result<Self> {
        std::fs::File::create(path).map(CurrentInput)
    }

    fn store(&self, input: &[u8]) {
        use std::os::unix::fs::FileExt;
        // Best effort: a failed write only loses the name of a later crash.
        let _ = self.0.set_len(0).and_then(|()| self.0.write_all_at(input, 0));
    }
}

/// Runs `target` for `duration` from the seeds in `seeds`, with a fixed `seed` for
/// the mutator so a run can be repeated. Inputs that panic are written to `crashes`;
/// each input is kept in `current`, when given, while it runs.
pub fn run(
    target: Target,
    seeds: &[PathBuf],
    duration: Duration,
    seed: u64,
    crashes: &Path,
    current: Option<&CurrentInput>,
) -> Report {
    let mut corpus: Vec<Vec<u8>> = seeds.iter().filter_map(|p| std::fs::read(p).ok()).collect();
    if corpus.is_empty() {
        corpus.push(Vec::new());
    }
    let mut rng = mutate::Rng::new(seed);
    let mut seen = HashSet::new();
    let mut report = Report::default();
    let workdir = tempfile::tempdir().expect("a temporary directory for the inputs");
    // Panics inside the target are caught and counted; the default hook would print
    // each one. The hook counts every panic, those Gnomon catches itself included.
    static PANICS: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    std::panic::set_hook(Box::new(|_| {
        PANICS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    }));
    let started = Instant::now();
    let mut next = 0usize;
    while started.elapsed() < duration {
        // Seeds first, unchanged; then mutations of random corpus entries.
        let input = if next < corpus.len() && report.executions < corpus.len() as u64 {
            next += 1;
            corpus[next - 1].clone()
        } else {
            let base = &corpus[rng.below(corpus.len())];
            let other = &corpus[rng.below(corpus.len())];
            mutate::mutate(base, other, target.mutation_hints(), &mut rng)
        };
        if let Some(current) = current {
            current.store(&input);
        }
        let one = Instant::now();
        let panics_before = PANICS.load(std::sync::atomic::Ordering::Relaxed);
        let outcome = std::panic::catch_unwind(|| target.run(&input, workdir.path()));
        let panicked = PANICS.load(std::sync::atomic::Ordering::Relaxed) > panics_before;
        report.slowest = report.slowest.max(one.elapsed());
        report.executions += 1;
        match outcome {
            Ok(kind) => {
                if panicked && report.caught.len() < 100 {
                    let _ = std::fs::create_dir_all(crashes);
                    let path = crashes.join(format!("{}-caught-{}", target.name(), report.caught.len()));
                    let _ = std::fs::write(&path, &input);
                    report.caught.push(path);
                }
                if seen.insert(kind) && corpus.len() < 20_000 {
                    corpus.push(input);
                }
            }
            Err(_) => {
                let _ = std::fs::create_dir_all(crashes);
                let path = crashes.join(format!("{}-{}", target.name(), report.crashes.len()));
                let _ = std::fs::write(&path, &input);
                report.crashes.push(path);
            }
        }
    }
    let _ = std::panic::take_hook();
    report.outcomes = seen.len();
    report.corpus = corpus.len();
    report
}

/// The regular files under `dir`, sorted, recursing into folders.
pub fn files_under(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let Ok(read) = std::fs::read_dir(dir) else { return out };
    for entry in read.flatten() {
        let path = entry.path();
        if path.is_dir() {
            out.extend(files_under(&path));
        } else {
            out.push(path);
        }
    }
    out.sort();
    out
}
