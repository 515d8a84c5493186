//! Issue 24 item 3: the Python package, built and tested by pytest inside `cargo test`.
//!
//! The test makes its own virtual environment (`target/pyenv`, kept between runs), installs
//! the test's Python packages into it from the package index (maturin, numpy, pandas, pytest,
//! dask with distributed, matplotlib), builds and installs the package from this repository as
//! `pip install .` does (its own cargo target directory, `target/python`: the outer `cargo
//! test` holds the lock on `target/release`), and runs `python/tests` with this build's `mbd`
//! binary as the CLI the tables are compared with.

use crate::common::repo;
use std::path::Path;
use std::process::Command;

/// The Python packages the tests need (the `test` extra of `pyproject.toml`, and the build
/// backend so that the build runs without fetching it again).
const PACKAGES: &[&str] = &[
    "maturin>=1.5,<2",
    "numpy>=1.21",
    "pandas>=1.3",
    "pytest>=7",
    "dask[distributed]>=2023.1",
    "matplotlib>=3.5",
];

fn run(cmd: &mut Command, what: &str) {
    let out = cmd
        .output()
        .unwrap_or_else(|e| panic!("{what}: cannot start: {e}"));
    assert!(
        out.status.success(),
        "{what} failed ({}):\n{}\n{}",
        out.status,
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
}

#[test]
fn the_python_package_passes_its_tests() {
    let root = repo("");
    let env = root.join("target").join("pyenv");
    let bin = env.join("bin");
    let python = bin.join("python");
    if !python.exists() {
        let python3 = std::env::var("PYTHON").unwrap_or_else(|_| "python3".to_string());
        run(
            Command::new(python3).args(["-m", "venv"]).arg(&env),
            "creating the virtual environment",
        );
    }
    let path = format!(
        "{}:{}",
        bin.display(),
        std::env::var("PATH").unwrap_or_default()
    );
    let pip = |args: &[&str], what: &str| {
        run(
            Command::new(&python)
                .args(["-m", "pip", "--disable-pip-version-check", "-q"])
                .args(args)
                .current_dir(&root)
                .env("PATH", &path)
                .env("CARGO_TARGET_DIR", root.join("target").join("python")),
            what,
        )
    };
    pip(
        &[&["install"][..], PACKAGES].concat(),
        "installing the test's packages",
    );
    pip(
        &[
            "install",
            "--no-build-isolation",
            "--force-reinstall",
            "--no-deps",
            ".",
        ],
        "building and installing the package (pip install .)",
    );
    let mbd_bin = Path::new(env!("CARGO_BIN_EXE_mbd"));
    run(
        Command::new(&python)
            .args([
                "-m",
                "pytest",
                "-q",
                "-p",
                "no:cacheprovider",
                "python/tests",
            ])
            .current_dir(&root)
            .env("PATH", &path)
            .env("MBD_BIN", mbd_bin)
            // The source tree's `python/` must not shadow the installed package.
            .env("PYTHONSAFEPATH", "1"),
        "pytest python/tests",
    );
}
