//! An argument refused by name: the argument as the user gave it (a flag by its flag,
//! `--fov`; a scene file's key by its key, `camera.fov_deg`; a function's parameter by
//! its name), the value given, and what is allowed. Every crate's error type carries one
//! ([`BadArgument`]) for the caller's mistakes, so that a message reads the same wherever
//! the check lives: `--fov 0: expected 0.1 to 170 degrees`.

use std::fmt::Display;

/// An argument outside what is allowed (the caller's fault, [`crate::Fault::Usage`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{name} {value}: expected {allowed}")]
pub struct BadArgument {
    /// The argument as the user gave it: `--fov`, `camera.fov_deg`, `quality`.
    pub name: String,
    /// The value given, as given.
    pub value: String,
    /// What is allowed: `0.1 to 170 degrees`, `a pose of the capture (0, 1, 2)`.
    pub allowed: String,
}

impl BadArgument {
    /// `name` given `value`, where `allowed` is allowed.
    pub fn new(name: impl Into<String>, value: impl Display, allowed: impl Into<String>) -> Self {
        Self {
            name: name.into(),
            value: value.to_string(),
            allowed: allowed.into(),
        }
    }

    /// The same refusal for an argument known to the caller by another name (a library's
    /// parameter, reported by the command line as its flag).
    pub fn renamed(self, name: impl Into<String>) -> Self {
        Self {
            name: name.into(),
            ..self
        }
    }
}

/// The first item of `items` given before: its place (from 1) and the item; `None` where
/// each is given once. A list a user gives (poses, views, walker counts, sizes) names each
/// value once, or its work is done twice.
pub fn given_twice<T: PartialEq>(items: &[T]) -> Option<(usize, &T)> {
    (items.iter().enumerate())
        .find(|(k, v)| items[..*k].contains(v))
        .map(|(k, v)| (k + 1, v))
}

/// `value` if it lies in `lo..=hi` (a NaN never does), else a [`BadArgument`] naming it;
/// `unit` follows the bounds in the message (`"degrees"`, or `""`).
pub fn within<T: PartialOrd + Display + Copy>(
    name: &str,
    value: T,
    lo: T,
    hi: T,
    unit: &str,
) -> Result<T, BadArgument> {
    if value >= lo && value <= hi {
        Ok(value)
    } else {
        let unit = if unit.is_empty() {
            String::new()
        } else {
            format!(" {unit}")
        };
        Err(BadArgument::new(name, value, format!("{lo} to {hi}{unit}")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_the_argument_its_value_and_what_is_allowed() {
        let e = within("--fov", 0.0_f32, 0.1, 170.0, "degrees").unwrap_err();
        assert_eq!(e.to_string(), "--fov 0: expected 0.1 to 170 degrees");
        assert_eq!(within("--fov", 45.0_f32, 0.1, 170.0, "degrees"), Ok(45.0));
        assert!(within("quality", f32::NAN, 0.0, 1.0, "").is_err());
        let e = within("quality", 101_u8, 1, 100, "")
            .unwrap_err()
            .renamed("--jpeg-quality");
        assert_eq!(e.to_string(), "--jpeg-quality 101: expected 1 to 100");
    }
}
