//! Shared helpers for integration tests: finding real Radiance (the oracle) and running
//! our own binaries.
//!
//! Real Radiance comes from the PyPI package `pyradiance` (its `bin/` and `lib/`), which the
//! README's test command installs. Set `RADIANCE_BIN` (and optionally `RAYPATH`) to use
//! another Radiance install. Interop tests **fail** when Radiance cannot be found, so a green
//! run always means "compared with real Radiance"; set `RDAYLIGHT_SKIP_RADIANCE=1` to skip
//! them deliberately (they then print that they were skipped).
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::sync::OnceLock;

/// Radiance's `bin/` and `lib/` folders, if available.
pub fn radiance_dirs() -> Option<(PathBuf, PathBuf)> {
    static DIRS: OnceLock<Option<(PathBuf, PathBuf)>> = OnceLock::new();
    DIRS.get_or_init(|| {
        if let Ok(bin) = std::env::var("RADIANCE_BIN") {
            let bin = PathBuf::from(bin);
            let lib = std::env::var("RAYPATH")
                .map(PathBuf::from)
                .unwrap_or_else(|_| bin.with_file_name("lib"));
            return Some((bin, lib));
        }
        let out = Command::new("python3")
            .args([
                "-c",
                "import pyradiance, os; print(os.path.dirname(pyradiance.__file__))",
            ])
            .output()
            .ok()?;
        if !out.status.success() {
            return None;
        }
        let root = PathBuf::from(String::from_utf8_lossy(&out.stdout).trim());
        let bin = root.join("bin");
        bin.join("rtrace").exists().then(|| (bin, root.join("lib")))
    })
    .clone()
}

/// True if interop tests should run; panics (test failure) when Radiance is missing and the
/// user did not ask to skip.
pub fn have_radiance(test: &str) -> bool {
    if radiance_dirs().is_some() {
        return true;
    }
    if std::env::var_os("RDAYLIGHT_SKIP_RADIANCE").is_some() {
        eprintln!("{test}: skipped (RDAYLIGHT_SKIP_RADIANCE set, no real Radiance)");
        return false;
    }
    panic!(
        "{test}: real Radiance not found. Install it with `pip install pyradiance` \
         (the README's test command does), or set RADIANCE_BIN, or set \
         RDAYLIGHT_SKIP_RADIANCE=1 to skip interop tests"
    );
}

/// A `Command` for a real Radiance program with `RAYPATH` set.
pub fn radiance(prog: &str) -> Command {
    let (bin, lib) = radiance_dirs().expect("real Radiance not found");
    let mut c = Command::new(bin.join(prog));
    let raypath = match std::env::var("RAYPATH") {
        Ok(p) if !p.is_empty() => format!(".:{}:{p}", lib.display()),
        _ => format!(".:{}", lib.display()),
    };
    c.env("RAYPATH", raypath);
    // Radiance's generators call each other (e.g. rfluxmtx runs rcontrib): put bin first.
    let path = std::env::var("PATH").unwrap_or_default();
    c.env("PATH", format!("{}:{path}", bin.display()));
    c
}

/// Run a command with the given stdin bytes; panic with its stderr if it fails.
pub fn run_ok(cmd: &mut Command, stdin: &[u8]) -> Vec<u8> {
    let out = run(cmd, stdin);
    if !out.status.success() {
        panic!(
            "{:?} failed ({}): {}",
            cmd,
            out.status,
            String::from_utf8_lossy(&out.stderr)
        );
    }
    out.stdout
}

/// Run a command with the given stdin bytes and return everything.
pub fn run(cmd: &mut Command, stdin: &[u8]) -> Output {
    use std::io::Write;
    let mut child = cmd
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap_or_else(|e| panic!("cannot start {cmd:?}: {e}"));
    let mut sin = child.stdin.take().unwrap();
    let data = stdin.to_vec();
    let writer = std::thread::spawn(move || {
        let _ = sin.write_all(&data);
    });
    let out = child.wait_with_output().unwrap();
    let _ = writer.join();
    out
}

/// One of this package's binaries, built by cargo for the integration tests.
pub fn ours(bin: &str) -> Command {
    let path = match bin {
        "rinfo" => env!("CARGO_BIN_EXE_rinfo"),
        "rmtx" => env!("CARGO_BIN_EXE_rmtx"),
        "rdc" => env!("CARGO_BIN_EXE_rdc"),
        "rspecsky" => env!("CARGO_BIN_EXE_rspecsky"),
        "rmetrics" => env!("CARGO_BIN_EXE_rmetrics"),
        "rglare" => env!("CARGO_BIN_EXE_rglare"),
        "ruplift" => env!("CARGO_BIN_EXE_ruplift"),
        "rmcop" => env!("CARGO_BIN_EXE_rmcop"),
        "rcalib" => env!("CARGO_BIN_EXE_rcalib"),
        "rrecon" => env!("CARGO_BIN_EXE_rrecon"),
        "rglod" => env!("CARGO_BIN_EXE_rglod"),
        other => panic!("unknown binary {other}"),
    };
    Command::new(path)
}

/// The repository root (for `radiance-fixtures/` and `examples/`).
pub fn repo() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// A fresh temporary directory, removed when dropped.
pub fn tmpdir() -> tempfile::TempDir {
    tempfile::tempdir().expect("temporary directory")
}

/// The name libtest gives test `name` of the module whose `module_path!()` is
/// `module_path` (the crate name dropped: `all::scene` -> `scene::name`), for a test that
/// re-runs this binary on itself with `--exact`.
pub fn test_path(module_path: &str, name: &str) -> String {
    match module_path.split_once("::") {
        Some((_, m)) => format!("{m}::{name}"),
        None => name.to_string(),
    }
}

/// A daylight-coefficient cache directory `$TMPDIR/<name>` for rcalib runs, seeded once per
/// process from the committed entries in `fixture` (copied, then renamed, because rcalib
/// runs of other tests may read the directory meanwhile). Keys hash the scene, sensors,
/// settings and the tracer's `REVISION` (`calib::cache`), so stale fixture entries are
/// simply never found and their values are traced again. `RDAYLIGHT_RCALIB_NO_SEED` skips
/// the seeding: the Makefile's cache targets regenerate a fixture from nothing that way.
pub fn seeded_cache(name: &str, fixture: &Path) -> PathBuf {
    static SEEDED: std::sync::Mutex<Vec<String>> = std::sync::Mutex::new(Vec::new());
    let dir = std::env::temp_dir().join(name);
    let mut done = SEEDED.lock().unwrap_or_else(|e| e.into_inner());
    if done.iter().any(|d| d == name) {
        return dir;
    }
    done.push(name.to_string());
    std::fs::create_dir_all(&dir).unwrap();
    if std::env::var_os("RDAYLIGHT_RCALIB_NO_SEED").is_some() {
        return dir;
    }
    for e in std::fs::read_dir(fixture).into_iter().flatten().flatten() {
        let to = dir.join(e.file_name());
        if !to.exists() {
            let tmp = dir.join(format!(
                ".seed-{}-{}",
                std::process::id(),
                e.file_name().to_string_lossy()
            ));
            std::fs::copy(e.path(), &tmp).unwrap();
            std::fs::rename(&tmp, &to).unwrap();
        }
    }
    dir
}
