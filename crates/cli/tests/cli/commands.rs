//! End-to-end tests of the `gnomon` binary: the default render, the float outputs,
//! and bad input (clear message, non-zero exit, no file left behind).

use std::process::Command;

use crate::support;

use support::{files_in, gnomon, read_npy, stderr, temp_dir};

#[test]
fn no_arguments_renders_spheres_to_gnomon_png() {
    let temp = temp_dir("default");
    let dir = temp.path();
    let out = gnomon(dir, &[]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(String::from_utf8_lossy(&out.stdout).trim(), "gnomon.png");
    let image = image::open(dir.join("gnomon.png")).unwrap().to_rgba8();
    assert_eq!(image.dimensions(), (1280, 720));
    // Not blank: the image has sky, lit ground and shadow, so many distinct colours.
    let distinct: std::collections::HashSet<_> = image.pixels().map(|p| p.0).collect();
    assert!(distinct.len() > 1000, "only {} distinct colours", distinct.len());
    assert_eq!(files_in(dir), ["gnomon.png"]);
}

#[test]
fn float_outputs_are_written_with_their_documented_layout() {
    let temp = temp_dir("floats");
    let dir = temp.path();
    let out = gnomon(
        dir,
        &[
            "render",
            "contact",
            "--width",
            "160",
            "--height",
            "90",
            "--shadow-res",
            "512",
            "--out",
            "c.png",
            "--visibility-out",
            "v.npy",
            "--shadow-map-out",
            "map.png",
            "--aov-out",
            "aov",
            "--verbose",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(
        stderr(&out).contains("adapter:") && stderr(&out).contains("backend:"),
        "--verbose names the adapter: {}",
        stderr(&out)
    );
    let (header, values) = read_npy(&dir.join("v.npy"));
    assert!(header.contains("'shape': (90, 160)"), "{header}");
    assert_eq!(values.len(), 160 * 90);
    assert!(values.iter().all(|v| v.is_nan() || (0.0..=1.0).contains(v)));
    let lit = values.iter().filter(|v| **v > 0.5).count();
    let shadowed = values.iter().filter(|v| **v < 0.5).count();
    assert!(lit > 1000 && shadowed > 100, "lit {lit}, shadowed {shadowed}");
    let map = image::open(dir.join("map.png")).unwrap();
    assert_eq!((map.width(), map.height()), (512, 512));
    assert!(matches!(map, image::DynamicImage::ImageLuma16(_)));
    assert_eq!(
        files_in(&dir.join("aov")),
        [
            "depth.exr",
            "geometric_normal.exr",
            "normal.exr",
            "object_id.exr",
            "position.exr",
            "visibility.exr"
        ]
    );
}

/// `--aov-format npy`: the AOVs as NumPy files, vectors height × width × 3, and the
/// same values as the `.npy` visibility output.
#[test]
fn aovs_as_npy_have_their_documented_shapes() {
    let temp = temp_dir("aov-npy");
    let dir = temp.path();
    let size = ["--width", "64", "--height", "36"];
    let args = ["render", "contact", "--out", "c.png", "--visibility-out", "v.npy", "--aov-out", "aov"];
    let out = gnomon(dir, &[&args[..], &size[..], &["--aov-format", "npy"]].concat());
    assert!(out.status.success(), "{}", stderr(&out));
    let aov = dir.join("aov");
    assert_eq!(
        files_in(&aov),
        [
            "depth.npy",
            "geometric_normal.npy",
            "normal.npy",
            "object_id.npy",
            "position.npy",
            "visibility.npy"
        ]
    );
    let header = |path: &std::path::Path| {
        let bytes = std::fs::read(path).unwrap();
        let len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
        let header = String::from_utf8(bytes[10..10 + len].to_vec()).unwrap();
        assert_eq!((10 + len) % 64, 0, "{header}");
        (header, bytes[10 + len..].to_vec())
    };
    for (name, shape, values) in [("position", "(36, 64, 3)", 36 * 64 * 3), ("depth", "(36, 64)", 36 * 64)] {
        let (text, data) = header(&aov.join(format!("{name}.npy")));
        assert!(text.contains(&format!("'shape': {shape}")) && text.contains("'<f4'"), "{name}: {text}");
        assert_eq!(data.len(), 4 * values, "{name}");
    }
    assert_eq!(header(&aov.join("visibility.npy")), header(&dir.join("v.npy")));
    let bad = gnomon(dir, &["render", "--aov-out", "aov2", "--aov-format", "tiff"]);
    assert!(!bad.status.success() && stderr(&bad).contains("--aov-format"), "{}", stderr(&bad));
}

#[test]
fn an_unknown_scene_names_the_valid_ones() {
    let temp = temp_dir("unknown");
    let dir = temp.path();
    let out = gnomon(dir, &["render", "nope"]);
    assert!(!out.status.success());
    let e = stderr(&out);
    assert!(
        e.contains("unknown scene `nope`")
            && e.contains("spheres, contact, grazing, columns")
            && e.contains(".glb"),
        "{e}"
    );
    assert!(files_in(dir).is_empty());
}

#[test]
fn a_shadow_map_beyond_the_device_limit_is_refused() {
    let temp = temp_dir("limit");
    let dir = temp.path();
    let out = Command::new(env!("CARGO_BIN_EXE_gnomon"))
        .current_dir(dir)
        .env("GNOMON_MAX_TEXTURE_SIZE", "2048")
        .args(["render", "--shadow-res", "4096"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let e = stderr(&out);
    assert!(e.contains("--shadow-res = 4096") && e.contains("up to 2048"), "{e}");
    assert!(files_in(dir).is_empty());
    let out = gnomon(dir, &["render", "--shadow-res", "100000"]);
    assert!(!out.status.success());
    assert!(stderr(&out).contains("256 to 8192"), "{}", stderr(&out));
    assert!(files_in(dir).is_empty());
}

#[test]
fn an_unwritable_output_fails_cleanly_and_writes_nothing() {
    let temp = temp_dir("unwritable");
    let dir = temp.path();
    std::fs::write(dir.join("a-file"), b"x").unwrap();
    // The directory of --out does not exist.
    let out = gnomon(dir, &["render", "--out", "missing/x.png"]);
    assert!(!out.status.success());
    assert!(stderr(&out).contains("missing") && stderr(&out).contains("does not exist"), "{}", stderr(&out));
    // One good output and one bad: neither is written.
    let out = gnomon(
        dir,
        &["render", "--width", "64", "--height", "64", "--out", "ok.png", "--visibility-out", "a-file/v.npy"],
    );
    assert!(!out.status.success());
    assert!(stderr(&out).contains("--visibility-out"), "{}", stderr(&out));
    // A wrong extension names the valid ones.
    let out = gnomon(dir, &["render", "--visibility-out", "v.txt"]);
    assert!(stderr(&out).contains(".exr or .npy"), "{}", stderr(&out));
    assert_eq!(files_in(dir), ["a-file"]);
}

#[test]
fn compare_writes_grid_metrics_heatmaps_and_reuses_the_cached_reference() {
    let temp = temp_dir("compare");
    let dir = temp.path();
    let run = || {
        Command::new(env!("CARGO_BIN_EXE_gnomon"))
            .current_dir(dir)
            .env("GNOMON_CACHE_DIR", dir.join("cache"))
            .args(["compare", "contact", "--width", "160", "--height", "90", "--shadow-res", "512"])
            .args(["--techniques", "hard,pcf2x2", "--out", "cmp", "--timing-frames", "2"])
            .output()
            .unwrap()
    };
    let out = run();
    assert!(out.status.success(), "{}", stderr(&out));
    let table = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(table.contains("| hard |") && table.contains("| pcf2x2 |"), "{table}");
    assert_eq!(
        files_in(&dir.join("cmp")),
        [
            "aliasing.png",
            "grid.png",
            "hard-error.png",
            "hard.png",
            "metrics.json",
            "metrics.md",
            "pcf2x2-error.png",
            "pcf2x2.png",
            "reference.png"
        ]
    );
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("cmp/metrics.json")).unwrap()).unwrap();
    let rows = json["rows"].as_array().unwrap();
    assert_eq!(rows.len(), 2);
    for row in rows {
        let compared = row["compared"].as_u64().unwrap();
        assert!(compared > 5000, "{row}");
        let rate = row["mismatch_rate"].as_f64().unwrap();
        assert!((0.0..0.05).contains(&rate), "{row}");
        // A sun without size: an exact reference, no penumbra, an edge band.
        assert_eq!(row["penumbra"]["pixels"].as_u64(), Some(0), "{row}");
        assert_eq!(row["penumbra"]["width"]["profiles"].as_u64(), Some(0), "{row}");
        assert!(row["edge"]["pixels"].as_u64().unwrap() > 100, "{row}");
    }
    assert!(table.contains("MAE, edge band"), "{table}");
    let grid = image::open(dir.join("cmp/grid.png")).unwrap();
    assert!(grid.width() > 960 && grid.height() > 3 * 270 / 2, "{}×{}", grid.width(), grid.height());
    // The second run reuses the reference.
    let again = run();
    assert!(again.status.success());
    assert!(stderr(&again).contains("loaded from the cache"), "{}", stderr(&again));
    // Same metrics from the cached reference (the timings differ run to run).
    let again: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("cmp/metrics.json")).unwrap()).unwrap();
    for (a, b) in rows.iter().zip(again["rows"].as_array().unwrap()) {
        for key in ["compared", "silhouette", "false_shadow", "false_lit", "mae", "p99"] {
            assert_eq!(a[key], b[key], "{key}");
        }
    }
}

/// Under an area light, `compare` reports the error over the reference's penumbra
/// beside the all-pixel one, with the penumbra width error, each named for its
/// denominator in metrics.json, metrics.md and the captions.
#[test]
fn compare_reports_penumbra_metrics_under_an_area_light() {
    let temp = temp_dir("compare-penumbra");
    let dir = temp.path();
    let out = Command::new(env!("CARGO_BIN_EXE_gnomon"))
        .current_dir(dir)
        .env("GNOMON_CACHE_DIR", dir.join("cache"))
        .args(["compare", "contact", "--light", "spot", "--spot-radius", "0.25", "--samples", "32"])
        .args(["--width", "240", "--height", "135", "--shadow-res", "1024"])
        .args(["--techniques", "pcf,pcss", "--out", "cmp", "--timing-frames", "1"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    let table = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(table.contains("MAE, penumbra") && table.contains("width error px"), "{table}");
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("cmp/metrics.json")).unwrap()).unwrap();
    assert!(json["denominators"]["penumbra.pixels, penumbra.mae, penumbra.rmse"].is_string(), "{json}");
    for row in json["rows"].as_array().unwrap() {
        let penumbra = &row["penumbra"];
        assert!(penumbra["pixels"].as_u64().unwrap() > 100, "{row}");
        // The penumbra is where the error is: its MAE exceeds the all-pixel one.
        assert!(penumbra["mae"].as_f64().unwrap() > row["mae"].as_f64().unwrap(), "{row}");
        let width = &penumbra["width"];
        assert!(width["profiles"].as_u64().unwrap() > 10, "{row}");
        assert!(width["error_px"].as_f64().unwrap() >= 0.0, "{row}");
    }
}

#[test]
fn compare_along_a_camera_path_reports_m_flips_and_shimmer() {
    let temp = temp_dir("camera-path");
    let dir = temp.path();
    let out = Command::new(env!("CARGO_BIN_EXE_gnomon"))
        .current_dir(dir)
        .env("GNOMON_CACHE_DIR", dir.join("cache"))
        .args(["compare", "columns", "--width", "160", "--height", "90", "--shadow-res", "512"])
        .args(["--techniques", "hard", "--out", "cmp", "--timing-frames", "1"])
        .args(["--camera-path", "orbit", "--path-frames", "3", "--partition", "cascades"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    let json: serde_json::Value =
        serde_json::from_slice(&std::fs::read(dir.join("cmp/metrics.json")).unwrap()).unwrap();
    let m = json["aliasing"]["mean"].as_f64().unwrap();
    assert!(m > 0.01 && m < 100.0, "mean m {m}");
    let flicker = &json["rows"][0]["flicker"];
    assert_eq!(flicker["pairs"].as_u64(), Some(2), "{flicker}");
    // An orbit of 0.05 rad moves the shadows across the screen: the reference flips.
    assert!(flicker["reference_flip_rate"].as_f64().unwrap() > 0.0, "{flicker}");
    let shimmer = flicker["shimmer_rate"].as_f64().unwrap();
    assert!((0.0..0.05).contains(&shimmer), "{flicker}");
    // Bad path parameters name the flag and the valid range, and write nothing.
    let bad = Command::new(env!("CARGO_BIN_EXE_gnomon"))
        .current_dir(dir)
        .args(["compare", "columns", "--camera-path", "dolly", "--path-frames", "1", "--out", "bad"])
        .output()
        .unwrap();
    assert!(!bad.status.success());
    assert!(stderr(&bad).contains("--path-frames = 1 is invalid: 2 to 240"), "{}", stderr(&bad));
    assert!(!dir.join("bad").exists());
}

#[test]
fn reference_writes_visibility_and_standard_error() {
    let temp = temp_dir("reference");
    let dir = temp.path();
    let out = Command::new(env!("CARGO_BIN_EXE_gnomon"))
        .current_dir(dir)
        .env("GNOMON_CACHE_DIR", dir.join("cache"))
        .args(["reference", "spheres", "--light", "spot", "--spot-radius", "0.4", "--samples", "16"])
        .args(["--width", "96", "--height", "54", "--out", "r.exr", "--std-error-out", "se.npy"])
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(stderr(&out).contains("Mrays/s") && stderr(&out).contains("standard error"), "{}", stderr(&out));
    let names = files_in(dir);
    assert!(names.contains(&"r.exr".to_string()) && names.contains(&"se.npy".to_string()), "{names:?}");
    // The same visibility as a .npy (from the cache): a header, then 96 × 54 floats.
    let npy = Command::new(env!("CARGO_BIN_EXE_gnomon"))
        .current_dir(dir)
        .env("GNOMON_CACHE_DIR", dir.join("cache"))
        .args(["reference", "spheres", "--light", "spot", "--spot-radius", "0.4", "--samples", "16"])
        .args(["--width", "96", "--height", "54", "--out", "r.npy"])
        .output()
        .unwrap();
    assert!(npy.status.success(), "{}", stderr(&npy));
    let bytes = std::fs::read(dir.join("r.npy")).unwrap();
    let se = std::fs::read(dir.join("se.npy")).unwrap();
    assert!(bytes.starts_with(b"\x93NUMPY") && bytes.len() == se.len(), "{} bytes", bytes.len());
    let bad = gnomon(dir, &["reference", "--samples", "4"]);
    assert!(!bad.status.success() && stderr(&bad).contains("--samples"), "{}", stderr(&bad));
}

/// A one-triangle glTF with its buffer embedded as a data URI.
const TRIANGLE_GLTF: &str = r#"{
  "asset": {"version": "2.0"},
  "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
  "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
  "buffers": [{"uri": "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAAAAAAIC/", "byteLength": 36}],
  "bufferViews": [{"buffer": 0, "byteLength": 36}],
  "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3", "min": [0, 0, -1], "max": [1, 0, 0]}]
}"#;

#[test]
fn a_scene_file_renders_with_its_views_and_settings() {
    let temp = temp_dir("scene-file");
    let dir = temp.path();
    std::fs::write(dir.join("tri.gltf"), TRIANGLE_GLTF).unwrap();
    // The flat triangle is stood upright (90° about x), so that the ground, placed at
    // the scene's lowest point, meets its bottom edge and catches its shadow.
    std::fs::write(
        dir.join("scene.toml"),
        "ground = true\n[[model]]\nfile = \"tri.gltf\"\ntranslation = [0.0, 0.5, 0.0]\nrotation_degrees = [90.0, 0.0, 0.0]\n\
         [[view]]\nname = \"above\"\neye = [0.3, 4.0, 0.5]\ntarget = [0.3, 0.0, -0.3]\n\
         [settings.image]\nwidth = 96\nheight = 54\n",
    )
    .unwrap();
    let out = gnomon(
        dir,
        &["render", "scene.toml", "--view", "above", "--out", "s.png", "--visibility-out", "v.npy"],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let image = image::open(dir.join("s.png")).unwrap();
    assert_eq!((image.width(), image.height()), (96, 54), "the file's [settings.image] applies");
    // The command line overrides the file.
    let out = gnomon(dir, &["render", "scene.toml", "--width", "64", "--out", "s.png"]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert_eq!(image::open(dir.join("s.png")).unwrap().width(), 64);
    // The triangle's shadow falls on the ground: some ground pixels are shadowed.
    let bytes = std::fs::read(dir.join("v.npy")).unwrap();
    let header_len = u16::from_le_bytes([bytes[8], bytes[9]]) as usize;
    let shadowed = bytes[10 + header_len..]
        .chunks(4)
        .filter(|c| f32::from_le_bytes((*c).try_into().unwrap()) < 0.5)
        .count();
    assert!(shadowed > 20, "{shadowed}");
    let bad = gnomon(dir, &["render", "scene.toml", "--view", "below"]);
    assert!(!bad.status.success() && stderr(&bad).contains("no view `below`"), "{}", stderr(&bad));
    let bad = gnomon(dir, &["render", "spheres", "--view", "above"]);
    assert!(
        !bad.status.success() && stderr(&bad).contains("views come from scene files"),
        "{}",
        stderr(&bad)
    );
}

#[test]
fn no_adapter_says_how_to_get_one() {
    // An empty WGPU_BACKEND enables no backend: the same as a machine with no driver.
    let temp = temp_dir("no-adapter");
    let dir = temp.path();
    let out = Command::new(env!("CARGO_BIN_EXE_gnomon"))
        .current_dir(dir)
        .env("WGPU_BACKEND", "")
        .arg("render")
        .output()
        .unwrap();
    assert!(!out.status.success());
    let e = stderr(&out);
    assert!(e.contains("no GPU adapter found") && e.contains("apt-get install mesa-vulkan-drivers"), "{e}");
    assert!(files_in(dir).is_empty());
}

#[test]
fn verbose_reports_frame_time_and_draws_for_each_of_many_lights() {
    let temp = temp_dir("many-lights");
    let dir = temp.path();
    let out = gnomon(
        dir,
        &[
            "render",
            "lamps",
            "--light",
            "all",
            "--width",
            "320",
            "--height",
            "180",
            "--verbose",
            "-o",
            "lamps.png",
        ],
    );
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(dir.join("lamps.png").is_file());
    let (refined, lines): (Vec<&str>, Vec<&str>) = err
        .lines()
        .filter(|l| l.starts_with("gnomon: light "))
        .partition(|l| l.contains(": refined by rays at "));
    assert_eq!(lines.len(), 8, "{err}");
    // The default refines every hard light by rays, and says where.
    assert!(!refined.is_empty() && refined.len() <= 8, "{err}");
    assert!(lines[0].contains("`sun` (sun, pcf-poisson, map 4 × 2048²)"), "{}", lines[0]);
    assert!(
        lines[4].contains("(point, pcf2x2, map 6 × 512²)") && lines[4].contains("shadow draws ["),
        "{}",
        lines[4]
    );
    assert!(err.contains("rendered in"), "{err}");
    // The GPU's frame time where the device has timestamp queries (lavapipe does).
    if err.contains("GPU time") {
        assert!(err.contains("GPU time: frame "), "{err}");
    }

    // A technique a cube map cannot take is refused, naming the light.
    let out = gnomon(dir, &["render", "--light", "point", "--technique", "vsm", "-o", "vsm.png"]);
    let err = stderr(&out);
    assert!(!out.status.success() && err.contains("--technique") && err.contains("point light"), "{err}");
    assert!(!dir.join("vsm.png").exists());
    // --light all needs a light list.
    let out = gnomon(dir, &["render", "columns", "--light", "all", "-o", "none.png"]);
    let err = stderr(&out);
    assert!(!out.status.success() && err.contains("light list") && err.contains("lamps"), "{err}");
}

#[test]
fn penumbrae_refined_by_rays_report_their_rays_and_refuse_an_impossible_count() {
    let temp = temp_dir("penumbra-rays");
    let dir = temp.path();
    let args = ["render", "contact", "--light", "spot", "--spot-radius", "0.5", "--technique", "pcss"];
    let small = ["--width", "160", "--height", "90", "--refine", "rays", "--verbose"];
    let out = gnomon(dir, &[&args[..], &small, &["--penumbra-rays", "8", "-o", "soft.png"]].concat());
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    let line = err.lines().find(|l| l.contains(": refined by rays at ")).expect("a refined light's line");
    let pixels: u64 = line.split(" at ").nth(1).and_then(|r| r.split(' ').next()?.parse().ok()).unwrap();
    // The mask path beams an area light's unsure pixels over the beam's fixed samples
    // of the light, whatever --penumbra-rays says (it sets the forward path's rays).
    let samples = gnomon_math::light_masks::SAMPLES as u64;
    assert!(
        pixels > 0
            && line
                .contains(&format!("({} rays, {samples} per pixel over the light's area)", samples * pixels)),
        "{line}"
    );
    // Lavapipe traces with the shader's BVH, whatever ray queries it has (`--tracer auto`).
    assert!(line.ends_with(", traced by the shader's BVH"), "{line}");
    let out = gnomon(dir, &[&args[..], &small, &["--penumbra-rays", "0", "-o", "none.png"]].concat());
    let err = stderr(&out);
    assert!(!out.status.success() && err.contains("--penumbra-rays") && err.contains("1 to 256"), "{err}");
    assert!(!dir.join("none.png").exists());
}

#[test]
fn contact_shadows_render_through_the_mask_and_forward_refuses_them() {
    let temp = temp_dir("contact-shadows");
    let dir = temp.path();
    let args = ["render", "contact", "--width", "320", "--height", "180", "--contact-shadows", "--verbose"];
    let out = gnomon(dir, &[&args[..], &["-o", "contact.png"]].concat());
    let err = stderr(&out);
    assert!(out.status.success(), "{err}");
    assert!(dir.join("contact.png").is_file());
    assert!(err.contains("in the prepass (shadows resolved in a screen-space mask)"), "{err}");
    // Contact shadows march through the prepass's depth: the forward path has none.
    let out = gnomon(dir, &[&args[..], &["--shadow-path", "forward", "-o", "forward.png"]].concat());
    let err = stderr(&out);
    assert!(!out.status.success() && !dir.join("forward.png").exists());
    assert!(err.contains("--contact-shadows") && err.contains("--shadow-path auto or mask"), "{err}");
    // An impossible parameter names its flag and range.
    let out = gnomon(dir, &[&args[..], &["--contact-steps", "0", "-o", "zero.png"]].concat());
    let err = stderr(&out);
    assert!(!out.status.success() && err.contains("--contact-steps") && err.contains("1 to 64"), "{err}");
}

/// `gnomon view --frames N --screenshot FILE` renders in a window (a virtual X server
/// here) and saves it; bad viewer arguments and a missing display are refused with the
/// input named, before any window opens and with nothing written.
#[test]
fn the_viewer_saves_a_screenshot_and_refuses_bad_input() {
    let temp = temp_dir("view");
    let dir = temp.path();
    let refused = |args: &[&str], needle: &str| {
        let out = Command::new(env!("CARGO_BIN_EXE_gnomon"))
            .current_dir(dir)
            .args(args)
            .env_remove("DISPLAY")
            .env_remove("WAYLAND_DISPLAY")
            .output()
            .unwrap();
        assert!(!out.status.success(), "{args:?} succeeded");
        assert!(stderr(&out).contains(needle), "{args:?}: {}", stderr(&out));
        assert!(!stderr(&out).contains("panicked"), "{args:?}: {}", stderr(&out));
    };
    refused(&["view", "--screenshot", "shot.jpg", "--frames", "2"], "--screenshot");
    refused(&["view", "--window", "10x10"], "WIDTHxHEIGHT");
    refused(&["view", "--frames", "0"], "--frames");
    refused(&["view", "nope"], "unknown scene `nope`");
    refused(&["view", "--frames", "2"], "xvfb-run");
    assert!(files_in(dir).is_empty());

    let out = Command::new("xvfb-run")
        .current_dir(dir)
        .args(["-a", "-s", "-screen 0 1280x800x24", env!("CARGO_BIN_EXE_gnomon")])
        .args(["view", "contact", "--frames", "3", "--screenshot", "shot.png", "--window", "900x600"])
        .output()
        .expect("xvfb-run (Debian package xvfb; scripts/install-system-deps.sh --tests installs it)");
    assert!(out.status.success(), "{}", stderr(&out));
    let shot = image::open(dir.join("shot.png")).unwrap().to_rgba8();
    // The window's size in physical pixels (Xvfb has a scale factor of 1).
    assert_eq!(shot.dimensions(), (900, 600));
    let distinct: std::collections::HashSet<[u8; 4]> = shot.pixels().map(|p| p.0).collect();
    assert!(distinct.len() > 500, "a near-blank screenshot: {} colours", distinct.len());
    assert_eq!(files_in(dir), ["shot.png"]);
}

#[test]
fn bench_times_each_pass_and_layer_per_technique_and_sweep_value() {
    let temp = temp_dir("bench");
    let dir = temp.path();
    let out = gnomon(
        dir,
        &[
            "bench",
            "spheres",
            "--techniques",
            "hard,vsm",
            "--sweep",
            "shadow-res=256,512",
            "--partition",
            "cascades",
            "--cascades",
            "2",
            "--frames",
            "3",
            "--warmup",
            "1",
            "--size",
            "96x64",
            "--depth-only",
            "--moving",
            "2",
            // The map alone: with rays refining it, the hard technique's touched
            // layer would be timed under `filter` too.
            "--refine",
            "off",
            "--out",
            "b",
        ],
    );
    assert!(out.status.success(), "{}", stderr(&out));
    let mut written = files_in(&dir.join("b"));
    written.sort();
    assert_eq!(written, ["bench.json", "bench.md"]);
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("b/bench.json")).unwrap()).unwrap();
    assert!(!report["adapter"].as_str().unwrap().is_empty() && report["driver"].is_string());
    assert_eq!((report["width"].as_u64(), report["height"].as_u64()), (Some(96), Some(64)));
    assert!(report["moving"] == 2 && report["rebuild_ms"].as_f64().unwrap() > 0.0, "{report}");
    let configs = report["configs"].as_array().unwrap();
    let labels: Vec<(String, String)> = configs
        .iter()
        .map(|c| (c["technique"].as_str().unwrap().into(), c["sweep_value"].as_str().unwrap().into()))
        .collect();
    assert_eq!(labels.len(), 4, "two techniques × two resolutions: {labels:?}");
    assert_eq!(labels[1], ("hard".to_string(), "512".to_string()));
    for config in configs {
        let pass =
            |name: &str| config["passes"].as_array().unwrap().iter().find(|p| p["name"] == name).cloned();
        for name in ["shadow", "lighting", "GPU frame", "CPU submit", "wall frame", "CPU move"] {
            let p = pass(name).unwrap_or_else(|| panic!("no {name} in {config}"));
            let (median, p95) = (p["median_ms"].as_f64().unwrap(), p["p95_ms"].as_f64().unwrap());
            assert!(median > 0.0 && p95 >= median && p["samples"] == 3, "{name}: {p}");
        }
        // The filterable technique has its moment pass timed; the other has none.
        assert_eq!(pass("filter").is_some(), config["technique"] == "vsm", "{config}");
        let layers = config["layers"].as_array().unwrap();
        assert_eq!(layers.len(), 2, "one time per cascade: {config}");
        // Frame by frame, the clocks nest: the GPU's frame and the CPU's submission
        // inside the wall-clock time of the call.
        let values = |p: &serde_json::Value| -> Vec<f64> {
            p["values_ms"].as_array().unwrap().iter().map(|v| v.as_f64().unwrap()).collect()
        };
        let [gpu, submit, wall, shadow] =
            ["GPU frame", "CPU submit", "wall frame", "shadow"].map(|n| values(&pass(n).unwrap()));
        for i in 0..3 {
            assert!(gpu[i] <= wall[i] && submit[i] <= wall[i], "frame {i}: {config}");
        }
        // The reported ratio is the median over frames of each frame's shadow time over
        // its baseline time (one sun: every light has a baseline), recomputed here.
        let baseline = values(&config["depth_only"]);
        let mut ratios: Vec<f64> = shadow.iter().zip(&baseline).map(|(s, b)| s / b).collect();
        ratios.sort_by(f64::total_cmp);
        let reported = config["shadow_over_depth_only"].as_f64().unwrap();
        assert!((reported - ratios[1]).abs() <= 1e-12 * reported, "{reported} vs {ratios:?}");
    }
    let md = std::fs::read_to_string(dir.join("b/bench.md")).unwrap();
    assert!(md.contains("| technique | shadow-res |") && md.contains("L0 layer 1"), "{md}");

    // Bad input: named, and nothing written.
    for (args, expected) in [
        (&["bench", "--sweep", "no-such-flag=1,2"][..], "no such setting"),
        (&["bench", "--sweep", "shadow-res=100"][..], "--sweep shadow-res=100"),
        (&["bench", "--size", "12"][..], "WIDTHxHEIGHT"),
        (&["bench", "--frames", "0"][..], "--frames 0"),
        (&["bench", "--moving", "0"][..], "--moving 0: give 1 to"),
        (&["bench", "instances:5"][..], "from 10 to 4000000"),
    ] {
        let out = gnomon(dir, args);
        assert!(!out.status.success() && stderr(&out).contains(expected), "{args:?}: {}", stderr(&out));
    }
    assert_eq!(files_in(dir), ["b"]);
}
