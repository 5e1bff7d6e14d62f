//! One error type for the whole library.
//!
//! Every error that comes from reading user input carries a [`Location`] (file, line, and
//! column where known) so that the binaries can print the one-line form the house style asks
//! for: `scene.rad:42:7: polygon 'win_s' expects a multiple of 3 real arguments, found 11`.

use std::fmt;

/// Where in the user's input something went wrong.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Location {
    /// File name as the user gave it (`-` or `<stdin>` for standard input).
    pub file: String,
    /// 1-based line number, when the format is line oriented.
    pub line: Option<usize>,
    /// 1-based column, when known.
    pub col: Option<usize>,
}

impl Location {
    pub fn file(file: impl Into<String>) -> Self {
        Location {
            file: file.into(),
            line: None,
            col: None,
        }
    }
    pub fn line(file: impl Into<String>, line: usize) -> Self {
        Location {
            file: file.into(),
            line: Some(line),
            col: None,
        }
    }
    pub fn at(file: impl Into<String>, line: usize, col: usize) -> Self {
        Location {
            file: file.into(),
            line: Some(line),
            col: Some(col),
        }
    }
}

impl fmt::Display for Location {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let file = if self.file.is_empty() {
            "<input>"
        } else {
            &self.file
        };
        write!(f, "{file}")?;
        if let Some(l) = self.line {
            write!(f, ":{l}")?;
            if let Some(c) = self.col {
                write!(f, ":{c}")?;
            }
        }
        Ok(())
    }
}

#[derive(Debug, thiserror::Error)]
pub enum Error {
    /// Malformed input: the message says what was found and what was expected.
    #[error("{loc}: {msg}")]
    Parse { loc: Location, msg: String },
    /// Input that is well formed but that this tool does not model (yet).
    #[error("{loc}: unsupported {what}")]
    Unsupported { loc: Location, what: String },
    /// Two inputs that cannot be combined (shapes, bases, channel counts).
    #[error("{0}")]
    Mismatch(String),
    /// An I/O failure on a named file or stream.
    #[error("{path}: {source}")]
    Io {
        path: String,
        #[source]
        source: std::io::Error,
    },
    /// Anything else that is the user's to fix (bad option values and the like).
    #[error("{0}")]
    Usage(String),
}

impl Error {
    pub fn parse(loc: Location, msg: impl Into<String>) -> Self {
        Error::Parse {
            loc,
            msg: msg.into(),
        }
    }
    pub fn unsupported(loc: Location, what: impl Into<String>) -> Self {
        Error::Unsupported {
            loc,
            what: what.into(),
        }
    }
    pub fn io(path: impl Into<String>, source: std::io::Error) -> Self {
        Error::Io {
            path: path.into(),
            source,
        }
    }
    /// True when the error is a closed output pipe (`rdc ... | head`), which is a normal end.
    pub fn is_broken_pipe(&self) -> bool {
        matches!(self, Error::Io { source, .. } if source.kind() == std::io::ErrorKind::BrokenPipe)
    }
}

pub type Result<T, E = Error> = std::result::Result<T, E>;

/// Most threads a user may ask for (`-n` of rdc, rglod, rcalib, rspecsky genssky): beyond
/// the cores, threads only cost memory (`-n 100000` started 100,000 threads, issue #19).
pub const MAX_THREADS: usize = 1024;

/// The one form of every bound on a count or size a user types (issue #19: `-ad` in the
/// quintillions ran for ever, `-x`/`-y` in the hundreds of millions aborted on allocation):
/// `value` above `max` is a usage error `OPTION VALUE: at most MAX (WHY)`.
pub fn at_most(option: &str, value: u64, max: u64, why: &str) -> Result<()> {
    if value > max {
        return Err(Error::Usage(format!(
            "{option} {value}: at most {max} ({why})"
        )));
    }
    Ok(())
}

/// Attach a path to a bare `std::io::Error`.
pub trait IoContext<T> {
    fn at_path(self, path: &str) -> Result<T>;
}

impl<T> IoContext<T> for std::io::Result<T> {
    fn at_path(self, path: &str) -> Result<T> {
        self.map_err(|e| Error::io(path, e))
    }
}
