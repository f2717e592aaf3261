//! What every kerf FMU instance (one disc or a cutterhead) shares of the
//! FMI 2.0 machinery: the log-category switches and the state-machine checks.

use super::instance::{kind_name, Kind, Mode, Res};
use super::log::Category;
use super::md;

/// On/off per log category of `md::LOG_CATEGORIES`.
#[derive(Debug, Clone)]
pub struct LogSwitches(Vec<bool>);

impl LogSwitches {
    /// Errors and warnings always on; the rest as `fmi2Instantiate`'s
    /// `loggingOn` says.
    pub fn new(logging_on: bool) -> Self {
        Self(
            md::LOG_CATEGORIES
                .iter()
                .map(|c| match *c {
                    "logStatusError" | "logStatusWarning" => true,
                    _ => logging_on,
                })
                .collect(),
        )
    }

    pub fn enabled(&self, cat: Category) -> bool {
        let name = cat.name();
        md::LOG_CATEGORIES
            .iter()
            .position(|c| *c == name)
            .is_some_and(|i| self.0[i])
    }

    /// `fmi2SetDebugLogging`: all categories when `categories` is empty or
    /// names `logAll`; an unknown name changes nothing and is an error.
    pub fn set(&mut self, on: bool, categories: &[String]) -> Res<()> {
        if categories.is_empty() {
            self.0.iter_mut().for_each(|b| *b = on);
            return Ok(());
        }
        let mut idx = Vec::new();
        for c in categories {
            match md::LOG_CATEGORIES.iter().position(|k| k == c) {
                Some(i) => idx.push(i),
                None => {
                    return Err(format!(
                        "fmi2SetDebugLogging: unknown log category \"{c}\" (known: {})",
                        md::LOG_CATEGORIES.join(", ")
                    ))
                }
            }
        }
        for i in idx {
            if md::LOG_CATEGORIES[i] == "logAll" {
                self.0.iter_mut().for_each(|b| *b = on);
            } else {
                self.0[i] = on;
            }
        }
        Ok(())
    }
}

/// Is `func` allowed in `mode` (`mask`: the modes it is allowed in)?
pub fn check_mode(mode: Mode, func: &str, mask: u32) -> Res<()> {
    if mode.bit() & mask != 0 {
        Ok(())
    } else {
        Err(format!(
            "{func}: illegal call sequence: not allowed in {}",
            mode_name(mode)
        ))
    }
}

/// Is `func`, which only `want` instances may call, allowed in a `have` one?
pub fn check_kind(have: Kind, func: &str, want: Kind) -> Res<()> {
    if have == want {
        Ok(())
    } else {
        Err(format!(
            "{func}: only for {} instances; this one was instantiated for {}",
            kind_name(want),
            kind_name(have)
        ))
    }
}

pub fn mode_name(mode: Mode) -> &'static str {
    use Mode::*;
    match mode {
        Instantiated => "the instantiated state",
        InitializationMode => "initialization mode",
        EventMode => "event mode",
        ContinuousTimeMode => "continuous-time mode",
        StepComplete => "the step-complete state",
        Terminated => "the terminated state",
        Error => "the error state (call fmi2Reset, fmi2SetFMUstate or fmi2FreeInstance)",
    }
}
