//! Shared test support for every crate's tests: where the real recordings are.
//!
//! Real-data tests use `../shared/data` beside the repository (recordings by other people that
//! are never copied into it). When it is absent they print why and pass without measuring
//! anything ([`shared_data`] returns `None`), so the repository's tests work on their own.
//! When the environment variable [`REQUIRE_DATA_ENV`] is set (CI sets it whenever
//! `../shared/data` is present), a real-data test that would skip fails instead: a missing or
//! renamed recording can never make CI pass silently.
//!
//! The ROS 2 interoperability tests check the simulator's output with third-party Python
//! tools in a venv ([`ros2_python`]); they skip in the same way when it is absent, and fail
//! instead when [`REQUIRE_ROS2_ENV`] is set (CI sets it after installing the venv).
//!
//! **The skips are counted.** A passing test's output is captured by the test harness, so a
//! skip's note alone would never be seen. Every skip is therefore also written to a ledger
//! shared by the test binaries of one `cargo test` run (under the target folder, keyed by the
//! `cargo` process that runs them all), and the last test binary a plain workspace
//! `cargo test` runs (`host-sim/tests/zz_real_data.rs`; cargo runs test binaries in the order
//! of their package's and target's names) prints one line straight to the process's stderr,
//! which the harness does not capture: `real data: 23 tests skipped: ../shared/data is absent
//! (...)`. [`SHARED_DATA_ENV`] points the tests at another folder (a missing one to see the
//! skips).
//!
//! Dependency-free on purpose, so the runtime's, the trainer's and the simulator's tests can
//! all use it as a dev-dependency.

pub mod docs;

use std::io::Write as _;
use std::path::{Path, PathBuf};

/// Set (to anything) to turn every real-data skip into a failure.
pub const REQUIRE_DATA_ENV: &str = "GESTURE_REQUIRE_DATA";

/// Set to a folder to use it instead of `../shared/data`.
pub const SHARED_DATA_ENV: &str = "GESTURE_SHARED_DATA";

/// The repository's root (this crate sits in `tests/`).
pub fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map_or_else(|| PathBuf::from(".."), Path::to_path_buf)
}

/// `../shared/data` relative to the repository root (or [`SHARED_DATA_ENV`]), whether or not
/// it exists.
pub fn shared_data_dir() -> PathBuf {
    match std::env::var_os(SHARED_DATA_ENV) {
        Some(dir) => PathBuf::from(dir),
        None => repo_root().join("../shared/data"),
    }
}

/// `../shared/data/<sub>` if it exists (`sub` may be empty for the folder itself). Otherwise
/// prints `skipping <test>: <why>` on stderr and returns `None`, or panics if
/// [`REQUIRE_DATA_ENV`] is set.
pub fn shared_data(test: &str, sub: &str) -> Option<PathBuf> {
    find(test, sub, true)
}

/// [`shared_data`], its skip counted in the run's ledger when `count`.
fn find(test: &str, sub: &str, count: bool) -> Option<PathBuf> {
    let root = shared_data_dir();
    let path = if sub.is_empty() {
        root.clone()
    } else {
        root.join(sub)
    };
    if path.exists() {
        return Some(path);
    }
    let why = if root.is_dir() {
        format!("{} is missing from the shared data", path.display())
    } else {
        format!("{} is absent, nothing measured", root.display())
    };
    note(test, &why, count);
    None
}

/// Reports a skipped real-data test (see [`shared_data`]) and counts it in this run's ledger
/// (see the crate docs); panics under [`REQUIRE_DATA_ENV`].
pub fn skip(test: &str, why: &str) {
    note(test, why, true);
}

/// [`skip`], counted in the ledger when `count`.
fn note(test: &str, why: &str, count: bool) {
    if std::env::var_os(REQUIRE_DATA_ENV).is_some() {
        panic!("{test}: real data required ({REQUIRE_DATA_ENV} is set) but {why}");
    }
    eprintln!("skipping {test}: {why}");
    if let Some(ledger) = ledger().filter(|_| count) {
        // One test per line: the binary and the harness's thread (named after the test).
        let binary = std::env::current_exe()
            .ok()
            .and_then(|e| e.file_stem().map(|s| s.to_string_lossy().into_owned()))
            .unwrap_or_default();
        let thread = std::thread::current().name().unwrap_or(test).to_string();
        let line = format!("{binary} {thread}\t{why}\n");
        // Best effort: a ledger that cannot be written leaves the note above.
        let _ = std::fs::create_dir_all(ledger.parent().unwrap_or(Path::new(".")));
        let _ = std::fs::OpenOptions::new()
            .create(true)
            .append(true)
            .open(&ledger)
            .and_then(|mut f| f.write_all(line.as_bytes()));
    }
}

/// The ledger of this `cargo test` run's skips: `<target>/<profile>/real-data-skips/<run>`,
/// the run named by the parent process (`cargo`) and its start time, so a later run that gets
/// the same process id starts a new ledger. `None` off Unix.
fn ledger() -> Option<PathBuf> {
    let exe = std::env::current_exe().ok()?;
    // target/<profile>/deps/<binary>
    let profile = exe.parent()?.parent()?;
    Some(profile.join("real-data-skips").join(run_key()?))
}

#[cfg(unix)]
fn run_key() -> Option<String> {
    let ppid = std::os::unix::process::parent_id();
    // Field 22 of /proc/<pid>/stat, the start time: the 20th after the command's `)`.
    let start = std::fs::read_to_string(format!("/proc/{ppid}/stat"))
        .ok()
        .and_then(|s| {
            let (_, rest) = s.rsplit_once(')')?;
            rest.split_whitespace().nth(19).map(str::to_string)
        })
        .unwrap_or_default();
    Some(format!("{ppid}-{start}"))
}

#[cfg(not(unix))]
fn run_key() -> Option<String> {
    None
}

/// The one line about this run's skipped real-data tests (`None`: none skipped), and the
/// ledger emptied: how many, and why (the shared folder absent, or recordings missing from
/// it; each test's output says which).
pub fn skipped_summary() -> Option<String> {
    let ledger = ledger()?;
    let text = std::fs::read_to_string(&ledger).ok()?;
    let _ = std::fs::remove_file(&ledger);
    let tests: std::collections::BTreeSet<&str> = text
        .lines()
        .filter_map(|l| l.split_once('\t').map(|(t, _)| t))
        .collect();
    if tests.is_empty() {
        return None;
    }
    let root = shared_data_dir();
    let why = if root.is_dir() {
        "recordings are missing from the shared data (each test's output names them)".to_string()
    } else {
        format!("{} is absent", root.display())
    };
    Some(format!(
        "real data: {} tests skipped: {why} (set {REQUIRE_DATA_ENV}=1 to make a skip fail)",
        tests.len()
    ))
}

/// Prints [`skipped_summary`] straight to the process's stderr, which the test harness does
/// not capture (it captures `eprintln!` only).
pub fn print_skipped_summary() {
    if let Some(line) = skipped_summary() {
        let _ = writeln!(std::io::stderr().lock(), "{line}");
    }
}

/// Set (to anything) to turn every skip of a ROS 2 interoperability test into a failure (CI
/// sets it after installing the Python packages those tests decode with).
pub const REQUIRE_ROS2_ENV: &str = "GESTURE_REQUIRE_ROS2";

/// Overrides where the ROS 2 tests' Python is (default: [`ros2_venv`]`/bin/python`).
pub const ROS2_PYTHON_ENV: &str = "GESTURE_ROS2_PYTHON";

/// The Python packages the ROS 2 tests import (PyPI names: cyclonedds, rosbags, mcap,
/// mcap-ros2-support, urdf-parser-py, and numpy with them).
pub const ROS2_PYTHON_MODULES: &str = "cyclonedds, rosbags, mcap, mcap_ros2, urdf_parser_py, numpy";

/// The virtual environment `.ci/run` installs the ROS 2 tests' Python packages into.
pub fn ros2_venv() -> PathBuf {
    repo_root().join("target/ros2-venv")
}

/// The Python that has the ROS 2 tests' packages ([`ROS2_PYTHON_MODULES`]): that of
/// [`ROS2_PYTHON_ENV`] or of [`ros2_venv`]. Otherwise prints `skipping <test>: <why>` and
/// returns `None`, or panics if [`REQUIRE_ROS2_ENV`] is set.
pub fn ros2_python(test: &str) -> Option<PathBuf> {
    let python = std::env::var_os(ROS2_PYTHON_ENV)
        .map_or_else(|| ros2_venv().join("bin/python"), PathBuf::from);
    if !python.exists() {
        skip_ros2(
            test,
            &format!(
                "{} is absent (python3 -m venv {v} && {v}/bin/pip install -r \
                 {r}; .ci/run does it)",
                python.display(),
                v = ros2_venv().display(),
                r = repo_root()
                    .join("host-sim/tests/ros2/requirements.txt")
                    .display()
            ),
        );
        return None;
    }
    let ok = std::process::Command::new(&python)
        .args(["-c", &format!("import {ROS2_PYTHON_MODULES}")])
        .output()
        .map(|o| o.status.success())
        .unwrap_or(false);
    if !ok {
        skip_ros2(
            test,
            &format!("{} cannot import {ROS2_PYTHON_MODULES}", python.display()),
        );
        return None;
    }
    Some(python)
}

/// Reports a skipped ROS 2 test; panics under [`REQUIRE_ROS2_ENV`].
pub fn skip_ros2(test: &str, why: &str) {
    if std::env::var_os(REQUIRE_ROS2_ENV).is_some() {
        panic!("{test}: ROS 2 tools required ({REQUIRE_ROS2_ENV} is set) but {why}");
    }
    eprintln!("skipping {test}: {why}");
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_missing_recording_skips_with_a_reason_or_fails_when_required() {
        let name = "no-such-recording-for-the-locator-test";
        if std::env::var_os(REQUIRE_DATA_ENV).is_some() {
            let r = std::panic::catch_unwind(|| find("locator", name, false));
            assert!(r.is_err(), "a required recording that is missing must fail");
        } else {
            // Not counted: no real-data test skipped here.
            assert_eq!(find("locator", name, false), None);
        }
        assert!(repo_root().join("Cargo.toml").is_file());
    }
}
