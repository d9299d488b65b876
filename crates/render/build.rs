//! Lists the renderer's WGSL modules for the linker (`src/passes/link.rs`): every
//! `.wgsl` file under `src/`, as its WESL module path (`src/passes/light.wgsl` is
//! `package::passes::light`) and its text, so that adding a file is all it takes to
//! make it importable.

use std::{
    fmt::Write as _,
    path::{Path, PathBuf},
};

fn wgsl_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", dir.display()))
        .map(|entry| entry.expect("a directory entry").path())
        .collect();
    entries.sort();
    for path in entries {
        if path.is_dir() {
            wgsl_files(&path, out);
        } else if path.extension().is_some_and(|ext| ext == "wgsl") {
            out.push(path);
        }
    }
}

fn main() {
    // Read when the script runs, not when it was compiled: cargo reuses a compiled
    // build script across checkouts that share a target folder.
    let manifest =
        std::env::var_os("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR for build scripts");
    let src = Path::new(&manifest).join("src");
    println!("cargo::rerun-if-changed={}", src.display());
    let mut files = Vec::new();
    wgsl_files(&src, &mut files);
    let mut list = String::from("&[\n");
    for file in &files {
        println!("cargo::rerun-if-changed={}", file.display());
        let relative = file.strip_prefix(&src).expect("under src").with_extension("");
        let path: Vec<&str> = relative.iter().map(|part| part.to_str().expect("a UTF-8 file name")).collect();
        writeln!(
            list,
            "    WgslModule {{ path: {:?}, source: include_str!({:?}) }},",
            path.join("::"),
            file.display().to_string()
        )
        .expect("writing to a String");
    }
    list.push(']');
    let out = PathBuf::from(std::env::var("OUT_DIR").expect("cargo sets OUT_DIR")).join("wgsl_modules.rs");
    std::fs::write(&out, list).unwrap_or_else(|e| panic!("cannot write {}: {e}", out.display()));
}
