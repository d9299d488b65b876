//! The fuzz targets: each takes bytes, runs them as far as Gnomon goes without a GPU,
//! and returns the kind of outcome. A panic escaping a target is a bug; an error of
//! any kind is the right answer to a bad input.

use std::path::Path;

use gnomon_scene::{Settings, gltf_loader, scene_file};

use crate::mutate::Hints;

/// A valid glTF that fuzzed scene files can name as a model (`file = "box.gltf"`).
const BOX_GLTF: &[u8] = include_bytes!("../../../examples/data/box-on-ground.gltf");

/// One fuzz target.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Target {
    /// A scene file's text: parsed, its models loaded, its lights and views checked,
    /// its `[settings]` laid over the defaults, checked, and resolved into lights and
    /// a camera.
    SceneFile,
    /// A `.glb` or `.gltf` file's bytes: loaded into a scene, validated, and resolved
    /// into the lights and camera a frame would use.
    Gltf,
    /// A command line, one argument per line: parsed by the settings' flags (the
    /// same definition `gnomon render` uses), checked, and any error put in flags.
    Flags,
}

impl Target {
    /// Every target, in the order runs report them.
    pub const ALL: [Target; 3] = [Target::SceneFile, Target::Gltf, Target::Flags];

    /// The target's name on the command line and in file names.
    pub fn name(self) -> &'static str {
        match self {
            Target::SceneFile => "scene-file",
            Target::Gltf => "gltf",
            Target::Flags => "flags",
        }
    }

    /// The target called `name`.
    pub fn named(name: &str) -> Option<Target> {
        Target::ALL.into_iter().find(|t| t.name() == name)
    }

    /// Seeds that every run starts from besides the files it is given: the shapes a
    /// valid input takes.
    pub fn builtin_seeds(self) -> Vec<Vec<u8>> {
        let texts: &[&str] = match self {
            Target::SceneFile => &[
                "builtin = \"columns\"\n[sun]\nelevation = 40.0\nazimuth = 200.0\nangular_diameter = 0.5\n",
                "ground = true\n[[model]]\nfile = \"box.gltf\"\n[spot]\nposition = [2.0, 6.0, 1.0]\ntarget = [0.0, 0.0, 0.0]\nouter_angle = 40.0\nrange = 30.0\nradius = 0.1\n",
                "builtin = \"lamps\"\n[[light]]\nname = \"lamp\"\ntype = \"point\"\nposition = [1.0, 2.0, 0.0]\nrange = 12.0\ncolor = [1.0, 0.8, 0.6]\n[light.shadow]\nfilter.technique = \"pcss\"\nmap.resolution = 512\n",
                "builtin = \"spheres\"\n[[view]]\nname = \"front\"\neye = [0.0, 3.0, 9.0]\ntarget = [0.0, 1.5, 0.0]\nfov = 45.0\nnear = 0.1\nfar = 100.0\n[settings.shadow.filter]\ntechnique = \"pcf\"\npcf_kernel = 3.0\n[settings.shadow]\npartition = \"cascades\"\n[settings.shadow.cascades]\ncount = 4\n",
            ],
            Target::Gltf => return vec![BOX_GLTF.to_vec()],
            Target::Flags => &[
                "--technique\npcf\n--pcf-kernel\n5\n--light\nspot\n--spot-outer-angle\n30",
                "--sun-elevation\n40\n--sun-azimuth\n-56\n--camera-target\n-5,5,0\n--fov\n60",
                "--partition\ncascades\n--cascades\n4\n--sdsm\n--depth-bias\n-3\n--slope-bias\n2\n--normal-offset\n0.5",
                "--light\nall\n--light-index\n2\n--refine\nrays\n--shadow-path\nmask\n--width\n640\n--height\n360",
            ],
        };
        let mut seeds: Vec<Vec<u8>> = texts.iter().map(|t| t.as_bytes().to_vec()).collect();
        if self == Target::Flags {
            // Each ranged setting at both ends, for the mutator to step past them.
            for (flag, range) in ranged_flags() {
                for end in [range.min, range.max] {
                    seeds.push(format!("--{flag}\n{end}").into_bytes());
                }
            }
        }
        seeds
    }

    /// Text the mutator inserts whole: the format's keys and punctuation.
    pub fn mutation_hints(self) -> Hints {
        match self {
            Target::SceneFile => &[
                "[sun]\n",
                "[spot]\n",
                "[point]\n",
                "[[light]]\n",
                "[[view]]\n",
                "[[model]]\n",
                "[settings]\n",
                "[light.shadow]\n",
                "type = \"spot\"\n",
                "builtin = \"lamps\"\n",
                "file = \"box.gltf\"\n",
                "elevation = ",
                "inner_angle = ",
                "color = [",
                "fov = ",
                "near = ",
                "range = ",
                "radius = ",
                "resolution = ",
                "technique = \"pcss\"\n",
                "= [1, 2, 3]\n",
                "\"\"\"",
                "]]\n",
            ],
            Target::Gltf => &[
                "\"count\": ",
                "\"byteLength\": ",
                "\"byteOffset\": ",
                "\"mode\": ",
                "\"matrix\": [0,0,0,0,0,0,0,0,0,0,0,0,0,0,0,0]",
                "\"indices\": ",
                "\"extensionsRequired\": [\"X\"],",
                "\"KHR_lights_punctual\"",
                "\"componentType\": 5125",
                "\"type\": \"VEC3\"",
                "\"children\": [0]",
                "{}",
                "[]",
                "null",
            ],
            Target::Flags => &[
                "--technique\n",
                "--light\n",
                "all\n",
                "--shadow-res\n",
                "--cascades\n",
                "--fov\n",
                "--camera-eye\n",
                "--refine\n",
                "--partition\n",
                "--warp\n",
                "lispsm\n",
                "--omni\n",
                "paraboloid\n",
                "--help\n",
                "=",
                ",",
                "\n",
                "--",
            ],
        }
    }

    /// Runs the target on `input`, using `workdir` for the files it must write.
    /// Returns a short name for the outcome: `ok`, or the first words of the error
    /// with its numbers blanked, so that inputs failing the same way count once.
    pub fn run(self, input: &[u8], workdir: &Path) -> String {
        let result = match self {
            Target::SceneFile => scene_file_target(input, workdir),
            Target::Gltf => gltf_target(input, workdir),
            Target::Flags => flags_target(input),
        };
        match result {
            Ok(()) => "ok".into(),
            Err(e) => outcome_kind(&e),
        }
    }
}

fn scene_file_target(input: &[u8], workdir: &Path) -> Result<(), String> {
    let model = workdir.join("box.gltf");
    if !model.exists() {
        std::fs::write(&model, BOX_GLTF).map_err(|e| e.to_string())?;
    }
    let path = workdir.join("scene.toml");
    std::fs::write(&path, input).map_err(|e| e.to_string())?;
    let loaded = scene_file::load(&path, None).map_err(|e| e.problem)?;
    let settings = match &loaded.settings {
        Some(table) => scene_file::merge_settings(table, &Settings::default())?,
        None => Settings::default(),
    };
    resolve(&settings, &loaded.scene)
}

fn gltf_target(input: &[u8], workdir: &Path) -> Result<(), String> {
    let name = if input.starts_with(b"glTF") { "m.glb" } else { "m.gltf" };
    let path = workdir.join(name);
    std::fs::write(&path, input).map_err(|e| e.to_string())?;
    let (scene, _) = gltf_loader::load(&path).map_err(|e| e.problem)?;
    scene.validate().map_err(|e| e.to_string())?;
    let _ = gnomon_scene::framing::default_camera(&scene);
    resolve(&Settings::default(), &scene)
}

/// What a frame would do first with a scene and settings: check them, and resolve
/// its camera and lights (each light's own settings laid over the render's).
fn resolve(settings: &Settings, scene: &gnomon_scene::Scene) -> Result<(), String> {
    settings.validate().map_err(|e| e.to_string())?;
    settings.resolve_camera(scene).map_err(|e| e.to_string())?;
    let techniques = gnomon_render::techniques::TechniqueRegistry::builtin();
    let lights = techniques.resolve_lights(settings, scene).map_err(|e| e.to_string())?;
    settings.uses_shadow_mask(&lights).map_err(|e| e.to_string())?;
    let _ = settings.unused(&lights);
    Ok(())
}

/// Every setting with a fixed range ([`gnomon_scene::settings::ranges::ALL`]) whose
/// ends are valid, with its flag's long name.
fn ranged_flags() -> Vec<(String, &'static gnomon_scene::settings::ranges::SettingRange)> {
    use clap::Args as _;
    let command = Settings::augment_args(clap::Command::new("gnomon"));
    gnomon_scene::settings::ranges::ALL
        .iter()
        .filter(|r| !r.min_open && !r.max_open)
        .filter_map(|r| {
            let flag = command.get_arguments().find(|a| a.get_id() == r.field())?.get_long()?.to_string();
            Some((flag, *r))
        })
        .collect()
}

fn flags_target(input: &[u8]) -> Result<(), String> {
    use clap::{Args as _, FromArgMatches as _};
    let text = String::from_utf8_lossy(input);
    let arguments = std::iter::once("gnomon").chain(text.split(['\n', '\0']).filter(|a| !a.is_empty()));
    let techniques = gnomon_render::techniques::TechniqueRegistry::builtin();
    let command = Settings::augment_args(clap::Command::new("gnomon"));
    let command = gnomon_scene::settings::settings_command(command, &techniques.choices());
    let command = gnomon_scene::settings::accept_negative_values(command);
    let matches = command.try_get_matches_from(arguments).map_err(|e| e.kind().to_string())?;
    let settings = Settings::from_arg_matches(&matches).map_err(|e| e.to_string())?;
    settings.validate().map_err(|e| gnomon_scene::settings::in_flags(&e.to_string()))?;
    toml::to_string(&settings).map_err(|e| e.to_string())?;
    Ok(())
}

/// The kind of `error`: its first five plain words, leaving out paths, quoted or
/// backticked text and numbers, so that inputs failing the same way count once
/// whatever names and values they held.
fn outcome_kind(error: &str) -> String {
    let plain = |w: &&str| !w.chars().any(|c| "/`\"'".contains(c) || c.is_ascii_digit());
    let words: Vec<&str> = error.split_whitespace().filter(plain).take(5).collect();
    words.join(" ")
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A range declared once is what the flags accept: both ends of every fixed
    /// range pass (the seeds above), and a value past either end is refused with the
    /// flag named.
    #[test]
    fn every_flag_with_a_range_refuses_a_value_past_it() {
        let ranged = ranged_flags();
        assert!(ranged.len() >= 20, "{} ranged flags", ranged.len());
        for (flag, range) in ranged {
            for past in [range.min - range.min.abs().max(1.0), range.max + range.max.abs().max(1.0)] {
                let input = format!("--{flag}\n{past}");
                let outcome = flags_target(input.as_bytes());
                let error = outcome.expect_err(&input);
                // Refused by the check, or by the flag's type (a negative count).
                assert!(error.contains("invalid"), "{input}: {error}");
            }
        }
        assert_eq!(
            flags_target(b"--max-radius\n65").unwrap_err(),
            "--max-radius = 65 is invalid: 1 to 64 texels"
        );
    }

    #[test]
    fn every_builtin_seed_is_a_valid_input() {
        let dir = tempfile::tempdir().unwrap();
        for target in Target::ALL {
            for seed in target.builtin_seeds() {
                assert_eq!(
                    target.run(&seed, dir.path()),
                    "ok",
                    "{target:?}: {}",
                    String::from_utf8_lossy(&seed)
                );
            }
        }
    }

    /// The inputs fuzzing found that once broke a target, kept as regressions: each
    /// must now give an error or a result with no panic at all, not even one that
    /// Gnomon catches (its message would still reach the user's terminal).
    #[test]
    fn every_kept_regression_input_runs_without_a_panic() {
        use std::sync::atomic::{AtomicUsize, Ordering};
        static PANICS: AtomicUsize = AtomicUsize::new(0);
        let dir = tempfile::tempdir().unwrap();
        let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("regressions");
        let mut tried = 0;
        for target in Target::ALL {
            for file in crate::files_under(&root.join(target.name())) {
                let input = std::fs::read(&file).unwrap();
                let default = std::panic::take_hook();
                std::panic::set_hook(Box::new(|_| {
                    PANICS.fetch_add(1, Ordering::Relaxed);
                }));
                let before = PANICS.load(Ordering::Relaxed);
                let outcome = std::panic::catch_unwind(|| target.run(&input, dir.path()));
                let panicked = PANICS.load(Ordering::Relaxed) > before;
                std::panic::set_hook(default);
                assert!(outcome.is_ok() && !panicked, "{} panics", file.display());
                tried += 1;
            }
        }
        assert!(tried >= 4, "the regressions are where this test looks: {tried} found");
    }

    /// Issue 49's hostile files (the glTF target's seeds): each is refused with an
    /// error, at once, without a panic, and without allocating what it declares (run
    /// in this process with no memory cap, a file that did would abort the test).
    #[test]
    fn every_hostile_seed_is_refused_at_once() {
        let dir = tempfile::tempdir().unwrap();
        let seeds = crate::files_under(&Path::new(env!("CARGO_MANIFEST_DIR")).join("seeds/gltf"));
        let files: Vec<_> = seeds.iter().filter(|p| p.extension().is_some_and(|e| e == "gltf")).collect();
        assert!(files.len() >= 14, "{files:?}");
        for file in files {
            let started = std::time::Instant::now();
            let outcome = Target::Gltf.run(&std::fs::read(file).unwrap(), dir.path());
            assert_ne!(outcome, "ok", "{} was accepted", file.display());
            assert!(started.elapsed().as_secs() < 5, "{}: {:?}", file.display(), started.elapsed());
        }
    }
}
