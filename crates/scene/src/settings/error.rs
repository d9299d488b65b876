//! The settings' error: the setting at fault, its value and what is valid, with the
//! range checks every group shares.

use super::*;

/// A setting outside its valid range. The message names the flag and what is valid.
#[derive(Debug, thiserror::Error, PartialEq)]
#[error("{flag} = {value} is invalid: {valid}")]
pub struct SettingsError {
    /// The setting at fault: its command-line flag (`--blur-radius`) or scene-file key.
    pub flag: &'static str,
    /// The value given, as text.
    pub value: String,
    /// What would be valid, in words (a range, or a condition on other settings).
    pub valid: String,
}

pub(super) fn check(
    ok: bool,
    flag: &'static str,
    value: impl ToString,
    valid: impl Into<String>,
) -> Result<(), SettingsError> {
    if ok { Ok(()) } else { Err(SettingsError { flag, value: value.to_string(), valid: valid.into() }) }
}

pub(super) fn check_opt(
    v: Option<f32>,
    flag: &'static str,
    ok: impl Fn(f32) -> bool,
    valid: &str,
) -> Result<(), SettingsError> {
    match v {
        Some(x) => check(x.is_finite() && ok(x), flag, x, valid),
        None => Ok(()),
    }
}

pub(super) fn check_vec(v: Option<Vec3>, flag: &'static str) -> Result<(), SettingsError> {
    match v {
        Some(p) => check(p.is_finite(), flag, format!("{},{},{}", p.x, p.y, p.z), "three finite numbers"),
        None => Ok(()),
    }
}
