//! Settings from the command line's flags, given as name and value pairs: a web
//! page's URL (`?technique=pcss&width=640`), the JS API's plain objects
//! (`{technique: "pcss", width: 640}`) and Python's keyword arguments all come here, so that each is parsed and
//! checked by the very definition the command line uses (clap's, derived on
//! [`Settings`]), and a wrong value gets the command line's error, word for word.

use crate::{Settings, settings};
use clap::{Args as _, FromArgMatches as _};

/// A flag and its value, as a page or a host gives it: the flag's long name without
/// its dashes (`technique`, `sun-elevation`) and its value in words (`pcss`, `30`,
/// `0,1,2`; `true` or `false` for a switch such as `ground`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Flag {
    /// The long name, without `--`.
    pub name: String,
    /// The value, as it would be typed.
    pub value: String,
}

/// Settings that could not be made from flags: the command line's message.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
#[error("{0}")]
pub struct FlagsError(pub String);

/// The command line's settings flags, with nothing else.
fn command() -> clap::Command {
    let command = clap::Command::new("gnomon").color(clap::ColorChoice::Never).disable_help_flag(true);
    settings::accept_negative_values(Settings::augment_args(command))
}

/// The settings `flags` give over the defaults, checked as the command line checks
/// them: parsed by clap, then [`Settings::validate`], whose message names the flag.
/// Whether a technique is registered is the renderer's to say
/// (`TechniqueRegistry::check`, which the front ends ask).
pub fn settings_from_flags(flags: &[Flag]) -> Result<Settings, FlagsError> {
    let command = command();
    let mut argv = vec!["gnomon".to_string()];
    for flag in flags {
        let Some(argument) = command.get_arguments().find(|a| a.get_long() == Some(flag.name.as_str()))
        else {
            return Err(FlagsError(format!(
                "unknown setting `{}`: give one of the command line's settings flags (`gnomon render --help`), \
                 without its dashes",
                flag.name
            )));
        };
        if argument.get_action().takes_values() {
            argv.push(format!("--{}={}", flag.name, flag.value));
        } else {
            match flag.value.as_str() {
                "true" | "" => argv.push(format!("--{}", flag.name)),
                "false" => {}
                other => {
                    return Err(FlagsError(format!(
                        "invalid value '{other}' for '--{}': it is a switch; give true or false",
                        flag.name
                    )));
                }
            }
        }
    }
    let matches = command.try_get_matches_from(argv).map_err(|e| FlagsError(clap_message(&e)))?;
    let settings = Settings::from_arg_matches(&matches).map_err(|e| FlagsError(clap_message(&e)))?;
    settings.validate().map_err(|e| FlagsError(settings::in_flags(&e.to_string())))?;
    Ok(settings)
}

/// clap's message without its usage and help lines, which speak of a terminal.
fn clap_message(error: &clap::Error) -> String {
    let rendered = error.render().to_string();
    let message: Vec<&str> = rendered
        .lines()
        .take_while(|line| !line.starts_with("Usage:") && !line.starts_with("For more information"))
        .filter(|line| !line.trim().is_empty())
        .collect();
    message.join("\n").trim_start_matches("error: ").to_string()
}

/// One settings flag, described for a page to build its control from.
#[derive(Clone, Debug, serde::Serialize, PartialEq, Eq)]
pub struct FlagInfo {
    /// The long name, without `--`.
    pub name: String,
    /// The group it is listed under in `gnomon render --help` (`Image`, `Shadow map`).
    pub heading: String,
    /// Its help, the first paragraph.
    pub help: String,
    /// The values it takes, where they are a list (`--technique`, `--light`).
    pub choices: Vec<String>,
    /// A switch, on or off (`--ground`), rather than a flag with a value.
    pub switch: bool,
    /// Its default, as `--help` shows it, if it has one.
    pub default: Option<String>,
}

/// Every settings flag, in `--help`'s order: what a page's settings panel is built
/// from, so that it offers exactly what the command line does.
pub fn describe() -> Vec<FlagInfo> {
    command()
        .get_arguments()
        .filter_map(|a| {
            let name = a.get_long()?.to_string();
            let choices = a.get_possible_values().iter().map(|v| v.get_name().to_string()).collect();
            let help = a.get_long_help().or(a.get_help()).map(|h| h.to_string()).unwrap_or_default();
            let default = a.get_default_values().first().map(|v| v.to_string_lossy().into_owned());
            Some(FlagInfo {
                name,
                heading: a.get_help_heading().unwrap_or("Settings").to_string(),
                help: help.split("\n\n").next().unwrap_or_default().to_string(),
                choices,
                switch: !a.get_action().takes_values(),
                default,
            })
        })
        .collect()
}

/// The value of a technique's name for a report: the settings' technique.
pub fn technique_name(settings: &Settings) -> String {
    settings.shadow.filter.technique.to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn flags(pairs: &[(&str, &str)]) -> Vec<Flag> {
        pairs.iter().map(|(n, v)| Flag { name: n.to_string(), value: v.to_string() }).collect()
    }

    #[test]
    fn flags_set_what_the_command_line_sets() {
        let s = settings_from_flags(&flags(&[
            ("technique", "pcss"),
            ("width", "640"),
            ("height", "360"),
            ("ground", "true"),
            ("light", "point"),
            ("camera-eye", "-1,2,3"),
        ]))
        .unwrap();
        assert_eq!(technique_name(&s), "pcss");
        assert_eq!((s.image.width, s.image.height), (640, 360));
        assert!(s.scene.ground);
        assert_eq!(s.camera.eye, Some(glam::Vec3::new(-1.0, 2.0, 3.0)));
        assert_eq!(settings_from_flags(&[]).unwrap(), Settings::default());
        assert!(!settings_from_flags(&flags(&[("ground", "false")])).unwrap().scene.ground);
    }

    /// The panel's description holds every flag the command line has, with its
    /// choices: a technique list, a light list, switches.
    #[test]
    fn describe_lists_the_command_lines_flags() {
        let all = describe();
        // A technique's name is free (a host registers its own): no list here.
        let technique = all.iter().find(|f| f.name == "technique").expect("--technique");
        assert_eq!(technique.default.as_deref(), Some("pcf2x2"));
        let partition = all.iter().find(|f| f.name == "partition").expect("--partition");
        assert!(partition.choices.iter().any(|c| c == "cascades"), "{partition:?}");
        let light = all.iter().find(|f| f.name == "light").expect("--light");
        assert_eq!(light.choices, ["sun", "spot", "point", "all"]);
        assert!(all.iter().find(|f| f.name == "ground").is_some_and(|f| f.switch));
        let width = all.iter().find(|f| f.name == "width").expect("--width");
        assert_eq!(width.default.as_deref(), Some("1280"));
        assert!(all.len() > 40, "{} flags", all.len());
    }

    /// Each wrong input is named with what is valid, as the command line names it.
    #[test]
    fn wrong_flags_get_the_command_lines_errors() {
        let e = settings_from_flags(&flags(&[("light", "moon")])).unwrap_err().0;
        assert!(e.contains("moon") && e.contains("--light") && e.contains("point"), "{e}");
        let e = settings_from_flags(&flags(&[("width", "0")])).unwrap_err().0;
        assert!(e.contains("--width") && e.contains("16384"), "{e}");
        let e = settings_from_flags(&flags(&[("widht", "10")])).unwrap_err().0;
        assert!(e.contains("unknown setting `widht`"), "{e}");
        let e = settings_from_flags(&flags(&[("ground", "maybe")])).unwrap_err().0;
        assert!(e.contains("--ground") && e.contains("true or false"), "{e}");
        assert!(!e.contains("Usage"), "{e}");
    }
}
