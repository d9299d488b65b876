//! The settings' error: the setting at fault, its value and what is valid, with the
//! range checks every group shares.

use super::*;

/// A setting outside its valid range. The message names the setting as scene files
/// write it (`shadow.filter.moments.blur_radius`), never a command-line flag: the
/// `gnomon` binary maps each setting in it to the flag its user typed.
#[derive(Debug, thiserror::Error, PartialEq)]
#[error("`{setting}` = {value} is invalid: {valid}")]
pub struct SettingsError {
    /// The setting at fault: its path in the settings' TOML (`shadow.map.resolution`),
    /// or a scene file's table (`[light.shadow]`).
    pub setting: &'static str,
    /// The value given, as text.
    pub value: String,
    /// What would be valid, in words (a range, or a condition on other settings, each
    /// named in backticks by its path).
    pub valid: String,
}

/// A setting's value as scene files (and flags) write it: serde's name for a choice
/// (`lispsm`, `pcf-tent`), the number or the list otherwise.
pub fn value_name(value: &impl Serialize) -> String {
    match toml::Value::try_from(value) {
        Ok(toml::Value::String(name)) => name,
        Ok(other) => other.to_string(),
        Err(e) => format!("<{e}>"),
    }
}

pub(super) fn check(
    ok: bool,
    setting: &'static str,
    value: impl ToString,
    valid: impl Into<String>,
) -> Result<(), SettingsError> {
    if ok { Ok(()) } else { Err(SettingsError { setting, value: value.to_string(), valid: valid.into() }) }
}

/// An optional value against its [`crate::limits::Limit`].
pub(super) fn check_limit(
    v: Option<f32>,
    setting: &'static str,
    limit: &crate::limits::Limit,
) -> Result<(), SettingsError> {
    match v {
        Some(x) => check(limit.allows(x), setting, crate::limits::shown(x), limit.valid),
        None => Ok(()),
    }
}

/// An optional position: every coordinate within [`crate::limits::COORDINATE`].
pub(super) fn check_vec(v: Option<Vec3>, setting: &'static str) -> Result<(), SettingsError> {
    match v {
        Some(p) => {
            crate::limits::check_vec3(&crate::limits::COORDINATE, setting, p).map(|_| ()).map_err(|e| {
                SettingsError { setting, value: format!("{},{},{}", p.x, p.y, p.z), valid: e.valid }
            })
        }
        None => Ok(()),
    }
}

#[cfg(feature = "cli")]
/// The library names a setting by its path in scene files, in backticks
/// (`` `shadow.map.resolution` ``); on the command line it is the flag its user typed.
/// Rewrites every such path in `message` into its flag, through clap's definition of
/// the settings: an argument's id is its field's name, the path's last segment, and
/// the path's first segment is a group of [`Settings`].
pub fn in_flags(message: &str) -> String {
    use clap::Args as _;
    let command = Settings::augment_args(clap::Command::new("gnomon"));
    let groups = toml::Table::try_from(Settings::default()).unwrap_or_default();
    let flag_of_setting = |path: &str| -> Option<String> {
        let (group, field) = (path.split_once('.')?.0, path.rsplit('.').next()?);
        if !groups.contains_key(group) {
            return None;
        }
        let argument = command.get_arguments().find(|a| a.get_id() == field)?;
        argument.get_long().map(|long| format!("--{long}"))
    };
    let mut out = String::with_capacity(message.len());
    let mut rest = message;
    while let Some(start) = rest.find('`') {
        let Some(length) = rest[start + 1..].find('`') else { break };
        let token = &rest[start + 1..start + 1 + length];
        out.push_str(&rest[..start]);
        match flag_of_setting(token) {
            Some(flag) => out.push_str(&flag),
            None => out.push_str(&rest[start..start + 2 + length]),
        }
        rest = &rest[start + 2 + length..];
    }
    out.push_str(rest);
    out
}
