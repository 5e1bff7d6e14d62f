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
//! Commands can be refused for untrusted scenes ([`super::LoadOptions::allow_exec`], default
//! from `RDAYLIGHT_NO_EXEC`); the error then says how to expand the scene by hand.

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

/// Run `cmd` (the text after `!`) with `sh -c` in `dir` and return its standard output.
/// `origin` is where the command came from, for error messages.
pub fn run(cmd: &str, dir: &Path, origin: &Location, opts: &LoadOptions) -> Result<String> {
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
    let out = c.output().map_err(|e| {
        Error::parse(
            origin.clone(),
            format!("cannot run command '!{shown}': {e}"),
        )
    })?;
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
}
