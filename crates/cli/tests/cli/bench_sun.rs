//! `bench --sun-path day`, `--spot-path sweep` and `--point-path sway`: a light
//! that moves every frame leaves no kept map valid, so every layer is drawn and its
//! texels counted; a still light with kept maps draws none.

use crate::support::{gnomon, stderr, temp_dir};

/// The median of one of a configuration's measured quantities.
fn median(config: &serde_json::Value, name: &str) -> f64 {
    let passes = config["passes"].as_array().unwrap();
    let pass = passes.iter().find(|p| p["name"] == name).unwrap_or_else(|| panic!("no {name} in {config}"));
    pass["median_ms"].as_f64().unwrap()
}

/// Runs `bench spheres` at 64² with a 256² map, kept maps on, and the extra flags;
/// returns its one configuration.
fn bench(dir: &std::path::Path, out: &str, extra: &[&str]) -> serde_json::Value {
    let mut args =
        vec!["bench", "spheres", "--frames", "3", "--warmup", "1", "--width", "64", "--height", "64"];
    args.extend(["--shadow-res", "256", "--refine", "off", "--map-cache", "still-casters", "--out", out]);
    args.extend(extra);
    let run = gnomon(dir, &args);
    assert!(run.status.success(), "{}", stderr(&run));
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join(out).join("bench.json")).unwrap()).unwrap();
    report["configs"][0].clone()
}

#[test]
fn a_moving_sun_draws_every_frame_and_a_still_one_keeps_its_map() {
    let temp = temp_dir("bench-sun");
    let dir = temp.path();
    let layer_mtexels = 256.0 * 256.0 / 1e6;
    let moving = bench(dir, "moving", &["--sun-path", "day"]);
    assert_eq!(median(&moving, "layers drawn"), 1.0, "{moving}");
    assert_eq!(median(&moving, "layers kept"), 0.0, "{moving}");
    assert!((median(&moving, "shadow Mtexels") - layer_mtexels).abs() < 1e-9, "{moving}");
    let still = bench(dir, "still", &[]);
    assert_eq!(median(&still, "layers kept"), 1.0, "{still}");
    assert_eq!(median(&still, "shadow Mtexels"), 0.0, "{still}");

    // Only the sun moves along a day.
    let out = gnomon(dir, &["bench", "spheres", "--sun-path", "day", "--light", "spot", "--out", "bad"]);
    assert!(!out.status.success() && stderr(&out).contains("--sun-path"), "{}", stderr(&out));
    assert!(!dir.join("bad").exists());
}

/// `bench --spot-path sweep`: a spot whose aim swings every frame leaves no kept map
/// valid, as a moving sun does; only the spot sweeps.
#[test]
fn a_sweeping_spot_draws_every_frame() {
    let temp = temp_dir("bench-spot");
    let dir = temp.path();
    let moving = bench(dir, "moving", &["--light", "spot", "--spot-path", "sweep"]);
    assert_eq!(median(&moving, "layers drawn"), 1.0, "{moving}");
    assert_eq!(median(&moving, "layers kept"), 0.0, "{moving}");
    let still = bench(dir, "still", &["--light", "spot"]);
    assert_eq!(median(&still, "layers kept"), 1.0, "{still}");

    let out = gnomon(dir, &["bench", "spheres", "--spot-path", "sweep", "--out", "bad"]);
    assert!(!out.status.success() && stderr(&out).contains("--spot-path"), "{}", stderr(&out));
    assert!(!dir.join("bad").exists());
}

/// `bench --point-path sway`: a point light carried across every frame redraws all
/// six faces of its cube map, and every page its virtual map's pixels read; still,
/// it keeps them; only the point light sways.
#[test]
fn a_swaying_point_light_draws_every_frame() {
    let temp = temp_dir("bench-point");
    let dir = temp.path();
    let moving = bench(dir, "moving", &["--light", "point", "--point-path", "sway"]);
    assert_eq!(median(&moving, "layers drawn"), 6.0, "{moving}");
    assert_eq!(median(&moving, "layers kept"), 0.0, "{moving}");
    let still = bench(dir, "still", &["--light", "point"]);
    assert_eq!(median(&still, "layers kept"), 6.0, "{still}");
    let virtual_map = ["--light", "point", "--partition", "virtual"];
    let moving = bench(dir, "moving-virtual", &[&virtual_map[..], &["--point-path", "sway"]].concat());
    assert!(median(&moving, "pages drawn") > 0.0, "{moving}");
    let still = bench(dir, "still-virtual", &virtual_map);
    assert_eq!(median(&still, "pages drawn"), 0.0, "{still}");

    let out = gnomon(dir, &["bench", "spheres", "--point-path", "sway", "--out", "bad"]);
    assert!(!out.status.success() && stderr(&out).contains("--point-path"), "{}", stderr(&out));
    assert!(!dir.join("bad").exists());
}
