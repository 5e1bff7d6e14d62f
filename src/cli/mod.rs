//! What every binary shares: error reporting and exit codes, in the ripgrep manner. (Atomic
//! output and terminal checks are [`crate::io`], a layer below the tools.)
//!
//! A binary's `main` is `fn main() { rdaylight::cli::run("rmtx", real_main) }`: errors print one
//! line `rmtx: file:line: message` on stderr and exit with status 1; a closed output pipe is a
//! normal end (status 0), as it is for Radiance's own programs in `| head`.

pub mod glare;
pub mod glare_annual;
pub mod rcalib;
pub mod rdc;
pub mod rglod;
pub mod rinfo;
pub mod rmetrics;
pub mod rmtx;
pub mod rrecon;
pub mod rspecsky;
pub mod ruplift;

use crate::error::Error;
use std::io::Write;

pub fn run(prog: &str, f: impl FnOnce() -> Result<(), Error>) -> ! {
    let code = match f() {
        Ok(()) => 0,
        Err(e) if e.is_broken_pipe() => 0,
        Err(e) => {
            let _ = writeln!(std::io::stderr(), "{prog}: {e}");
            1
        }
    };
    let _ = std::io::stdout().flush();
    std::process::exit(code)
}

/// Parse `args` (program name first) with clap: `--help`/`--version` print and exit 0; an
/// error becomes one line (what clap says first) and status 1 like every other error (clap
/// alone would print a block and exit 2).
pub fn parse_or_exit<P: clap::Parser>(args: Vec<String>) -> Result<P, Error> {
    P::try_parse_from(args).map_err(usage_error)
}

/// The one convention for command-line errors in every tool: `--help`/`--version` print and
/// exit 0; anything else becomes a one-line [`Error::Usage`] (status 1 through [`run`]).
pub fn usage_error(e: clap::Error) -> Error {
    if !e.use_stderr() {
        e.exit()
    }
    let text = e.to_string();
    let first = text.lines().next().unwrap_or("bad command line");
    Error::Usage(first.trim_start_matches("error: ").to_string())
}
