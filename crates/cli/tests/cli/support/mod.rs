//! What the binary's end-to-end tests share: running `gnomon`, temporary
//! directories that clean up after themselves, and reading outputs back.
#![allow(dead_code)]

use std::path::Path;
use std::process::{Command, Output};

pub fn gnomon(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_gnomon")).current_dir(dir).args(args).output().expect("run gnomon")
}

/// A fresh directory under the system's temporary folder, removed with everything
/// in it when the guard is dropped, so test runs leave nothing behind.
pub fn temp_dir(name: &str) -> tempfile::TempDir {
    tempfile::Builder::new()
        .prefix(&format!("gnomon-cli-{name}-"))
        .tempdir()
        .expect("create a temporary directory")
}

pub fn files_in(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    names
}

pub fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// A float32 `.npy` as `gnomon` writes them (format 1.0): its header and its values.
pub fn read_npy(path: &Path) -> (String, Vec<f32>) {
    let bytes = std::fs::read(path).unwrap();
    let len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let header = String::from_utf8(bytes[10..10 + len].to_vec()).unwrap();
    let values = bytes[10 + len..].chunks(4).map(|c| f32::from_le_bytes(c.try_into().unwrap())).collect();
    (header, values)
}
