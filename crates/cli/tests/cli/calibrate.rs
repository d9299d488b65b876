//! End-to-end tests of `gnomon calibrate`: the sweep's outputs, the chosen setting
//! written into a scene file, and bad input refused before any work.

use crate::support;

use support::{files_in, stderr, temp_dir};

fn calibrate(dir: &std::path::Path, args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_gnomon"))
        .current_dir(dir)
        .env("GNOMON_CACHE_DIR", dir.join("cache"))
        .args(["calibrate", "contact", "--width", "160", "--height", "90", "--shadow-res", "512"])
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn calibrate_plots_the_front_picks_a_setting_and_writes_it() {
    let temp = temp_dir("calibrate");
    let dir = temp.path();
    let authored = "# The courtyard, as its author wrote it.\nbuiltin = \"contact\"  # keep\n";
    std::fs::write(dir.join("scene.toml"), authored).unwrap();
    let out = calibrate(
        dir,
        &[
            "--technique",
            "hard",
            "--sweep-slope-bias",
            "0..3:3",
            "--sweep-normal-offset",
            "0..1:2",
            "--views",
            "2",
            "--out",
            "cal",
            "--write",
            "scene.toml",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(files_in(&dir.join("cal")), ["calibration.json", "calibration.md", "front.png"]);
    let report = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(report.contains("**chosen**") && report.contains("| defaults |"), "{report}");
    assert!(report.contains("Held-out views: chosen"), "{report}");
    // The sweep measures the map alone; the defaults as they render, with rays, are
    // measured on the held-out views beside it.
    assert!(report.contains("with --refine off") && report.contains("refined by rays"), "{report}");
    // The JSON holds every setting of the 3 × 2 grid, and the choice is the least
    // total mismatch among them.
    let json: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("cal/calibration.json")).unwrap()).unwrap();
    let points = json["points"].as_array().unwrap();
    assert_eq!(points.len(), 6, "{json}");
    let least = points.iter().map(|p| p["mismatch"].as_f64().unwrap()).fold(f64::INFINITY, f64::min);
    assert_eq!(json["chosen"]["mismatch"].as_f64(), Some(least), "{json}");
    assert_eq!(json["refine"], "off");
    let refined = json["held_out"]["defaults_refined_by_rays"]["mismatch"].as_f64().unwrap();
    assert!((0.0..=1.0).contains(&refined), "{json}");
    let plot = image::open(dir.join("cal/front.png")).unwrap();
    assert_eq!((plot.width(), plot.height()), (960, 720));
    // The plot is drawn, not blank: many distinct colours (text, axes, points).
    let colours: std::collections::HashSet<[u8; 4]> = plot.to_rgba8().pixels().map(|p| p.0).collect();
    assert!(colours.len() > 20, "{} colours", colours.len());
    // The chosen bias is in the scene file, which still loads and keeps its content.
    let written = std::fs::read_to_string(dir.join("scene.toml")).unwrap();
    assert!(written.starts_with(authored), "the author's comments and layout kept: {written}");
    let table: toml::Table = toml::from_str(&written).unwrap();
    assert_eq!(table["builtin"].as_str(), Some("contact"));
    let bias = &table["settings"]["shadow"]["bias"];
    let slope = bias["slope_bias"].as_float().unwrap();
    assert!([0.0, 1.5, 3.0].contains(&slope), "{written}");
    let render = std::process::Command::new(env!("CARGO_BIN_EXE_gnomon"))
        .current_dir(dir)
        .args(["render", "scene.toml", "--width", "64", "--height", "36", "--out", "check.png"])
        .output()
        .unwrap();
    assert!(render.status.success(), "{}", stderr(&render));
}

#[test]
fn calibrate_refuses_empty_inverted_and_pointless_sweeps_before_any_work() {
    let temp = temp_dir("calibrate-bad");
    let dir = temp.path();
    for (args, says) in [
        (&["--sweep-slope-bias", "3..1:4"][..], "inverted"),
        (&["--sweep-slope-bias", "0..1:0"][..], "1 to 64 values"),
        (&["--sweep-normal-offset", "0..1:1"][..], "STEPS ≥ 2"),
        (&["--sweep-slope-bias", "1..1:1", "--sweep-normal-offset", "0..0:1"][..], "nothing to sweep"),
        (&["--views", "1"][..], "--views = 1"),
        (&["--light", "all", "--light-index", "3"][..], "light"),
        // `contact` has no light list: a scene without lights to calibrate for.
        (&["--light", "all"][..], "calibration needs a light"),
        (&["--technique", "pcf2x2", "--sweep-kernel", "3..7:3"][..], "has no PCF kernel to sweep"),
        (&["--technique", "pcf", "--sweep-kernel", "0..7:3"][..], "--sweep-kernel = 0 is invalid"),
    ] {
        let out = calibrate(dir, &[args, &["--out", "cal"]].concat());
        assert!(!out.status.success(), "{args:?} was accepted");
        assert!(stderr(&out).contains(says), "{args:?}: {}", stderr(&out));
        assert!(!dir.join("cal").exists(), "{args:?} wrote output");
    }
}

/// All or nothing (issue 49): a `--write` file that cannot be edited (not TOML) fails
/// the run before any output is written (before the sweep, in fact), naming the file.
#[test]
fn calibrate_writes_nothing_when_its_scene_file_cannot_be_edited() {
    let temp = temp_dir("calibrate-write");
    let dir = temp.path();
    std::fs::write(dir.join("scene.toml"), "builtin = \"contact\"\n").unwrap();
    std::fs::write(dir.join("broken.toml"), "settings = [unclosed\n").unwrap();
    let out = calibrate(
        dir,
        &[
            "--technique",
            "hard",
            "--sweep-slope-bias",
            "0..1:2",
            "--views",
            "2",
            "--out",
            "cal",
            "--write",
            "broken.toml",
        ],
    );
    assert!(!out.status.success());
    let said = stderr(&out);
    assert!(said.contains("--write") && said.contains("broken.toml") && said.contains("not TOML"), "{said}");
    assert!(!dir.join("cal").exists(), "wrote {:?}", files_in(&dir.join("cal")));
    assert_eq!(std::fs::read_to_string(dir.join("broken.toml")).unwrap(), "settings = [unclosed\n");
}

/// A `--write` into a folder that takes no files (/proc, where even root cannot
/// create one) is refused before the sweep, naming the flag and the folder: the
/// audit's run failed only when its outputs were moved into place, after the work,
/// and said only "No such file or directory".
#[test]
#[cfg(target_os = "linux")]
fn calibrate_refuses_a_write_into_a_folder_that_takes_no_files_before_any_work() {
    let temp = temp_dir("calibrate-proc");
    let dir = temp.path();
    let out = calibrate(
        dir,
        &["--technique", "hard", "--views", "2", "--out", "cal", "--write", "/proc/gnomon-calibration.toml"],
    );
    assert!(!out.status.success());
    let said = stderr(&out);
    assert!(said.contains("--write /proc/gnomon-calibration.toml: cannot write in /proc"), "{said}");
    assert!(!said.contains("reference"), "it swept before refusing: {said}");
    assert!(!dir.join("cal").exists(), "wrote {:?}", files_in(&dir.join("cal")));
}
