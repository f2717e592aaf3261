//! Errors of the physics core. Every fallible core call returns [`KerfError`];
//! the FMI layer turns it into `fmi2Error` plus a logger message.

use std::fmt;

#[derive(Debug, Clone, PartialEq)]
pub enum KerfError {
    /// A parameter is out of its domain (name, value, why): outside its
    /// allowed range (`bounds.rs`, the range is in `why`) or breaking a rule
    /// between parameters.
    BadParameter {
        name: &'static str,
        value: f64,
        why: std::borrow::Cow<'static, str>,
    },
    /// An input is not finite or absurd (name, value, the values it may
    /// take, e.g. "finite, |x| <= 1e6 m").
    BadInput {
        name: &'static str,
        value: f64,
        allowed: std::borrow::Cow<'static, str>,
    },
    /// A surface file could not be read or written (file, line (0 = whole file), what).
    SurfaceFile {
        file: String,
        line: usize,
        what: String,
    },
    /// A serialized state blob is corrupt, foreign or from another grid.
    BadState(String),
    /// A head layout or one of its discs is invalid (the whole message:
    /// file, cutter and key).
    Layout(String),
    /// One call would do more work than a call may (sub-steps, nodes visited
    /// or written); the message says how to split it. Refused before
    /// anything changed.
    TooMuchWork(String),
}

impl fmt::Display for KerfError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            KerfError::BadParameter { name, value, why } => {
                write!(f, "parameter {name} = {}: {why}", Compact(*value))
            }
            KerfError::BadInput {
                name,
                value,
                allowed,
            } => write!(
                f,
                "input {name} = {} is not a finite, plausible value ({allowed})",
                Compact(*value)
            ),
            KerfError::SurfaceFile {
                file,
                line: 0,
                what,
            } => write!(f, "surface file {file}: {what}"),
            KerfError::SurfaceFile { file, line, what } => {
                write!(f, "surface file {file}, line {line}: {what}")
            }
            KerfError::BadState(why) => write!(f, "FMU state rejected: {why}"),
            KerfError::Layout(msg) => write!(f, "{msg}"),
            KerfError::TooMuchWork(why) => write!(f, "refused, nothing changed: {why}"),
        }
    }
}

impl std::error::Error for KerfError {}

/// A value as a message shows it: as Rust prints it (`0.25`, `-3`, `NaN`,
/// `inf`), but in exponent form (`1e30`, `5e-324`) where that would run to
/// more than a dozen characters: a host's 1e300 is not 301 digits long.
pub struct Compact(pub f64);

impl fmt::Display for Compact {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let plain = self.0.to_string();
        if plain.len() > 12 {
            let short = format!("{:e}", self.0);
            if short.len() < plain.len() {
                return f.write_str(&short);
            }
        }
        f.write_str(&plain)
    }
}

pub type Result<T> = std::result::Result<T, KerfError>;

#[cfg(test)]
mod tests {
    use super::{Compact, KerfError};

    /// Values print as Rust prints them until that runs long; then in
    /// exponent form, which is exact too (both are the shortest form that
    /// reads back as the same f64).
    #[test]
    fn values_in_messages_stay_short_and_exact() {
        for (v, s) in [
            (0.25, "0.25"),
            (-3.0, "-3"),
            (1e6, "1000000"),
            (1e30, "1e30"),
            (-1e300, "-1e300"),
            (5e-324, "5e-324"),
            (1.5e-7, "0.00000015"),
            (1.5e-13, "1.5e-13"),
            (f64::NAN, "NaN"),
            (f64::NEG_INFINITY, "-inf"),
        ] {
            let text = Compact(v).to_string();
            assert_eq!(text, s);
            let back: f64 = text.parse().unwrap();
            assert!(
                back == v || (v.is_nan() && back.is_nan()),
                "{text} reads back as {back}"
            );
        }
        let e = KerfError::BadInput {
            name: "vx",
            value: 1e300,
            allowed: "at most 1e4 m/s or rad/s".into(),
        };
        assert_eq!(
            e.to_string(),
            "input vx = 1e300 is not a finite, plausible value (at most 1e4 m/s or rad/s)"
        );
    }
}
