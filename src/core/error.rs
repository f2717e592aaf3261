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
    /// An input is not finite or absurd (name, value).
    BadInput { name: &'static str, value: f64 },
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
                write!(f, "parameter {name} = {value}: {why}")
            }
            KerfError::BadInput { name, value } => {
                write!(f, "input {name} = {value} is not a finite, plausible value")
            }
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

pub type Result<T> = std::result::Result<T, KerfError>;
