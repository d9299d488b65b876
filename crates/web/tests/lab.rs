//! The lab the browser runs, driven natively on lavapipe: the same code, minus
//! wasm-bindgen. Its frames must be the renderer's own, its truth `raytraced`'s,
//! and a bad file must leave it working.

use gnomon_render::{Gpu, OutputRequest, Renderer};
use gnomon_web::{
    flags::{Flag, settings_from_flags},
    lab::{Lab, Truth},
};

// The shared `figure:` lines that `.ci/run` gathers into its summary.
#[allow(dead_code)]
#[path = "../../render/tests/gpu/support/figures.rs"]
mod figures;

fn flags(pairs: &[(&str, &str)]) -> Vec<Flag> {
    pairs.iter().map(|(n, v)| Flag { name: n.to_string(), value: v.to_string() }).collect()
}

fn gpu() -> Gpu {
    Gpu::new_headless().expect("a device (lavapipe: sh scripts/install-system-deps.sh --tests)")
}

/// Small enough to be quick, large enough for the spheres' shadows to span pixels.
const SMALL: [(&str, &str); 2] = [("width", "96"), ("height", "54")];

#[test]
fn the_labs_frame_is_the_renderers_and_its_counts_add_up() {
    let gpu = gpu();
    let mut lab = Lab::new(gpu.clone()).unwrap();
    let given = flags(&[SMALL[0], SMALL[1], ("technique", "pcf2x2")]);
    lab.set_flags(&given).unwrap();
    let report = pollster::block_on(lab.render(Truth::Measure)).unwrap();
    assert_eq!((report.scene.as_str(), report.technique.as_str()), ("spheres", "pcf2x2"));
    assert_eq!((report.width, report.height), (96, 54));

    let settings = settings_from_flags(&given).unwrap();
    let scene = gnomon_scene::builtin::spheres();
    let frame = Renderer::new(&gpu).unwrap().render(&scene, &settings, &OutputRequest::default()).unwrap();
    let lab_visibility = lab.visibility().unwrap();
    let same =
        frame.visibility.iter().zip(lab_visibility).filter(|(a, b)| a == b || a.is_nan() && b.is_nan());
    assert_eq!(same.count(), frame.visibility.len(), "the lab's frame differs from the renderer's");
    let drawn = frame.visibility.iter().filter(|v| v.is_finite()).count();
    assert_eq!(report.lit + report.shadowed, drawn);
    assert!(report.lit > 0 && report.shadowed > 0, "{report:?}");
    let truth = report.truth.clone().unwrap();
    assert!(truth.compared > drawn / 2, "{truth:?}");
    let mismatch = report.mismatch_vs_raytraced.unwrap();
    figures::figure("web lab, spheres, pcf2x2, against raytraced", figures::percent(mismatch), "< 1%");
    assert!(mismatch < 0.01, "{report:?}");
    assert_eq!(lab.heatmap().unwrap().len(), 96 * 54 * 4);
}

/// The truth against itself has no error; a map too coarse and too biased for the
/// scene has some, so the measure can fail.
#[test]
fn the_truth_measures_zero_against_itself_and_sees_a_poor_map() {
    let mut lab = Lab::new(gpu()).unwrap();
    lab.set_flags(&flags(&[SMALL[0], SMALL[1], ("technique", "raytraced")])).unwrap();
    let traced = pollster::block_on(lab.render(Truth::Measure)).unwrap();
    assert_eq!(traced.mismatch_vs_raytraced, Some(0.0), "{traced:?}");
    // A negative bias of about 0.12 of the depth range at depth 0.5 (`--depth-bias`'s
    // help) puts each surface behind its own depth in the map: acne, lit surfaces
    // falsely shadowed.
    let poor = [SMALL[0], SMALL[1], ("technique", "hard"), ("shadow-res", "256"), ("refine", "off")];
    lab.set_flags(&flags(&[&poor[..], &[("depth-bias", "-2000000")]].concat())).unwrap();
    let report = pollster::block_on(lab.render(Truth::Measure)).unwrap();
    let mismatch = report.mismatch_vs_raytraced.unwrap();
    figures::figure(
        "web lab, spheres, hard with acne, against raytraced",
        figures::percent(mismatch),
        "> 0.5%",
    );
    assert!(mismatch > 0.005, "{report:?}");
}

/// A bad file is refused with the loader's message, naming it; the lab keeps its
/// scene and renders on.
#[test]
fn a_bad_file_is_named_and_the_lab_keeps_working() {
    let mut lab = Lab::new(gpu()).unwrap();
    lab.set_flags(&flags(&SMALL)).unwrap();
    let e = lab.load_gltf(b"glTF\x02\x00\x00\x00garbage", "broken.glb").unwrap_err().to_string();
    assert!(e.starts_with("broken.glb: "), "{e}");
    assert_eq!(lab.scene_name(), "spheres");
    let e = lab.load_builtin("nowhere").unwrap_err().to_string();
    assert!(e.contains("unknown scene `nowhere`") && e.contains("spheres"), "{e}");
    let e = lab.set_flags(&flags(&[("width", "0")])).unwrap_err().to_string();
    assert!(e.contains("--width"), "{e}");
    let e = lab.set_flags(&flags(&[("technique", "nope")])).unwrap_err().to_string();
    assert!(e.contains("nope") && e.contains("pcss"), "{e}");
    assert_eq!(lab.settings().image.width, 96, "a refused flag changed the settings");
    assert!(pollster::block_on(lab.render(Truth::Skip)).is_ok());
}
