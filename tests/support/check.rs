//! A test that cannot set up what it is about checks nothing, and must not pass quietly:
//! under CI it fails, saying what it could not set up; elsewhere it says so, loudly, on
//! standard error and the caller returns without checking.

/// Whether this run is CI's: `CI` set to anything but empty, `0` or `false` (CI services
/// set `CI=true`; `.ci/run` sets it when it is not set).
pub fn under_ci() -> bool {
    std::env::var("CI").is_ok_and(|v| {
        let v = v.trim();
        !(v.is_empty() || v == "0" || v.eq_ignore_ascii_case("false"))
    })
}

/// `test` cannot check what it is about because of `reason` (what could not be set up,
/// and how to set it up): a failure under CI, else a printed skip the caller follows by
/// returning.
pub fn cannot_check(test: &str, reason: &str) {
    assert!(
        !under_ci(),
        "{test}: {reason}; under CI every test must check what it is about (scripts/setup.sh --test, run as root, sets it up)"
    );
    eprintln!(
        "\n!!!!! SKIPPED {test}: {reason}; it checks nothing here (under CI it fails) !!!!!\n"
    );
}
