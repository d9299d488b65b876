//! The viewer in a real window: it opens (under Xvfb when there is no display),
//! renders frames on the GPU (lavapipe in CI), switches the technique through the
//! same action the panel's technique box sends, and saves screenshots, which must
//! show a picture and must change with the technique far more than between two
//! frames of one technique. Then it grabs a sphere, as Ctrl + drag does, and moves
//! it: the sphere is a moving caster while held, so the kept shadow maps keep every
//! layer and only the sphere is drawn over them.
//!
//! winit wants the main thread, so this test is its own `main` (`harness = false`).

use std::path::{Path, PathBuf};
use std::process::{Command, ExitCode};

use gnomon_scene::{Settings, builtin, settings::Technique};
use gnomon_viewer::{Action, Grip, LayerCache, SceneSource, View, ViewerOptions};

const UNDER_XVFB: &str = "GNOMON_TEST_UNDER_XVFB";

fn main() -> ExitCode {
    let no_display = std::env::var_os("DISPLAY").is_none() && std::env::var_os("WAYLAND_DISPLAY").is_none();
    if no_display && std::env::var_os(UNDER_XVFB).is_none() {
        return rerun_under_xvfb();
    }
    match window_test() {
        Ok(()) => {
            println!("test viewer_window ... ok");
            ExitCode::SUCCESS
        }
        Err(e) => {
            eprintln!("test viewer_window ... FAILED: {e:#}");
            ExitCode::FAILURE
        }
    }
}

/// Runs this test binary again inside a virtual X server.
fn rerun_under_xvfb() -> ExitCode {
    let me = std::env::current_exe().expect("the test binary's path");
    let status = Command::new("xvfb-run")
        .args(["-a", "-s", "-screen 0 1600x1000x24"])
        .arg(me)
        .args(std::env::args_os().skip(1))
        .env(UNDER_XVFB, "1")
        .status();
    match status {
        Ok(s) if s.success() => ExitCode::SUCCESS,
        Ok(s) => {
            eprintln!("test viewer_window ... FAILED under xvfb-run ({s})");
            ExitCode::FAILURE
        }
        Err(e) => {
            eprintln!(
                "test viewer_window ... FAILED: there is no display and `xvfb-run` cannot be started ({e}); \
                 install the Debian package `xvfb` (scripts/install-system-deps.sh does)"
            );
            ExitCode::FAILURE
        }
    }
}

fn window_test() -> anyhow::Result<()> {
    let dir = std::env::var_os("GNOMON_TEST_KEEP")
        .map(PathBuf::from)
        .unwrap_or_else(|| std::env::temp_dir().join(format!("gnomon-viewer-window-{}", std::process::id())));
    std::fs::create_dir_all(&dir)?;
    let shot = |name: &str| dir.join(format!("{name}.png"));
    let scene = builtin::build("spheres").expect("a built-in scene");
    let form = gnomon_viewer::settings_form::SettingsForm::new();
    // A large sun: PCSS's penumbrae are then wide, and hard shadows are not. The
    // map's answer alone (`refine off`): by default the sun's penumbrae are beamed to
    // the truth whatever the technique, and switching it would change nothing.
    let settings = form
        .set(&Settings::default(), "sun_angular_diameter", Some("6"))
        .and_then(|s| form.set(&s, "technique", Some("hard")))
        .and_then(|s| form.set(&s, "refine", Some("off")))
        .map_err(anyhow::Error::msg)?;
    let mut options = ViewerOptions::new(scene, settings, SceneSource::Builtin("spheres".into()));
    options.window_size = [1100, 700];
    options.frames = Some(21);
    let set = |id: &str, value: &str| Action::Set { id: id.into(), value: Some(value.into()) };
    options.script = vec![
        (3, Action::Screenshot(shot("hard"))),
        (5, Action::Screenshot(shot("hard-again"))),
        (6, set("technique", "pcss")),
        (9, Action::Screenshot(shot("pcss"))),
        (10, Action::SaveSceneFile(dir.join("view.toml"))),
        (10, Action::Show(View::TexelDensity)),
        (12, Action::Screenshot(shot("density"))),
        (13, Action::Show(View::Lit)),
        (13, Action::Grab(Grip::Named("sphere 1,1".into()))),
        (14, Action::Screenshot(shot("held"))),
        (15, Action::MoveHeldBy([1.5, 0.0, 0.0])),
        (16, Action::MoveHeldBy([0.0, 0.0, 1.0])),
        (18, Action::Screenshot(shot("moved"))),
        (19, Action::Release),
    ];
    let report = gnomon_viewer::run(options)?;

    anyhow::ensure!(report.frames == 21, "drew {} frames, not 21", report.frames);
    anyhow::ensure!(report.screenshots.len() == 6, "screenshots: {:?}", report.screenshots);
    anyhow::ensure!(
        report.settings.shadow.filter.technique == Technique::PCSS,
        "the technique action left {:?}",
        report.settings.shadow.filter.technique
    );
    let hard = load(&shot("hard"))?;
    let again = load(&shot("hard-again"))?;
    let pcss = load(&shot("pcss"))?;
    let density = load(&shot("density"))?;
    for (name, image) in [("hard", &hard), ("pcss", &pcss), ("density", &density)] {
        let spread = luminance_spread(image);
        println!("{name}: luminance standard deviation {spread:.1}");
        anyhow::ensure!(spread > 20.0, "the {name} screenshot is blank (luminance deviation {spread:.1})");
    }
    // Within the scene's view (the panels' timings change from frame to frame): one
    // technique renders the same picture twice; another changes the shadows.
    let [x, y, w, h] = report.view_rect;
    println!("the scene's view: {w}×{h} at ({x}, {y})");
    anyhow::ensure!(w > 200 && h > 200, "the scene's view is only {w}×{h}");
    let view = |image: &image::RgbaImage| image::imageops::crop_imm(image, x, y, w, h).to_image();
    let (hard, again, pcss, density) = (view(&hard), view(&again), view(&pcss), view(&density));
    anyhow::ensure!(luminance_spread(&hard) > 20.0, "the scene's view is blank");
    let control = changed_pixels(&hard, &again);
    let switched = changed_pixels(&hard, &pcss);
    let shown = changed_pixels(&pcss, &density);
    let pixels = (w * h) as usize;
    println!(
        "pixels changed of {pixels}: same technique {control}, hard → pcss {switched}, lit → texel density {shown}"
    );
    anyhow::ensure!(control * 1000 <= pixels, "one technique drew two different pictures ({control} pixels)");
    anyhow::ensure!(switched * 100 > pixels, "switching to PCSS changed only {switched} of {pixels} pixels");
    anyhow::ensure!(shown * 4 > pixels, "the texel-density view changed only {shown} of {pixels} pixels");

    // The held sphere: after the first frame (the scene uploaded again with it moving),
    // every layer keeps its map, and only the sphere is drawn over it.
    anyhow::ensure!(report.grabbed == ["sphere 1,1"], "grabbed {:?}", report.grabbed);
    let held = &report.layer_cache_while_held;
    println!("layer caches while held: {held:?}");
    anyhow::ensure!(held.len() >= 5, "{} frames drawn while held", held.len());
    for (frame, layers) in held.iter().enumerate().skip(1) {
        anyhow::ensure!(
            layers.iter().all(|l| *l == LayerCache::Kept),
            "frame {frame} while held redrew its layers: {layers:?}"
        );
    }
    let (before, after) = (view(&load(&shot("held"))?), view(&load(&shot("moved"))?));
    let moved = changed_pixels(&before, &after);
    println!("pixels changed by moving the sphere: {moved} of {pixels}");
    anyhow::ensure!(moved * 500 > pixels, "moving the sphere changed only {moved} of {pixels} pixels");

    check_saved_view(&dir.join("view.toml"))?;
    if std::env::var_os("GNOMON_TEST_KEEP").is_none() {
        std::fs::remove_dir_all(&dir)?;
    }
    Ok(())
}

/// The saved scene file holds the view: the technique, the sun and the camera.
fn check_saved_view(path: &Path) -> anyhow::Result<()> {
    let saved = gnomon_scene::scene_file::load(path, None)?;
    let table = saved.settings.expect("settings in the saved file");
    let reloaded =
        gnomon_scene::scene_file::merge_settings(&table, &Settings::default()).map_err(anyhow::Error::msg)?;
    anyhow::ensure!(reloaded.shadow.filter.technique == Technique::PCSS);
    anyhow::ensure!(reloaded.light.sun_angular_diameter == Some(6.0));
    anyhow::ensure!(reloaded.camera.eye.is_some() && reloaded.camera.target.is_some(), "no camera saved");
    Ok(())
}

fn load(path: &Path) -> anyhow::Result<image::RgbaImage> {
    Ok(image::open(PathBuf::from(path))?.to_rgba8())
}

fn luminance_spread(image: &image::RgbaImage) -> f64 {
    let values: Vec<f64> =
        image.pixels().map(|p| 0.2126 * p[0] as f64 + 0.7152 * p[1] as f64 + 0.0722 * p[2] as f64).collect();
    let mean = values.iter().sum::<f64>() / values.len() as f64;
    (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / values.len() as f64).sqrt()
}

/// Pixels whose colour moved by more than 12 levels in some channel.
fn changed_pixels(a: &image::RgbaImage, b: &image::RgbaImage) -> usize {
    assert_eq!(a.dimensions(), b.dimensions());
    a.pixels().zip(b.pixels()).filter(|(p, q)| (0..3).any(|c| (p[c] as i32 - q[c] as i32).abs() > 12)).count()
}
