//! Output that never leaves a file half-written, and what the writers need to know about
//! the streams they write to.

use crate::error::Error;
use std::io::{IsTerminal, Write};

/// Progress on stderr only when a person is watching (stderr is a terminal).
pub fn show_progress() -> bool {
    std::io::stderr().is_terminal()
}

/// True when standard output is a regular file. Radiance's `fputformat` pads `FORMAT=` so
/// binary data starts aligned only when `ftell` works (a seekable file), never in pipes; our
/// writers do the same, so their bytes match Radiance's in both cases.
pub fn stdout_is_file() -> bool {
    #[cfg(unix)]
    {
        use std::os::fd::AsFd;
        std::io::stdout()
            .as_fd()
            .try_clone_to_owned()
            .map(std::fs::File::from)
            .and_then(|f| f.metadata())
            .is_ok_and(|m| m.is_file())
    }
    #[cfg(not(unix))]
    {
        false
    }
}

/// A temporary name beside `path` (same directory, so a rename replaces it atomically):
/// `.name.PID.N.part`, N counting the calls in this process, so threads writing the same
/// target (e.g. two tests filling one cache) never share a temporary file.
pub fn temp_beside(path: &std::path::Path) -> std::path::PathBuf {
    static CALLS: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let n = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(std::path::Path::new("."));
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    dir.join(format!(".{name}.{}.{n}.part", std::process::id()))
}

/// Write a file atomically: the data goes to a temporary file beside the target which is
/// renamed over it only once everything was written, so a failed run leaves nothing
/// half-written behind.
pub fn write_atomically(
    path: &std::path::Path,
    f: impl FnOnce(&mut dyn Write) -> Result<(), Error>,
) -> Result<(), Error> {
    let shown = path.display().to_string();
    let tmp = temp_beside(path);
    let result = (|| {
        let file = std::fs::File::create(&tmp).map_err(|e| Error::io(&shown, e))?;
        let mut w = std::io::BufWriter::new(file);
        f(&mut w)?;
        w.flush().map_err(|e| Error::io(&shown, e))?;
        std::fs::rename(&tmp, path).map_err(|e| Error::io(&shown, e))
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// The end of a streamed atomic write (rdc's `--reweight` and `--se-out` files, written row
/// by row to [`temp_beside`]): `closed` is the outcome of flushing and closing the
/// temporary file; then it is renamed over `path`. On any failure the temporary file is
/// removed, so nothing half-written stays behind (issue #19: a target that could not be
/// replaced left `.part` files).
pub fn replace_with(
    tmp: &std::path::Path,
    path: &str,
    closed: std::io::Result<()>,
) -> Result<(), Error> {
    let done = closed
        .and_then(|()| std::fs::rename(tmp, path))
        .map_err(|e| Error::io(path, e));
    if done.is_err() {
        let _ = std::fs::remove_file(tmp);
    }
    done
}
