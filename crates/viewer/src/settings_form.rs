//! The settings panel's model, generated from the same clap definition as the CLI's
//! flags: one [`Field`] per flag of [`Settings`], with its help text, kind and
//! choices, and a way to read a field as flag text and to change it by re-parsing the
//! whole flag list through clap. The panel, the "copy as CLI command" button and the
//! viewer's automated tests all edit settings through [`SettingsForm::set`], so an
//! edit in the window is exactly what the same flag does on the command line.

use std::any::TypeId;
use std::collections::BTreeMap;

use clap::{ArgAction, Args, FromArgMatches};
use gnomon_scene::Settings;

/// What kind of value a field takes, which decides its widget.
#[derive(Clone, Debug, PartialEq)]
pub enum FieldKind {
    /// One of a fixed list: (value, help) pairs.
    Choice(Vec<(String, String)>),
    /// A flag that is on when present (`--contact-shadows`).
    Flag,
    /// `--name true|false`.
    Bool,
    Integer,
    Float,
    /// Anything else (X,Y,Z vectors): edited as text.
    Text,
}

/// One flag of [`Settings`].
#[derive(Clone, Debug)]
pub struct Field {
    /// clap's id, which is also the field's name in the settings' TOML.
    pub id: String,
    /// The long flag, without the dashes.
    pub long: String,
    /// The `--help` heading it is listed under (the panel's section).
    pub heading: String,
    /// The help text, for the tooltip.
    pub help: String,
    /// The value's placeholder in `--help` (`DISTANCE`, `X,Y,Z`).
    pub value_name: Option<String>,
    pub kind: FieldKind,
    /// The flag has no default: left unset, the scene decides.
    pub optional: bool,
    /// The valid values of a number with a fixed range, which bound its drag value.
    pub range: Option<&'static gnomon_scene::settings::ranges::SettingRange>,
}

/// Every flag of [`Settings`], in `--help` order.
pub struct SettingsForm {
    fields: Vec<Field>,
}

/// The settings' flags, with the built-in techniques as `--technique`'s choices.
fn settings_command() -> clap::Command {
    let command = Settings::augment_args(clap::Command::new("gnomon").no_binary_name(true));
    let techniques = gnomon_render::techniques::TechniqueRegistry::builtin();
    gnomon_scene::settings::settings_command(command, &techniques.choices())
}

impl Default for SettingsForm {
    fn default() -> Self {
        Self::new()
    }
}

impl SettingsForm {
    pub fn new() -> Self {
        let command = settings_command();
        let fields = command
            .get_arguments()
            .filter(|a| !a.is_positional() && a.get_long().is_some())
            .map(|arg| {
                let parser = arg.get_value_parser().type_id();
                let possible = arg.get_possible_values();
                let kind = match arg.get_action() {
                    ArgAction::SetTrue => FieldKind::Flag,
                    _ if parser == TypeId::of::<bool>() => FieldKind::Bool,
                    _ if !possible.is_empty() => FieldKind::Choice(
                        possible
                            .iter()
                            .filter(|v| !v.is_hide_set())
                            .map(|v| {
                                (
                                    v.get_name().to_string(),
                                    v.get_help().map(|h| h.to_string()).unwrap_or_default(),
                                )
                            })
                            .collect(),
                    ),
                    _ if [
                        TypeId::of::<u32>(),
                        TypeId::of::<usize>(),
                        TypeId::of::<u64>(),
                        TypeId::of::<i32>(),
                        TypeId::of::<i64>(),
                    ]
                    .iter()
                    .any(|t| parser == *t) =>
                    {
                        FieldKind::Integer
                    }
                    _ if parser == TypeId::of::<f32>() || parser == TypeId::of::<f64>() => FieldKind::Float,
                    _ => FieldKind::Text,
                };
                Field {
                    id: arg.get_id().to_string(),
                    long: arg.get_long().unwrap_or_default().to_string(),
                    heading: arg.get_help_heading().unwrap_or("Other").to_string(),
                    help: arg.get_long_help().or(arg.get_help()).map(|h| h.to_string()).unwrap_or_default(),
                    value_name: arg.get_value_names().and_then(|v| v.first()).map(|v| v.to_string()),
                    kind,
                    optional: arg.get_default_values().is_empty()
                        && !matches!(arg.get_action(), ArgAction::SetTrue),
                    range: gnomon_scene::settings::ranges::of_field(arg.get_id().as_str()),
                }
            })
            .collect();
        Self { fields }
    }

    pub fn fields(&self) -> &[Field] {
        &self.fields
    }

    pub fn field(&self, id: &str) -> Option<&Field> {
        self.fields.iter().find(|f| f.id == id)
    }

    /// Every field's value as it would be written after its flag; a field missing
    /// from the map is unset (the scene decides), and a [`FieldKind::Flag`] is
    /// "true" or "false".
    pub fn values(&self, settings: &Settings) -> BTreeMap<String, String> {
        let mut leaves = BTreeMap::new();
        if let Ok(tree) = toml::Value::try_from(settings) {
            collect_leaves(&tree, &mut leaves);
        }
        self.fields.iter().filter_map(|f| leaves.remove(&f.id).map(|v| (f.id.clone(), v))).collect()
    }

    /// `settings` with field `id` set to `value` (flag text, as on the command line;
    /// `None` unsets an optional field), parsed and checked exactly as the command line
    /// is. The error names the flag and what is valid.
    pub fn set(&self, settings: &Settings, id: &str, value: Option<&str>) -> Result<Settings, String> {
        let field = self.field(id).ok_or_else(|| format!("no setting `{id}`"))?;
        let mut values = self.values(settings);
        match value {
            Some(v) => values.insert(id.to_string(), v.trim().to_string()),
            None if field.optional => values.remove(id),
            None => return Err(format!("--{} needs a value", field.long)),
        };
        let parsed = self.parse(&values)?;
        // The panel speaks in flags, as the command line does.
        parsed.validate().map_err(|e| gnomon_scene::settings::in_flags(&e.to_string()))?;
        Ok(parsed)
    }

    /// The command-line flags that turn `baseline`'s settings into `settings`'s.
    pub fn flags(&self, settings: &Settings, baseline: &Settings) -> Vec<String> {
        let (now, before) = (self.values(settings), self.values(baseline));
        self.fields
            .iter()
            .filter(|f| now.get(&f.id) != before.get(&f.id))
            .filter_map(|f| match (&f.kind, now.get(&f.id)) {
                (FieldKind::Flag, Some(v)) if v == "true" => Some(vec![format!("--{}", f.long)]),
                (FieldKind::Flag, _) | (_, None) => None,
                (_, Some(v)) => Some(vec![format!("--{}", f.long), v.clone()]),
            })
            .flatten()
            .collect()
    }

    /// Parses a complete set of field values through clap.
    fn parse(&self, values: &BTreeMap<String, String>) -> Result<Settings, String> {
        let mut argv = Vec::new();
        for field in &self.fields {
            match (&field.kind, values.get(&field.id)) {
                (FieldKind::Flag, Some(v)) if v == "true" => argv.push(format!("--{}", field.long)),
                (FieldKind::Flag, _) | (_, None) => {}
                (_, Some(v)) => argv.push(format!("--{}={v}", field.long)),
            }
        }
        let matches = settings_command().try_get_matches_from(argv).map_err(|e| {
            // clap's message without its usage lines: what was wrong and what is valid.
            let text = e.to_string();
            text.lines()
                .map(str::trim)
                .filter(|l| {
                    !l.is_empty() && !l.starts_with("Usage:") && !l.starts_with("For more information")
                })
                .collect::<Vec<_>>()
                .join(" ")
                .trim_start_matches("error: ")
                .to_string()
        })?;
        Settings::from_arg_matches(&matches).map_err(|e| e.to_string())
    }
}

/// Every leaf of a TOML tree, keyed by its own name, written as flag text.
fn collect_leaves(value: &toml::Value, into: &mut BTreeMap<String, String>) {
    if let toml::Value::Table(table) = value {
        for (key, v) in table {
            match v {
                toml::Value::Table(_) => collect_leaves(v, into),
                leaf => {
                    if let Some(text) = flag_text(leaf) {
                        into.insert(key.clone(), text);
                    }
                }
            }
        }
    }
}

/// A TOML value as it is written after a flag: numbers in their shortest form (the
/// settings are `f32`, so `0.3` and not `0.30000001192092896`), vectors as X,Y,Z.
fn flag_text(value: &toml::Value) -> Option<String> {
    Some(match value {
        toml::Value::String(s) => s.clone(),
        toml::Value::Integer(i) => i.to_string(),
        toml::Value::Float(f) => (*f as f32).to_string(),
        toml::Value::Boolean(b) => b.to_string(),
        toml::Value::Array(items) => items.iter().map(flag_text).collect::<Option<Vec<_>>>()?.join(","),
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use gnomon_scene::settings::{DebugView, Technique};

    use super::*;

    /// Every flag maps to exactly one field of the settings' TOML, and setting it to
    /// some other valid value changes that field and nothing else.
    #[test]
    fn every_flag_reads_and_writes_its_own_setting() {
        let form = SettingsForm::new();
        assert!(form.fields().len() > 40, "only {} fields", form.fields().len());
        let base = Settings::default();
        let before = form.values(&base);
        for field in form.fields() {
            let other = match &field.kind {
                FieldKind::Choice(choices) => {
                    choices.iter().map(|(v, _)| v.clone()).find(|v| before.get(&field.id) != Some(v))
                }
                FieldKind::Flag | FieldKind::Bool => Some(
                    if before.get(&field.id).map(String::as_str) == Some("true") { "false" } else { "true" }
                        .into(),
                ),
                FieldKind::Integer | FieldKind::Float => None,
                FieldKind::Text => None,
            };
            let Some(other) = other else { continue };
            // Some values are valid only with others (a technique's companions); a
            // refusal must then name the flag's own value or another flag.
            match form.set(&base, &field.id, Some(&other)) {
                Ok(changed) => {
                    let after = form.values(&changed);
                    assert_eq!(after.get(&field.id), Some(&other), "--{}", field.long);
                    let differing: Vec<_> = after
                        .iter()
                        .filter(|(k, v)| before.get(*k) != Some(v))
                        .map(|(k, _)| k.clone())
                        .collect();
                    assert_eq!(differing, vec![field.id.clone()], "--{} {other}", field.long);
                }
                Err(e) => assert!(e.contains("--"), "--{} {other}: unhelpful error {e:?}", field.long),
            }
        }
    }

    #[test]
    fn numbers_and_vectors_round_trip_through_flag_text() {
        let form = SettingsForm::new();
        let base = Settings::default();
        let s = form.set(&base, "slope_bias", Some("0.3")).unwrap();
        assert_eq!(s.shadow.bias.slope_bias, 0.3);
        assert_eq!(form.values(&s)["slope_bias"], "0.3");
        let s = form.set(&s, "eye", Some("1,2.5,-3")).unwrap();
        assert_eq!(s.camera.eye, Some(glam::Vec3::new(1.0, 2.5, -3.0)));
        let s = form.set(&s, "technique", Some("pcss")).unwrap();
        assert_eq!(s.shadow.filter.technique, Technique::PCSS);
        let s = form.set(&s, "debug_view", Some("cascades")).unwrap();
        assert_eq!(s.image.debug_view, DebugView::Cascades);
        // Unsetting an optional field gives it back to the scene.
        let s = form.set(&s, "eye", None).unwrap();
        assert_eq!(s.camera.eye, None);
        // The flags rebuild the same settings from the defaults.
        let flags = form.flags(&s, &base);
        assert!(flags.contains(&"--technique".to_string()), "{flags:?}");
        let command = settings_command();
        let rebuilt = Settings::from_arg_matches(&command.try_get_matches_from(&flags).unwrap()).unwrap();
        assert_eq!(rebuilt, s);
    }

    #[test]
    fn invalid_values_are_refused_with_the_flag_named() {
        let form = SettingsForm::new();
        let base = Settings::default();
        let e = form.set(&base, "technique", Some("blurry")).unwrap_err();
        assert!(e.contains("--technique") && e.contains("pcss"), "{e}");
        let e = form.set(&base, "resolution", Some("-4")).unwrap_err();
        assert!(e.contains("--shadow-res"), "{e}");
        let e = form.set(&base, "eye", Some("1,2")).unwrap_err();
        assert!(e.contains("--camera-eye") && e.contains("X,Y,Z"), "{e}");
        assert!(form.set(&base, "no_such_setting", Some("1")).is_err());
    }

    #[test]
    fn every_field_explains_itself() {
        for field in SettingsForm::new().fields() {
            assert!(field.help.len() > 10, "--{} has no tooltip", field.long);
        }
    }

    /// The settings' declared ranges reach the panel: the drag value's bounds and the
    /// tooltip's words are the checks' own.
    #[test]
    fn every_ranged_number_is_bounded_by_its_declared_range() {
        let form = SettingsForm::new();
        let mut bounded = 0;
        for range in gnomon_scene::settings::ranges::ALL {
            let Some(field) = form.field(range.field()) else { continue };
            assert_eq!(field.range.map(|r| r.setting), Some(range.setting), "--{}", field.long);
            assert!(field.help.contains(&range.describe()), "--{}: {}", field.long, field.help);
            bounded += 1;
        }
        assert!(bounded >= 20, "{bounded} bounded fields");
    }
}
