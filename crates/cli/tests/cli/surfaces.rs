//! `gnomon reference --surfaces`: the truth traced from the surfaces a frame drew, as
//! `--aov-out` writes them, and the folders it refuses.

use std::path::Path;

use super::support::{files_in, gnomon, read_npy, stderr, temp_dir};

/// A float32 `.npy`'s values (as `--aov-out` and `reference --out` write them).
fn npy_values(path: &Path) -> Vec<f32> {
    read_npy(path).1
}

const SIZE: [&str; 4] = ["--width", "96", "--height", "54"];

/// Under a hard light, the CPU truth at a frame's own surfaces is the GPU's
/// `raytraced` answer at the same points: two tracers, one question. And the truth is
/// the surfaces', not the camera's: traced with another camera given, it is the same.
#[test]
fn the_truth_at_a_frames_surfaces_is_its_raytraced_answer() {
    let temp = temp_dir("surfaces");
    let dir = temp.path();
    let render = ["render", "spheres", "--technique", "raytraced", "--out", "f.png", "--aov-out", "aov"];
    let low_sun = ["--sun-elevation", "20"];
    let out = gnomon(dir, &[&render[..], &SIZE[..], &low_sun[..], &["--aov-format", "npy"]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    let reference =
        |out| ["reference", "spheres", "--surfaces", "aov", "--out", out, "--sun-elevation", "20"];
    let out = gnomon(dir, &reference("truth.npy"));
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("truth at the 96×54 surfaces"), "{}", stderr(&out));
    let truth = npy_values(&dir.join("truth.npy"));
    let traced = npy_values(&dir.join("aov/visibility.npy"));
    assert_eq!(truth.len(), 96 * 54);
    let drawn: Vec<(f32, f32)> =
        truth.iter().zip(&traced).filter(|(t, _)| t.is_finite()).map(|(&t, &v)| (t, v)).collect();
    assert!(drawn.len() > 96 * 54 / 2, "{} pixels drawn", drawn.len());
    let shadowed = drawn.iter().filter(|(t, _)| *t < 0.5).count();
    let differ = drawn.iter().filter(|(t, v)| (*t < 0.5) != (*v < 0.5)).count();
    assert!(shadowed > 100, "{shadowed} of {} pixels shadowed", drawn.len());
    assert!(differ <= drawn.len() / 1000, "{differ} of {} pixels differ", drawn.len());
    // Another camera changes nothing: the points are the folder's.
    let elsewhere = [&reference("elsewhere.npy")[..], &["--camera-eye", "9,9,9"]].concat();
    assert!(gnomon(dir, &elsewhere).status.success());
    let same = npy_values(&dir.join("elsewhere.npy"));
    assert!(same.iter().zip(&truth).all(|(a, b)| a.to_bits() == b.to_bits()));
}

/// A light with a size: the truth at the surfaces comes with its standard error,
/// each in [0, 1], and a penumbra between.
#[test]
fn an_area_lights_truth_at_surfaces_has_its_standard_error() {
    let temp = temp_dir("surfaces-soft");
    let dir = temp.path();
    let light = ["--light", "spot", "--spot-radius", "0.4"];
    let render = ["render", "spheres", "--out", "f.png", "--aov-out", "aov", "--aov-format", "npy"];
    assert!(gnomon(dir, &[&render[..], &SIZE[..], &light[..]].concat()).status.success());
    let reference = ["reference", "spheres", "--surfaces", "aov", "--samples", "64", "--out", "t.npy"];
    let out = gnomon(dir, &[&reference[..], &light[..], &["--std-error-out", "se.npy"]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    let (truth, se) = (npy_values(&dir.join("t.npy")), npy_values(&dir.join("se.npy")));
    let penumbra = truth.iter().zip(&se).filter(|(t, s)| **t - **s > 0.0 && **t + **s < 1.0).count();
    assert!(penumbra > 50, "{penumbra} penumbra pixels");
    assert!(se.iter().filter(|s| s.is_finite()).all(|s| (0.0..0.5).contains(s)));
}

/// A folder without the files, or with files from two frames, is refused by name,
/// and nothing is written.
#[test]
fn a_folder_of_wrong_surfaces_is_refused_by_name() {
    let temp = temp_dir("surfaces-bad");
    let dir = temp.path();
    std::fs::create_dir(dir.join("empty")).unwrap();
    let out = gnomon(dir, &["reference", "--surfaces", "empty", "--out", "t.npy"]);
    assert!(!out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("--surfaces") && stderr(&out).contains("position.npy: no such file"),
        "{}",
        stderr(&out)
    );
    let small =
        ["render", "spheres", "--out", "f.png", "--aov-format", "npy", "--width", "8", "--height", "4"];
    assert!(gnomon(dir, &[&small[..], &["--aov-out", "a"]].concat()).status.success());
    let large = [&small[..6], &["--width", "16", "--height", "4", "--aov-out", "b"]].concat();
    assert!(gnomon(dir, &large).status.success());
    std::fs::rename(dir.join("b/geometric_normal.npy"), dir.join("a/geometric_normal.npy")).unwrap();
    let out = gnomon(dir, &["reference", "--surfaces", "a", "--out", "t.npy"]);
    assert!(
        stderr(&out).contains("geometric_normal.npy: 16×4 pixels, but position.npy beside it is 8×4"),
        "{}",
        stderr(&out)
    );
    assert!(!files_in(dir).contains(&"t.npy".to_string()));
}
