//! A scene file's three-number arrays (`translation = [0, 1, 2]`): exactly three.
//! serde's fixed-size arrays take the first three of a longer TOML array and drop
//! the rest without a word, so `[0, 1, 2, 3]` would have placed a model at (0, 1, 2).

use serde::{Deserialize, Deserializer, de::Error};

/// Exactly three numbers.
pub(super) fn exact<'de, D: Deserializer<'de>>(deserializer: D) -> Result<[f32; 3], D::Error> {
    let numbers = Vec::<f32>::deserialize(deserializer)?;
    <[f32; 3]>::try_from(numbers.as_slice())
        .map_err(|_| D::Error::custom(format!("{} numbers given, expected three: [x, y, z]", numbers.len())))
}

/// Absent, or exactly three numbers.
pub(super) fn optional<'de, D: Deserializer<'de>>(deserializer: D) -> Result<Option<[f32; 3]>, D::Error> {
    exact(deserializer).map(Some)
}

#[cfg(test)]
mod tests {
    #[derive(serde::Deserialize)]
    struct Entry {
        #[serde(deserialize_with = "super::exact")]
        at: [f32; 3],
        #[serde(default, deserialize_with = "super::optional")]
        colour: Option<[f32; 3]>,
    }

    #[test]
    fn three_numbers_and_no_more() {
        let e: Entry = toml::from_str("at = [0, 1, 2]").unwrap();
        assert_eq!((e.at, e.colour), ([0.0, 1.0, 2.0], None));
        let e: Entry = toml::from_str("at = [0, 1, 2]\ncolour = [1, 1, 1]").unwrap();
        assert_eq!(e.colour, Some([1.0; 3]));
        for bad in ["at = [0, 1, 2, 3]", "at = [0, 1]", "at = [0, 1, 2]\ncolour = [1, 1, 1, 1]"] {
            let e = toml::from_str::<Entry>(bad).err().unwrap().to_string();
            assert!(e.contains("expected three"), "{bad}: {e}");
        }
    }
}
