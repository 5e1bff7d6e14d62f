//! Inline commands: `!command` lines in scene files and `!command` scene inputs.
//!
//! Radiance (`src/common/readobj.c:readobj`) hands the rest of a `!` line (joined across
//! backslash-newlines by `fgetline.c`, the backslash-newline kept for the shell) to `popen`,
//! i.e. `/bin/sh -c`, and reads the command's standard output as more scene text. We do the
//! same with two deliberate differences:
//! - the working directory is the folder of the scene file that holds the line (Radiance uses
//!   the process's current directory), so a scene and its `.cal`/`.dat` helpers move together;
//! - a non-zero exit status is an error here (Radiance only warns "bad status"), because a
//!   half-written generator output is a silently wrong scene.
//!
//! A command's output is scene text held in memory, so it is bounded: more than
//! [`MAX_OUTPUT`] bytes on standard output is an error (the command is killed), and at most
//! [`MAX_STDERR`] bytes of its standard error are kept for messages (issue #19: `!yes` made
//! `rinfo` run out of memory, `!head -c 3000000000 /dev/zero` aborted it).
//!
//! Commands can be refused for untrusted scenes ([`super::LoadOptions::allow_exec`], default
//! from `RDAYLIGHT_NO_EXEC`); the error then says how to expand the scene by hand.

use std::io::Read;
use std::path::Path;
use std::process::{Command, Stdio};

use super::LoadOptions;
use crate::error::{Error, Location, Result};

/// The command as one readable line for messages and locations: backslash-newlines and runs
/// of white space become single spaces; very long commands are shortened.
pub fn display_command(cmd: &str) -> String {
    let joined = cmd.replace("\\\r\n", " ").replace("\\\n", " ");
    let mut one: String = joined.split_whitespace().collect::<Vec<_>>().join(" ");
    const MAX: usize = 100;
    if one.chars().count() > MAX {
        one = one.chars().take(MAX - 3).collect::<String>() + "...";
    }
    one
}

/// Most bytes of scene text one inline command may print (1 GiB). The largest generated
/// scenes we know (a million-polygon `obj2rad` conversion) are about 100 MB; the parsed
/// objects take several times the text's size, so a larger output would exhaust memory
/// before it could be traced anyway.
pub const MAX_OUTPUT: u64 = 1 << 30;

/// Bytes of a command's standard error kept for warnings and the failure message; the
/// rest is read and dropped so that the command does not block on a full pipe.
const MAX_STDERR: u64 = 1 << 20;

/// Run `cmd` (the text after `!`) with `sh -c` in `dir` and return its standard output.
/// `origin` is where the command came from, for error messages.
pub fn run(cmd: &str, dir: &Path, origin: &Location, opts: &LoadOptions) -> Result<String> {
    run_limited(cmd, dir, origin, opts, MAX_OUTPUT)
}

/// [`run`] with an output limit of `max_output` bytes.
fn run_limited(
    cmd: &str,
    dir: &Path,
    origin: &Location,
    opts: &LoadOptions,
    max_output: u64,
) -> Result<String> {
    let shown = display_command(cmd);
    if !opts.allow_exec {
        return Err(Error::parse(
            origin.clone(),
            format!(
                "refused to run inline command '!{shown}' (--no-exec or RDAYLIGHT_NO_EXEC is set); \
                 to expand the scene, run the command yourself and include its output in place \
                 of the '!' line"
            ),
        ));
    }
    let mut c = Command::new("sh");
    c.arg("-c").arg(cmd);
    // An empty dir means "the current directory" (a bare file name's parent is "").
    if !dir.as_os_str().is_empty() {
        c.current_dir(dir);
    }
    for (k, v) in &opts.command_env {
        c.env(k, v);
    }
    // Commands get no standard input: the scene itself may be arriving on ours.
    c.stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let cannot = |e: std::io::Error| {
        Error::parse(
            origin.clone(),
            format!("cannot run command '!{shown}': {e}"),
        )
    };
    let mut child = c.spawn().map_err(cannot)?;
    // Standard error is drained on a thread while standard output is read here, so that
    // neither pipe can fill up and stall the command.
    let mut err_pipe = child.stderr.take().expect("stderr is piped");
    let err_reader = std::thread::spawn(move || {
        let mut kept = Vec::new();
        let _ = (&mut err_pipe).take(MAX_STDERR).read_to_end(&mut kept);
        let _ = std::io::copy(&mut err_pipe, &mut std::io::sink());
        kept
    });
    let mut stdout = Vec::new();
    let read = child
        .stdout
        .take()
        .expect("stdout is piped")
        .take(max_output + 1)
        .read_to_end(&mut stdout);
    if read.is_ok() && stdout.len() as u64 > max_output {
        // Not an error of the command's own: stop it (it may never end, like `!yes`).
        let _ = child.kill();
        let _ = child.wait();
        // Not joined: a pipeline's other processes may hold standard error open a moment
        // longer (they end on the closed output pipe); the thread ends with them.
        drop(err_reader);
        return Err(Error::parse(
            origin.clone(),
            format!(
                "command '!{shown}' printed more than {max_output} bytes of scene text \
                 (the limit for one inline command); run it yourself and check its output"
            ),
        ));
    }
    read.map_err(cannot)?;
    let status = child.wait().map_err(cannot)?;
    let err_bytes = err_reader.join().unwrap_or_default();
    let out = std::process::Output {
        status,
        stdout,
        stderr: err_bytes,
    };
    let stderr = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() {
        let last = stderr
            .lines()
            .rev()
            .find(|l| !l.trim().is_empty())
            .unwrap_or("")
            .trim();
        let status = match out.status.code() {
            Some(code) => format!("exit status {code}"),
            None => "killed by a signal".to_string(),
        };
        let detail = if last.is_empty() {
            String::new()
        } else {
            format!(": {last}")
        };
        return Err(Error::parse(
            origin.clone(),
            format!("command '!{shown}' failed ({status}){detail}"),
        ));
    }
    // Generators print warnings on stderr; pass them on, as Radiance's popen would.
    if !stderr.trim().is_empty() {
        eprint!("{stderr}");
    }
    Ok(String::from_utf8_lossy(&out.stdout).into_owned())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn display_joins_continuations() {
        assert_eq!(
            display_command("genbox white \\\n  box 1 1 1 "),
            "genbox white box 1 1 1"
        );
        let long = "x ".repeat(200);
        assert!(display_command(&long).ends_with("...") && display_command(&long).len() == 100);
    }

    /// Issue #19: `!yes` in a scene filled memory; output beyond the limit is an error
    /// that names the command and the limit, and the endless command is stopped.
    #[test]
    fn endless_output_is_an_error() {
        let opts = LoadOptions {
            allow_exec: true,
            command_env: Vec::new(),
        };
        let at = Location::line("big.rad", 3);
        let e = run_limited("yes", Path::new(""), &at, &opts, 1000)
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("big.rad:3: ") && e.contains("'!yes'"), "{e}");
        assert!(e.contains("more than 1000 bytes"), "{e}");
        let ok = run_limited("printf 12345", Path::new(""), &at, &opts, 5).unwrap();
        assert_eq!(ok, "12345");
    }
}
