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
    #[error("{loc}: {}", readable(msg))]
    Parse { loc: Location, msg: String },
    /// Input that is well formed but that this tool does not model (yet).
    #[error("{loc}: unsupported {}", readable(what))]
    Unsupported { loc: Location, what: String },
    /// Two inputs that cannot be combined (shapes, bases, channel counts).
    #[error("{}", readable(.0))]
    Mismatch(String),
    /// An I/O failure on a named file or stream.
    #[error("{path}: {source}")]
    Io {
        path: String,
        #[source]
        source: std::io::Error,
    },
    /// Anything else that is the user's to fix (bad option values and the like).
    #[error("{}", readable(.0))]
    Usage(String),
}

/// Longest piece of quoted input an error shows (characters, `...` included).
pub const MAX_QUOTED: usize = 80;
/// Longest run of non-blank characters an error shows outside quotes (paths included).
const MAX_WORD: usize = 240;
/// Longest message: beyond it the middle is cut, keeping what was found (the start) and
/// what was expected (the end).
const MAX_MESSAGE: usize = 1000;

/// `s` cut to at most `max` characters, ending in `...` when cut.
fn cut(s: &str, max: usize) -> String {
    if s.chars().count() <= max {
        return s.to_string();
    }
    let mut t: String = s.chars().take(max.saturating_sub(3)).collect();
    t.push_str("...");
    t
}

/// A piece of the user's input for an error message: at most [`MAX_QUOTED`] characters,
/// control characters escaped, so a binary line or a 50 KB token stays one readable line.
pub fn quoted(s: &str) -> String {
    cut(&escape_controls(s), MAX_QUOTED)
}

/// Control characters (a binary file's bytes, a stray carriage return) as `\u{..}`
/// escapes: an error must stay one line and must not drive the terminal.
fn escape_controls(s: &str) -> String {
    if !s.chars().any(char::is_control) {
        return s.to_string();
    }
    s.chars()
        .map(|c| {
            if c.is_control() {
                c.escape_default().to_string()
            } else {
                c.to_string()
            }
        })
        .collect()
}

/// Every message as it is printed (issue #19: errors echoed whole binary lines and 50 KB
/// tokens). Errors are built in hundreds of places, most of them quoting what they found
/// as `'...'`; this is the one place that bounds them all: a quoted span (opened by a `'`
/// after a blank or an opening bracket, closed by one not followed by a letter or digit, so the
/// apostrophe of "rtrace's" is not a quote) longer than [`MAX_QUOTED`] is cut, then any
/// word longer than `MAX_WORD` and the whole message beyond `MAX_MESSAGE`.
fn readable(msg: &str) -> std::borrow::Cow<'_, str> {
    let short = msg.len() <= MAX_QUOTED && !msg.chars().any(char::is_control);
    if short {
        return std::borrow::Cow::Borrowed(msg);
    }
    let chars: Vec<char> = escape_controls(msg).chars().collect();
    let alnum = |k: usize| chars.get(k).is_some_and(|c| c.is_alphanumeric());
    let mut out = String::with_capacity(msg.len().min(2 * MAX_MESSAGE));
    let mut i = 0;
    while i < chars.len() {
        // A quote opens after a blank, the start or an opening bracket, `=`, `:` or `,`,
        // never right after another quote: a quoted command that ends in its own quote
        // (`'!echo 'x''`) must not open a span over the rest of the message.
        let opens = chars[i] == '\''
            && (i == 0 || chars[i - 1].is_whitespace() || "([{=:,".contains(chars[i - 1]));
        let close = opens
            .then(|| (i + 1..chars.len()).find(|&j| chars[j] == '\'' && !alnum(j + 1)))
            .flatten();
        if let Some(j) = close {
            let inner: String = chars[i + 1..j].iter().collect();
            out.push('\'');
            out.push_str(&cut(&inner, MAX_QUOTED));
            out.push('\'');
            i = j + 1;
        } else {
            out.push(chars[i]);
            i += 1;
        }
    }
    let words: Vec<String> = out.split(' ').map(|w| cut(w, MAX_WORD)).collect();
    let joined = words.join(" ");
    let n = joined.chars().count();
    if n <= MAX_MESSAGE {
        return std::borrow::Cow::Owned(joined);
    }
    let head: String = joined.chars().take(MAX_MESSAGE / 2).collect();
    let tail: String = joined.chars().skip(n - MAX_MESSAGE / 2 + 5).collect();
    std::borrow::Cow::Owned(format!("{head} ... {tail}"))
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

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_quote_ending_in_a_quote_opens_no_span_over_the_rest() {
        let tail = " (--no-exec is set); run the command yourself and put its output in place \
                    of the '!' line";
        let msg = format!("s.rad:3: refused to run '!echo 'x sphere s 0 0 4 0 0 0 1''{tail}");
        assert_eq!(Error::Usage(msg.clone()).to_string(), msg);
    }

    #[test]
    fn quoted_input_is_cut_and_escaped() {
        let token = "x".repeat(50_000);
        let e = Error::parse(
            Location::line("a.rad", 3),
            format!("found '{token}'; expected a number"),
        );
        let s = e.to_string();
        assert!(s.len() < 120, "{s}");
        assert!(
            s.starts_with("a.rad:3: found 'xxx") && s.ends_with("...'; expected a number"),
            "{s}"
        );
        let s = Error::Usage("bad byte '\u{1b}[2J\0' in rtrace's input".into()).to_string();
        assert_eq!(s, "bad byte '\\u{1b}[2J\\u{0}' in rtrace's input");
        // Apostrophes are not quotes; short messages pass unchanged.
        let m = format!("rtrace's and Radiance's {}", "y".repeat(100));
        assert_eq!(Error::Usage(m.clone()).to_string(), m);
        let long = "word ".repeat(1000);
        let s = Error::Usage(format!("{long}; expected the end")).to_string();
        assert!(
            s.chars().count() <= MAX_MESSAGE && s.ends_with("expected the end"),
            "{s}"
        );
        assert_eq!(quoted(&"z".repeat(100)).chars().count(), MAX_QUOTED);
    }
}
