//! Where a key of a scene file is: its line and column, from the TOML parser's spans,
//! so that an error about a value points at the text the user wrote.

use toml::de::{DeTable, DeValue};

/// One step of a path into a TOML document: a table's key, or an array's index (an
/// array of tables such as `[[light]]` included).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Step<'a> {
    /// A key of a table.
    Key(&'a str),
    /// An element of an array.
    Index(usize),
}

/// A path into a TOML document, e.g. `light[2].color` as
/// `[Key("light"), Index(2), Key("color")]`.
pub type KeyPath<'a> = [Step<'a>];

/// The path as scene files write it: `light[2].color`, `settings.shadow.map.resolution`.
pub fn display(path: &KeyPath) -> String {
    let mut out = String::new();
    for step in path {
        match step {
            Step::Key(key) => {
                if !out.is_empty() {
                    out.push('.');
                }
                out.push_str(key);
            }
            Step::Index(i) => out.push_str(&format!("[{i}]")),
        }
    }
    out
}

/// The 1-based line and column of the value at `path` in `text`, or of the deepest
/// table on the path that exists (a missing key is reported where it belongs).
/// `None` when the text does not parse or the path's first key is absent.
pub fn locate(text: &str, path: &KeyPath) -> Option<(usize, usize)> {
    let root = DeTable::parse(text).ok()?;
    let mut table = root.get_ref();
    let mut found = None;
    let mut steps = path.iter().peekable();
    let mut value: Option<&toml::Spanned<DeValue>> = None;
    while let Some(step) = steps.next() {
        let next = match (step, value.map(|v| v.get_ref())) {
            (Step::Key(key), None) => {
                table.iter().find(|(k, _)| k.get_ref().as_ref() == *key).map(|(_, v)| v)
            }
            (Step::Key(key), Some(DeValue::Table(t))) => {
                table = t;
                t.iter().find(|(k, _)| k.get_ref().as_ref() == *key).map(|(_, v)| v)
            }
            (Step::Index(i), Some(DeValue::Array(a))) => a.get(*i),
            (Step::Key(_), Some(_)) | (Step::Index(_), _) => None,
        };
        match next {
            Some(v) => {
                found = Some(v.span().start);
                value = Some(v);
            }
            None => break,
        }
        if steps.peek().is_none() {
            break;
        }
    }
    found.map(|offset| line_and_column(text, offset))
}

/// The 1-based line and column (in characters) of byte `offset` in `text`.
fn line_and_column(text: &str, offset: usize) -> (usize, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let column = before.rsplit('\n').next().map_or(0, |l| l.chars().count()) + 1;
    (line, column)
}

#[cfg(test)]
mod tests {
    use super::*;

    const TEXT: &str = "builtin = \"columns\"\n\n[spot]\nposition = [0, 5, 0]\ninner_angle = -50\n\n[[light]]\ntype = \"point\"\n\n[[light]]\ntype = \"sun\"\ncolor = [1, 2, 3]\n\n[settings.shadow.map]\nresolution = 3\n";

    #[test]
    fn keys_tables_and_array_elements_are_found_where_they_are_written() {
        use Step::*;
        assert_eq!(locate(TEXT, &[Key("spot"), Key("inner_angle")]), Some((5, 15)));
        assert_eq!(locate(TEXT, &[Key("light"), Index(1), Key("color")]), Some((12, 9)));
        assert_eq!(
            locate(TEXT, &[Key("settings"), Key("shadow"), Key("map"), Key("resolution")]),
            Some((15, 14))
        );
        assert_eq!(display(&[Key("light"), Index(1), Key("color")]), "light[1].color");
    }

    #[test]
    fn a_missing_key_is_reported_at_its_table_and_a_missing_table_not_at_all() {
        use Step::*;
        let spot = locate(TEXT, &[Key("spot")]);
        assert_eq!(locate(TEXT, &[Key("spot"), Key("range")]), spot);
        assert_eq!(locate(TEXT, &[Key("point"), Key("range")]), None);
        assert_eq!(locate("not toml [", &[Key("spot")]), None);
    }
}
