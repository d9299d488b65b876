//! The binary's shadow rays: the `raytraced` technique is listed, traces every
//! light-facing pixel whatever `--refine` says and reports them with `--verbose`, on
//! the mask path (counted) and the forward path (not counted), and its penumbra rays
//! are no unused setting.

use crate::support;

use support::{gnomon, stderr, temp_dir};

const SMALL: [&str; 4] = ["--width", "160", "--height", "90"];

#[test]
fn raytraced_is_listed_and_traces_whatever_refine_says() {
    let temp = temp_dir("raytraced");
    let dir = temp.path();
    let listed = gnomon(dir, &["techniques"]);
    assert!(String::from_utf8_lossy(&listed.stdout).contains("raytraced"), "{}", stderr(&listed));

    let args = ["render", "spheres", "--technique", "raytraced", "--refine", "off", "--verbose"];
    let out = gnomon(dir, &[&args[..], &SMALL, &["-o", "mask.png"]].concat());
    let err = stderr(&out);
    assert!(out.status.success() && dir.join("mask.png").is_file(), "{err}");
    let line = err.lines().find(|l| l.contains(": refined by rays at ")).expect("the traced pixels' line");
    let pixels: u64 = line.split(" at ").nth(1).and_then(|r| r.split(' ').next()?.parse().ok()).unwrap();
    // Most of a 160×90 view of `spheres` faces the sun.
    assert!(pixels > 5_000, "{line}");
    assert!(!err.contains("warning"), "{err}");

    let forward = ["--shadow-path", "forward", "-o", "forward.png"];
    let out = gnomon(dir, &[&args[..], &SMALL, &forward].concat());
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(err.contains("refined by rays in the lighting pass (forward path: not counted)"), "{err}");

    // A soft sun's penumbra rays are the technique's own: no warning that they go unused.
    let soft = ["--sun-angular-diameter", "1", "--penumbra-rays", "4", "-o", "soft.png"];
    let out = gnomon(dir, &[&args[..], &SMALL, &soft].concat());
    let err = stderr(&out);
    assert!(
        out.status.success() && !err.contains("penumbra_rays") && !err.contains("--penumbra-rays"),
        "{err}"
    );
    // On the mask path a soft sun's pixels are beamed over the beam's samples.
    let beamed = format!("{} per pixel over the light's area", gnomon_math::light_masks::SAMPLES);
    assert!(err.contains(&beamed), "{err}");
}
