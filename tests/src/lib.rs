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
//! Dependency-free on purpose, so the runtime's, the trainer's and the simulator's tests can
//! all use it as a dev-dependency.

pub mod docs;

use std::path::{Path, PathBuf};

/// Set (to anything) to turn every real-data skip into a failure.
pub const REQUIRE_DATA_ENV: &str = "GESTURE_REQUIRE_DATA";

/// The repository's root (this crate sits in `tests/`).
pub fn repo_root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map_or_else(|| PathBuf::from(".."), Path::to_path_buf)
}

/// `../shared/data` relative to the repository root, whether or not it exists.
pub fn shared_data_dir() -> PathBuf {
    repo_root().join("../shared/data")
}

/// `../shared/data/<sub>` if it exists (`sub` may be empty for the folder itself). Otherwise
/// prints `skipping <test>: <why>` on stderr and returns `None`, or panics if
/// [`REQUIRE_DATA_ENV`] is set.
pub fn shared_data(test: &str, sub: &str) -> Option<PathBuf> {
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
    skip(test, &why);
    None
}

/// Reports a skipped real-data test (see [`shared_data`]); panics under [`REQUIRE_DATA_ENV`].
pub fn skip(test: &str, why: &str) {
    if std::env::var_os(REQUIRE_DATA_ENV).is_some() {
        panic!("{test}: real data required ({REQUIRE_DATA_ENV} is set) but {why}");
    }
    eprintln!("skipping {test}: {why}");
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
            let r = std::panic::catch_unwind(|| shared_data("locator", name));
            assert!(r.is_err(), "a required recording that is missing must fail");
        } else {
            assert_eq!(shared_data("locator", name), None);
        }
        assert!(repo_root().join("Cargo.toml").is_file());
    }
}
