//! The CPU features this binary was built to assume (`.cargo/config.toml`:
//! x86-64-v2), checked before an instance is made: on a CPU without them the
//! FMU refuses at fmi2Instantiate, naming what is missing, instead of
//! stopping the host on an illegal instruction later.

/// Features the compiler may have used here, for x86-64: each with whether
/// this build assumed it (`cfg!(target_feature)`) and whether this CPU has
/// it, side by side so the two cannot name different features.
#[cfg(target_arch = "x86_64")]
fn features() -> [(&'static str, bool, bool); 6] {
    macro_rules! feature {
        ($name:tt) => {
            (
                $name,
                cfg!(target_feature = $name),
                std::is_x86_feature_detected!($name),
            )
        };
    }
    [
        feature!("sse3"),
        feature!("ssse3"),
        feature!("sse4.1"),
        feature!("sse4.2"),
        feature!("popcnt"),
        feature!("cmpxchg16b"),
    ]
}

/// Why this CPU cannot run this binary, or `None` when it can.
pub fn unsupported() -> Option<String> {
    #[cfg(target_arch = "x86_64")]
    {
        let f = features();
        let assumed: Vec<(&str, bool)> = f.iter().map(|&(n, built, _)| (n, built)).collect();
        missing(&assumed, |name| {
            f.iter().any(|&(n, _, has)| n == name && has)
        })
    }
    #[cfg(not(target_arch = "x86_64"))]
    {
        None
    }
}

/// The features of `assumed` that were built in but `detect` does not find.
fn missing(assumed: &[(&str, bool)], detect: impl Fn(&str) -> bool) -> Option<String> {
    let lacking: Vec<&str> = assumed
        .iter()
        .filter(|&&(name, built_in)| built_in && !detect(name))
        .map(|&(name, _)| name)
        .collect();
    (!lacking.is_empty()).then(|| {
        format!(
            "this CPU lacks {}, which this build of kerf assumes (x86-64-v2); \
             rebuild it with RUSTFLAGS=\"-C target-cpu=x86-64\"",
            lacking.join(", ")
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_cpu_without_a_built_in_feature_is_named() {
        let assumed = [("sse4.1", true), ("popcnt", true), ("avx", false)];
        let msg = missing(&assumed, |f| f != "sse4.1" && f != "avx").expect("refused");
        assert!(
            msg.contains("lacks sse4.1,") && !msg.contains("popcnt"),
            "{msg}"
        );
        // a feature the build did not assume is never asked for
        assert_eq!(missing(&assumed, |f| f != "avx"), None);
    }

    /// The build assumes what the repository's cargo config asks for, and the
    /// machine that runs the tests has it.
    #[cfg(target_arch = "x86_64")]
    #[test]
    fn this_build_assumes_x86_64_v2_and_this_cpu_has_it() {
        let built: Vec<&str> = features()
            .into_iter()
            .filter(|&(_, b, _)| b)
            .map(|(n, _, _)| n)
            .collect();
        if std::env::var_os("RUSTFLAGS").is_none() {
            assert!(
                built.contains(&"sse4.2") && built.contains(&"popcnt"),
                "{built:?}"
            );
        }
        assert_eq!(unsupported(), None);
    }
}
