//! The valid range and unit of every numeric setting whose range is fixed, each
//! declared once as a [`SettingRange`] constant beside its field's struct. The
//! settings' checks test values against it and word their errors from it; `--help`
//! prints it after the field's help ([`annotate_ranges`]); the viewer bounds its
//! drag values by it; the flags fuzzer inserts its ends and the values just past
//! them. [`ALL`] lists them for those readers. (Ranges that depend on another
//! setting, such as a PCF kernel in world units or a technique's 16-bit exponents,
//! are checked where that setting is read.)

use super::SettingsError;

/// A numeric setting's valid values: a closed or half-open interval of finite
/// numbers, and its unit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SettingRange {
    /// The setting's path in scene files (`shadow.filter.pcss.max_radius`): the name
    /// its errors use, and whose last segment is its flag's id.
    pub setting: &'static str,
    /// The least valid value (excluded when `min_open`).
    pub min: f64,
    /// Whether `min` itself is invalid.
    pub min_open: bool,
    /// The largest valid value (excluded when `max_open`).
    pub max: f64,
    /// Whether `max` itself is invalid.
    pub max_open: bool,
    /// The unit, after the numbers ("texels"); empty for a plain number.
    pub unit: &'static str,
}

impl SettingRange {
    /// `[min, max]`.
    pub const fn closed(setting: &'static str, min: f64, max: f64, unit: &'static str) -> Self {
        SettingRange { setting, min, min_open: false, max, max_open: false, unit }
    }

    /// `(min, max]`: above `min`.
    pub const fn above(setting: &'static str, min: f64, max: f64, unit: &'static str) -> Self {
        SettingRange { setting, min, min_open: true, max, max_open: false, unit }
    }

    /// `[min, max)`: below `max`.
    pub const fn below(setting: &'static str, min: f64, max: f64, unit: &'static str) -> Self {
        SettingRange { setting, min, min_open: false, max, max_open: true, unit }
    }

    /// The field's name: the path's last segment, its flag's id.
    pub fn field(&self) -> &'static str {
        self.setting.rsplit('.').next().unwrap_or(self.setting)
    }

    /// Whether `x` is finite and inside, compared in `x`'s own type: an `f32`
    /// setting of 0.1 is at the end of a range declared to 0.1, though
    /// `0.1f32 as f64` is above `0.1f64`.
    pub fn allows<T: RangeValue>(&self, x: T) -> bool {
        x.within(self)
    }

    /// Whether `x` is inside, at `f64` precision.
    fn allows_f64(&self, x: f64) -> bool {
        let above = if self.min_open { x > self.min } else { x >= self.min };
        let below = if self.max_open { x < self.max } else { x <= self.max };
        x.is_finite() && above && below
    }

    /// What is valid, in words: "1 to 64 texels", or "in (0, 100]" for an open end.
    pub fn describe(&self) -> String {
        let unit = if self.unit.is_empty() { String::new() } else { format!(" {}", self.unit) };
        if self.min_open || self.max_open {
            let open = if self.min_open { '(' } else { '[' };
            let close = if self.max_open { ')' } else { ']' };
            format!("in {open}{}, {}{close}{unit}", self.min, self.max)
        } else {
            format!("{} to {}{unit}", self.min, self.max)
        }
    }

    /// `value` against the range: an error naming the setting, the value and the range.
    pub fn check<T: RangeValue>(&self, value: T) -> Result<(), SettingsError> {
        if self.allows(value) {
            Ok(())
        } else {
            Err(SettingsError { setting: self.setting, value: value.shown(), valid: self.describe() })
        }
    }
}

/// A setting's number type, compared with a range in its own precision.
pub trait RangeValue: Copy + ToString {
    /// Whether `self` lies in `range`.
    fn within(self, range: &SettingRange) -> bool;
    /// `self` as an error shows it.
    fn shown(self) -> String {
        self.to_string()
    }
}

impl RangeValue for f32 {
    fn shown(self) -> String {
        crate::limits::shown(self)
    }

    fn within(self, r: &SettingRange) -> bool {
        let (min, max) = (r.min as f32, r.max as f32);
        let above = if r.min_open { self > min } else { self >= min };
        let below = if r.max_open { self < max } else { self <= max };
        self.is_finite() && above && below
    }
}

impl RangeValue for f64 {
    fn within(self, r: &SettingRange) -> bool {
        r.allows_f64(self)
    }
}

impl RangeValue for u32 {
    fn within(self, r: &SettingRange) -> bool {
        r.allows_f64(self.into())
    }
}

impl RangeValue for i32 {
    fn within(self, r: &SettingRange) -> bool {
        r.allows_f64(self.into())
    }
}

/// Every fixed range, in the order of the settings' tables.
pub static ALL: &[&SettingRange] = &[
    &super::WIDTH_RANGE,
    &super::HEIGHT_RANGE,
    &super::PCF_KERNEL_TEXELS_RANGE,
    &super::POISSON_SAMPLES_RANGE,
    &super::BLOCKER_SAMPLES_RANGE,
    &super::PCSS_MAX_RADIUS_RANGE,
    &super::PCSS_MAX_PENUMBRA_RANGE,
    &super::BLUR_RADIUS_RANGE,
    &super::MIN_VARIANCE_RANGE,
    &super::BLEEDING_REDUCTION_RANGE,
    &super::ESM_EXPONENT_RANGE,
    &super::EVSM_POSITIVE_RANGE,
    &super::EVSM_NEGATIVE_RANGE,
    &super::MOMENT_BIAS_RANGE,
    &super::CSM_TERMS_RANGE,
    &super::CSM_ATTENUATION_RANGE,
    &super::CSM_SCALE_RANGE,
    &super::CSM_OFFSET_RANGE,
    &super::RESOLUTION_RANGE,
    &super::POOL_SIDE_RANGE,
    &super::LOD_BIAS_RANGE,
    &super::EDGE_LEVELS_RANGE,
    &super::LEVEL_RESOLUTION_RANGE,
    &super::CASCADE_COUNT_RANGE,
    &super::SPLIT_LAMBDA_RANGE,
    &super::CASCADE_BLEND_RANGE,
    &super::DEPTH_BIAS_RANGE,
    &super::SLOPE_BIAS_RANGE,
    &super::NORMAL_OFFSET_RANGE,
    &super::CONTACT_LENGTH_RANGE,
    &super::CONTACT_STEPS_RANGE,
    &super::CONTACT_THICKNESS_RANGE,
    &super::PENUMBRA_RAYS_RANGE,
    &super::PENUMBRA_FRAMES_RANGE,
    &super::REFERENCE_SAMPLES_RANGE,
];

/// The range of the setting whose field (flag id) is `field`.
pub fn of_field(field: &str) -> Option<&'static SettingRange> {
    ALL.iter().copied().find(|r| r.field() == field)
}

/// `command` with each ranged flag's help ending in its range ("[1 to 64 texels]"),
/// so that `--help` says what the checks accept.
#[cfg(feature = "cli")]
pub fn annotate_ranges(command: clap::Command) -> clap::Command {
    let command = command.mut_args(|arg| match of_field(arg.get_id().as_str()) {
        Some(range) => {
            let valid = range.describe();
            let help = arg.get_help().map(|h| h.to_string()).unwrap_or_default();
            let long_help = arg.get_long_help().map(|h| format!("{h} [{valid}]"));
            let arg = arg.help(format!("{help} [{valid}]"));
            match long_help {
                Some(long) => arg.long_help(long),
                None => arg,
            }
        }
        None => arg,
    });
    command.mut_subcommands(annotate_ranges)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_range_allows_its_ends_unless_open_and_nothing_outside() {
        let closed = SettingRange::closed("a.b", 1.0, 64.0, "texels");
        assert!(closed.allows(1.0) && closed.allows(64.0) && closed.allows(3.5));
        assert!(!closed.allows(0.999) && !closed.allows(64.001) && !closed.allows(f64::NAN));
        // An f32 setting is compared in f32: 0.1f32 is the end of a range to 0.1.
        let tenth = SettingRange::closed("a.b", 0.0, 0.1, "");
        assert!(tenth.allows(0.1f32) && !tenth.allows(0.1f64 + 1e-9) && !tenth.allows(0.100001f32));
        assert!(SettingRange::closed("a.b", 0.0, 16777216.0, "").allows(16777216i32));
        assert!(!SettingRange::closed("a.b", 0.0, 16777216.0, "").allows(16777217i32));
        assert!(!closed.allows(f64::INFINITY));
        let above = SettingRange::above("a.b", 0.0, 100.0, "");
        assert!(!above.allows(0.0) && above.allows(1e-9) && above.allows(100.0));
        let below = SettingRange::below("a.b", 0.0, 1.0, "");
        assert!(below.allows(0.0) && !below.allows(1.0));
        assert_eq!(closed.describe(), "1 to 64 texels");
        assert_eq!(above.describe(), "in (0, 100]");
        assert_eq!(closed.field(), "b");
        let e = closed.check(65.0f32).unwrap_err();
        assert_eq!((e.setting, e.value.as_str(), e.valid.as_str()), ("a.b", "65", "1 to 64 texels"));
    }

    #[test]
    fn every_range_is_one_field_and_holds_its_default() {
        let defaults = toml::Table::try_from(super::super::Settings::default()).unwrap();
        for range in ALL {
            assert_eq!(ALL.iter().filter(|r| r.field() == range.field()).count(), 1, "{}", range.setting);
            assert!(range.min < range.max, "{}", range.setting);
            let mut value = &toml::Value::Table(defaults.clone());
            for segment in range.setting.split('.') {
                value = value.get(segment).unwrap_or_else(|| panic!("{} is not a setting", range.setting));
            }
            let x = value.as_float().or(value.as_integer().map(|i| i as f64)).expect(range.setting);
            assert!(range.allows(x), "{}'s default {x} is outside {}", range.setting, range.describe());
        }
    }
}
