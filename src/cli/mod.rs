//! What every binary shares: error reporting and exit codes, in the ripgrep manner. (Atomic
//! output and terminal checks are [`crate::io`], a layer below the tools.)
//!
//! A binary's `main` is `fn main() { rdaylight::cli::run("rmtx", real_main) }`: errors print one
//! line `rmtx: file:line: message` on stderr and exit with status 1; a closed output pipe is a
//! normal end (status 0), as it is for Radiance's own programs in `| head`.

pub mod glare;
pub mod glare_annual;
pub mod manual;
pub mod progress;
pub mod rcalib;
pub mod rdc;
pub mod rglod;
pub mod rinfo;
pub mod rmcop;
pub mod rmetrics;
pub mod rmtx;
pub mod rrecon;
pub mod rspecsky;
pub mod ruplift;

use crate::error::Error;
use std::io::Write;

/// Every tool's command line as clap describes it, subcommands included, with those parsed
/// apart attached (`rglare annual`, `rspecsky genssky`): what `--help`, the man pages and
/// the shell completions are made of. One entry per binary, in the README's order.
pub fn commands() -> Vec<clap::Command> {
    use clap::CommandFactory;
    vec![
        rdc::Options::command(),
        rspecsky::Options::command().subcommand(rspecsky::GensskyArgs::command().name("genssky")),
        rmtx::Options::command(),
        rmetrics::Options::command(),
        rinfo::Options::command(),
        glare::command(),
        ruplift::Cli::command(),
        rcalib::Cli::command(),
        rrecon::Cli::command(),
        rglod::Options::command(),
        rmcop::Options::command(),
    ]
}

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

/// Radiance spells some options with two letters after one dash (`-ab 5`, `-cs 18`), which
/// clap can only take as long options: every argument equal to `-NAME` for a `NAME` in
/// `names` becomes `--NAME`, up to a `--` after which everything is an operand. The one
/// rewrite every tool with Radiance's letters shares.
pub fn long_spellings<S: AsRef<str>>(
    args: impl IntoIterator<Item = S>,
    names: &[&str],
) -> Vec<String> {
    let mut operands = false;
    args.into_iter()
        .map(|a| {
            let a = a.as_ref();
            operands |= a == "--";
            match a.strip_prefix('-') {
                Some(n) if !operands && names.contains(&n) => format!("--{n}"),
                _ => a.to_string(),
            }
        })
        .collect()
}

/// clap's parser for every real-valued option: Rust's `f64` parsing takes `nan`, `inf` and
/// `1e999`, which no option means (issue #19: `rmtx -s inf` and `rdc -cw 380 inf` were
/// accepted); clap turns the message into `invalid value 'nan' for '-s <F>': ...`.
pub fn finite(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err("expected a finite number".into()),
        Err(e) => Err(e.to_string()),
    }
}

/// clap's parser for a count with an upper bound (issue #19: every count a user can type is
/// bounded): a whole number from 0 to `MAX`; the option's help says why its bound is what
/// it is.
pub fn at_most<const MAX: usize>(s: &str) -> Result<usize, String> {
    match s.trim().parse::<usize>() {
        Ok(v) if v <= MAX => Ok(v),
        Ok(v) => Err(format!("{v} is more than the limit {MAX}")),
        Err(_) => Err(format!("expected a whole number from 0 to {MAX}")),
    }
}

/// `command` without the options `names` and their values (either spelling: `--x v` or
/// `--x=v`), up to a `--`. Options that only say which piece of a run this is (`--shard`,
/// `--hours`, `--manifest`) are left out of headers, so every piece names the whole run's
/// command and the merge restores its header line for line.
pub fn without_options(command: &[String], names: &[&str]) -> Vec<String> {
    let mut out = Vec::with_capacity(command.len());
    let mut skip_next = false;
    for (i, a) in command.iter().enumerate() {
        if skip_next {
            skip_next = false;
            continue;
        }
        if a == "--" {
            out.extend(command[i..].iter().cloned());
            break;
        }
        let inline = a.split_once('=').is_some_and(|(n, _)| names.contains(&n));
        if names.contains(&a.as_str()) {
            skip_next = true;
        } else if !inline {
            out.push(a.clone());
        }
    }
    out
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
    let mut lines = text.lines().map(str::trim).filter(|l| !l.is_empty());
    let mut first = lines
        .next()
        .unwrap_or("bad command line")
        .trim_start_matches("error: ")
        .to_string();
    // "the following required arguments were not provided:" names them on the next line.
    if first.ends_with(':') {
        if let Some(next) = lines.next().filter(|l| !l.starts_with("Usage:")) {
            first = format!("{first} {next}");
        }
    }
    Error::Usage(first)
}

#[cfg(test)]
mod tests {
    use clap::Parser;

    #[derive(Parser, Debug)]
    struct Needs {
        #[arg(long, required = true)]
        effect: String,
    }

    /// clap names the missing arguments on its second line: the one line keeps them.
    #[test]
    fn missing_arguments_are_named() {
        let e = super::parse_or_exit::<Needs>(vec!["t".into()]).unwrap_err();
        assert_eq!(
            e.to_string(),
            "the following required arguments were not provided: --effect <EFFECT>"
        );
    }

    #[test]
    fn long_spellings_stop_at_the_operands() {
        let got = super::long_spellings(["x", "-ab", "5", "--ab", "-abc", "--", "-ab"], &["ab"]);
        assert_eq!(got, ["x", "--ab", "5", "--ab", "-abc", "--", "-ab"]);
    }
}
