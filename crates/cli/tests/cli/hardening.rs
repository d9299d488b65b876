//! The hardening audit's cases that the binary itself must handle: bounds on every
//! flag, warnings for settings that do nothing, negative values, errors that blame
//! the scene file's line instead of a flag, outputs that would overwrite each other,
//! the reference cache, and what a machine without a Vulkan driver sees.

use crate::support;

use std::process::Command;

use support::{files_in, gnomon, stderr, temp_dir};

const SMALL: [&str; 4] = ["--width", "32", "--height", "24"];

fn render(dir: &std::path::Path, args: &[&str]) -> std::process::Output {
    let mut all = vec!["render"];
    all.extend(SMALL);
    all.extend(args);
    gnomon(dir, &all)
}

#[test]
fn flags_beyond_their_finite_range_are_refused_before_any_work() {
    let temp = temp_dir("flag-bounds");
    let dir = temp.path();
    for (flag, value, range) in [
        ("--depth-bias", "2147483647", "16777216"),
        ("--depth-bias", "-2147483647", "16777216"),
        ("--slope-bias", "1e30", "0 to 100"),
        ("--normal-offset", "1e9", "0 to 64 texels"),
        ("--sun-elevation", "-30", "(0, 90]"),
        ("--sun-azimuth", "inf", "[-360, 360]"),
        ("--sun-angular-diameter", "1e30", "[0, 30]"),
        ("--fov", "0", "at least 0.01 degrees and below 180"),
        ("--fov", "1e-5", "at least 0.01 degrees"),
        ("--camera-near", "-1", "(0, 1e7]"),
        ("--csm-scale", "1e30", "(0, 100]"),
        ("--contact-distance", "1e30", "(0, 1e7]"),
        ("--contact-bias", "inf", "[0, 1e7]"),
    ] {
        let out = render(dir, &[flag, value]);
        assert!(!out.status.success(), "{flag} {value} was accepted");
        let e = stderr(&out);
        assert!(e.contains(flag) && e.contains(range), "{flag} {value}: {e}");
    }
    let out = render(dir, &["--kernel-unit", "world", "--pcf-kernel", "1e30"]);
    assert!(stderr(&out).contains("--pcf-kernel") && stderr(&out).contains("(0, 1e7]"), "{}", stderr(&out));
    assert!(files_in(dir).is_empty());
}

#[test]
fn settings_the_render_cannot_use_are_warned_of_by_what_they_need() {
    let temp = temp_dir("unused");
    let dir = temp.path();
    let out = render(dir, &["--light-index", "2", "--omni", "paraboloid", "--spot-range", "4"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let e = stderr(&out);
    assert!(e.contains("warning: --light-index has no effect here: it needs --light all"), "{e}");
    assert!(e.contains("warning: --omni has no effect here: it needs a point light"), "{e}");
    assert!(e.contains("warning: --spot-range has no effect here: it needs --light spot"), "{e}");
}

#[test]
fn negative_values_need_no_equals_sign_and_a_missing_value_is_still_reported() {
    let temp = temp_dir("negative");
    let dir = temp.path();
    let out = render(dir, &["--camera-target", "-5,5,0", "--sun-azimuth", "-56", "--depth-bias", "-3"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let out = gnomon(dir, &["render", "--out", "--width", "32"]);
    assert!(!out.status.success() && stderr(&out).contains("--out"), "{}", stderr(&out));
}

#[test]
fn a_bad_scene_file_value_is_reported_at_its_line_and_key_not_as_a_flag() {
    let temp = temp_dir("scene-file-blame");
    let dir = temp.path();
    std::fs::write(dir.join("res.toml"), "builtin = \"columns\"\n\n[settings.shadow.map]\nresolution = 3\n")
        .unwrap();
    let out = render(dir, &["res.toml"]);
    let e = stderr(&out);
    assert!(!out.status.success());
    assert!(e.contains("res.toml:4:14:") && e.contains("`settings.shadow.map.resolution` = 3"), "{e}");
    assert!(!e.contains("--shadow-res"), "the user typed no flag: {e}");
    // The file must stand alone: a flag that would override the value does not hide it.
    let out = render(dir, &["res.toml", "--shadow-res", "512"]);
    assert!(!out.status.success() && stderr(&out).contains("res.toml:4:14:"), "{}", stderr(&out));
    // A bad flag over a good file is the flag's.
    std::fs::write(dir.join("ok.toml"), "builtin = \"columns\"\n\n[settings.shadow.map]\nresolution = 512\n")
        .unwrap();
    let out = render(dir, &["ok.toml", "--shadow-res", "3"]);
    assert!(stderr(&out).contains("--shadow-res = 3"), "{}", stderr(&out));
    std::fs::write(
        dir.join("spot.toml"),
        "builtin = \"columns\"\n[spot]\nposition = [2, 6, 1]\ntarget = [0, 0, 0]\nouter_angle = 40\ninner_angle = -50\nrange = 30\n",
    )
    .unwrap();
    let out = render(dir, &["spot.toml", "--out", "spot.png"]);
    assert!(
        stderr(&out).contains("spot.toml:6:15:") && stderr(&out).contains("`inner_angle` = -50"),
        "{}",
        stderr(&out)
    );
    assert!(!dir.join("spot.png").exists());
}

#[test]
fn outputs_that_would_write_one_file_are_refused_before_rendering() {
    let temp = temp_dir("shared-outputs");
    let dir = temp.path();
    let out = render(dir, &["--out", "same.png", "--shadow-map-out", "./same.png"]);
    assert!(!out.status.success());
    assert!(stderr(&out).contains("are the same file"), "{}", stderr(&out));
    std::fs::create_dir(dir.join("D")).unwrap();
    let out = render(dir, &["--aov-out", "D", "--visibility-out", "D/visibility.exr", "--out", "a.png"]);
    assert!(!out.status.success());
    assert!(
        stderr(&out).contains("--aov-out") && stderr(&out).contains("--visibility-out"),
        "{}",
        stderr(&out)
    );
    let out = gnomon(
        dir,
        &["compare", "--techniques", "pcf,pcf", "--out", "cmp", "--width", "32", "--height", "24"],
    );
    assert!(!out.status.success());
    assert!(stderr(&out).contains("`pcf` twice"), "{}", stderr(&out));
    assert_eq!(files_in(dir), ["D"]);
    assert!(files_in(&dir.join("D")).is_empty());
}

/// An image whose frame, or whose reference, would pass the memory budget is refused
/// before any of it is allocated, naming what it would take, and writes nothing.
#[test]
fn an_image_over_the_memory_budget_is_refused_up_front() {
    let temp = temp_dir("budget");
    // 4000²: over the budget (3.8 GiB of targets, 1.4 GiB of reference), while its
    // largest target (244 MiB) fits any device's largest buffer (WebGPU's default 256).
    let huge = ["--width", "4000", "--height", "4000"];
    for (command, item) in
        [("render", "the image's targets, 4000×4000"), ("reference", "the reference's pixels, 4000×4000")]
    {
        let mut args = vec![command];
        args.extend(huge);
        args.extend(["--out", "x.png"]);
        let out = Command::new(env!("CARGO_BIN_EXE_gnomon"))
            .current_dir(temp.path())
            .env_remove("GNOMON_MEMORY_MIB")
            .env("GNOMON_CACHE_DIR", temp.path().join("cache"))
            .args(&args)
            .output()
            .unwrap();
        let e = stderr(&out);
        assert!(
            !out.status.success() && e.contains(item) && e.contains("GNOMON_MEMORY_MIB"),
            "{command}: {e}"
        );
        assert!(
            files_in(temp.path()).iter().all(|f| f == "cache"),
            "{command} wrote {:?}",
            files_in(temp.path())
        );
    }
}

#[test]
fn instances_beyond_the_limit_are_out_of_range_not_unknown() {
    let temp = temp_dir("instances");
    let out = render(temp.path(), &["instances:5000000"]);
    let e = stderr(&out);
    assert!(!out.status.success());
    assert!(
        e.contains("instances:5000000") && e.contains("10 to 4000000") && !e.contains("unknown scene"),
        "{e}"
    );
}

#[test]
fn without_a_vulkan_driver_the_install_hint_is_printed_or_the_render_runs() {
    let temp = temp_dir("no-vulkan");
    let dir = temp.path();
    let out = Command::new(env!("CARGO_BIN_EXE_gnomon"))
        .current_dir(dir)
        .env_remove("WGPU_BACKEND")
        .env("VK_ICD_FILENAMES", "/nonexistent")
        .args(["render", "--width", "32", "--height", "24"])
        .output()
        .unwrap();
    let e = stderr(&out);
    assert!(!e.contains("Validation Error") && !e.contains("panicked"), "{e}");
    if out.status.success() {
        assert_eq!(files_in(dir), ["gnomon.png"]);
    } else {
        assert!(e.contains("apt-get install mesa-vulkan-drivers"), "{e}");
        assert!(files_in(dir).is_empty());
    }
}

#[test]
fn an_unset_runtime_directory_prints_no_driver_noise() {
    let temp = temp_dir("xdg");
    let out = Command::new(env!("CARGO_BIN_EXE_gnomon"))
        .current_dir(temp.path())
        .env_remove("XDG_RUNTIME_DIR")
        .args(["render", "--width", "32", "--height", "24"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(!stderr(&out).contains("XDG_RUNTIME_DIR"), "{}", stderr(&out));
}

#[test]
fn the_cache_command_lists_and_clears_references() {
    let temp = temp_dir("cache");
    let cache = temp.path().join("cache");
    std::fs::create_dir(&cache).unwrap();
    for name in ["reference-a.bin", "reference-b.bin"] {
        std::fs::write(cache.join(name), vec![0u8; 4096]).unwrap();
    }
    std::fs::write(cache.join("notes.txt"), b"mine").unwrap();
    let run = |args: &[&str]| {
        Command::new(env!("CARGO_BIN_EXE_gnomon"))
            .env("GNOMON_CACHE_DIR", &cache)
            .args(args)
            .output()
            .unwrap()
    };
    let listed = run(&["cache"]);
    let text = String::from_utf8_lossy(&listed.stdout);
    assert!(text.contains("reference-a.bin") && text.contains("2 references"), "{text}");
    let cleared = run(&["cache", "--clear"]);
    assert!(String::from_utf8_lossy(&cleared.stdout).contains("removed 2 references"));
    assert_eq!(files_in(&cache), ["notes.txt"], "only references are removed");
    let bad = Command::new(env!("CARGO_BIN_EXE_gnomon"))
        .env("GNOMON_CACHE_DIR", &cache)
        .env("GNOMON_CACHE_MAX_MIB", "lots")
        .arg("cache")
        .output()
        .unwrap();
    assert!(!bad.status.success() && stderr(&bad).contains("GNOMON_CACHE_MAX_MIB"), "{}", stderr(&bad));
}

/// Ctrl-C while outputs are being staged removes every temporary file and writes no
/// output: the run polls for the first staged file, then interrupts.
#[test]
fn an_interrupt_while_staging_leaves_no_file_behind() {
    let temp = temp_dir("interrupt");
    let dir = temp.path();
    let mut child = Command::new(env!("CARGO_BIN_EXE_gnomon"))
        .current_dir(dir)
        .args(["render", "--width", "2048", "--height", "2048", "--aov-out", "aov", "--out", "a.png"])
        // A frame of 4 M pixels, over the default budget: large, so that staging lasts.
        .env("GNOMON_MEMORY_MIB", "4096")
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    let staged = |d: &std::path::Path| files_in(d).iter().any(|f| f.contains(".gnomon-"));
    let started = std::time::Instant::now();
    let mut interrupted = false;
    while started.elapsed() < std::time::Duration::from_secs(300) {
        if let Some(status) = child.try_wait().unwrap() {
            panic!("finished ({status}) before a staged file was seen");
        }
        if staged(dir) || (dir.join("aov").is_dir() && staged(&dir.join("aov"))) {
            let signal = Command::new("kill").args(["-INT", &child.id().to_string()]).status().unwrap();
            assert!(signal.success());
            interrupted = true;
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
    assert!(interrupted, "no staged file appeared");
    let out = child.wait_with_output().unwrap();
    assert_eq!(out.status.code(), Some(130), "{}", stderr(&out));
    assert!(stderr(&out).contains("interrupted"), "{}", stderr(&out));
    let left: Vec<String> = files_in(dir).into_iter().filter(|f| f != "aov").collect();
    assert!(left.is_empty(), "left behind: {left:?}");
    if dir.join("aov").is_dir() {
        assert!(files_in(&dir.join("aov")).is_empty(), "left behind: {:?}", files_in(&dir.join("aov")));
    }
}
