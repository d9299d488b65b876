//! `gnomon view`: the interactive viewer on a scene, with every setting live.

use std::path::PathBuf;

use clap::Args;
use gnomon_scene::Settings;
use gnomon_viewer::{SceneSource, ViewerOptions};

#[derive(Args, Debug)]
pub struct ViewArgs {
    #[command(flatten)]
    pub scene: crate::lab::SceneArgs,
    /// Close the window after this many frames (for automation; with --screenshot,
    /// the last frame is saved).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..), help_heading = "Viewer")]
    pub frames: Option<u32>,
    /// Save the window as a PNG after the last frame (--frames) or when it is closed.
    #[arg(long, value_name = "FILE.png", help_heading = "Viewer")]
    pub screenshot: Option<PathBuf>,
    /// Start with the panels hidden (F1 shows them).
    #[arg(long, help_heading = "Viewer")]
    pub hide_panels: bool,
    /// Start with the shadow-map preview open (every cascade or cube face, in grayscale).
    #[arg(long, help_heading = "Viewer")]
    pub shadow_maps: bool,
    /// The window's size in logical pixels, as WIDTHxHEIGHT.
    #[arg(long, value_name = "WxH", default_value = "1400x860", value_parser = parse_size, help_heading = "Viewer")]
    pub window: [u32; 2],
    #[command(flatten)]
    pub settings: Settings,
}

fn parse_size(text: &str) -> Result<[u32; 2], String> {
    let bad = || format!("expected WIDTHxHEIGHT with each from 64 to 16384, like 1400x860; got `{text}`");
    let (w, h) = text.split_once(['x', 'X']).ok_or_else(bad)?;
    let side = |s: &str| s.trim().parse::<u32>().ok().filter(|v| (64..=16384).contains(v));
    Ok([side(w).ok_or_else(bad)?, side(h).ok_or_else(bad)?])
}

pub fn run(args: &ViewArgs) -> anyhow::Result<()> {
    args.settings.validate()?;
    if let Some(p) = &args.screenshot {
        crate::output::check_file(p, &["png"], "--screenshot")?;
    }
    let (scene, settings) = crate::lab::load(&args.scene, &args.settings)?;
    // What the scene alone gives: "copy as CLI command" writes the flags beyond it.
    let (_, baseline) = crate::lab::load(&args.scene, &Settings::default())?;
    let source = SceneSource::from_argument(&args.scene.scene, args.scene.view.as_deref());
    let mut options = ViewerOptions::new(scene, settings, source);
    options.baseline = baseline;
    options.frames = args.frames;
    options.screenshot = args.screenshot.clone();
    options.hide_panel = args.hide_panels;
    options.show_maps = args.shadow_maps;
    options.window_size = args.window;
    let report = gnomon_viewer::run(options)?;
    for path in &report.screenshots {
        eprintln!("gnomon: wrote {}", path.display());
    }
    Ok(())
}
