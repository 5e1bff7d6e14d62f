//! `--help` and `--version` in every tool and every subcommand (issue #21: `--version` was
//! refused by every clap subcommand, e.g. `rcalib compare --version`, and nothing checked
//! the subcommands), man pages and shell completions. The tools and subcommands come from
//! `rdaylight::cli::commands()`, the clap definitions the man pages and completions are
//! made from, so a new subcommand is covered without touching this file.

use crate::common;
use common::{ours, run};

/// Every (binary, subcommand path) pair: `[]` for the tool itself.
fn invocations() -> Vec<(String, Vec<String>)> {
    fn walk(cmd: &clap::Command, path: Vec<String>, out: &mut Vec<Vec<String>>) {
        out.push(path.clone());
        for sub in cmd.get_subcommands() {
            // clap's own `help` subcommand takes subcommand names, not options.
            if sub.get_name() == "help" || sub.is_hide_set() {
                continue;
            }
            let mut p = path.clone();
            p.push(sub.get_name().to_string());
            walk(sub, p, out);
        }
    }
    let mut all = Vec::new();
    for cmd in rdaylight::cli::commands() {
        let mut paths = Vec::new();
        walk(&cmd, Vec::new(), &mut paths);
        for p in paths {
            all.push((cmd.get_name().to_string(), p));
        }
    }
    all
}

#[test]
fn every_binary_is_described() {
    let mut names: Vec<String> = rdaylight::cli::commands()
        .iter()
        .map(|c| c.get_name().to_string())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            "rcalib", "rdc", "rglare", "rglod", "rinfo", "rmcop", "rmetrics", "rmtx", "rrecon",
            "rspecsky", "ruplift"
        ]
    );
    // The subcommands parsed apart from clap are attached.
    let subs = invocations();
    for want in [
        ["rglare", "annual"],
        ["rspecsky", "genssky"],
        ["rcalib", "explain"],
    ] {
        assert!(
            subs.iter()
                .any(|(t, p)| t == want[0] && p == &[want[1].to_string()]),
            "{want:?} missing"
        );
    }
}

#[test]
fn help_and_version_everywhere() {
    let version = env!("CARGO_PKG_VERSION");
    for (tool, path) in invocations() {
        for flag in ["--help", "--version"] {
            let out = run(ours(&tool).args(&path).arg(flag), b"");
            let shown = format!("{tool} {} {flag}", path.join(" "));
            let stdout = String::from_utf8_lossy(&out.stdout);
            assert_eq!(
                out.status.code(),
                Some(0),
                "{shown}: {}",
                String::from_utf8_lossy(&out.stderr)
            );
            assert!(out.stderr.is_empty(), "{shown}: nothing on stderr");
            if flag == "--version" {
                assert!(
                    stdout.lines().count() == 1 && stdout.trim_end().ends_with(version),
                    "{shown}: {stdout}"
                );
            } else {
                assert!(
                    stdout.contains("Usage:") || stdout.contains("usage:"),
                    "{shown}: {stdout}"
                );
                // A tool's help names its subcommands (rspecsky's did not list genssky).
                if path.is_empty() {
                    for (t, p) in invocations() {
                        if t == tool && p.len() == 1 {
                            assert!(
                                stdout.contains(&format!("{tool} {}", p[0]))
                                    || stdout.contains(&format!("  {}", p[0])),
                                "{shown} does not name its subcommand {}",
                                p[0]
                            );
                        }
                    }
                }
            }
        }
    }
}

/// `rglare` and `rglare annual` are parsed by hand (evalglare's letters, view options,
/// options passed on to rdc): every option their clap description names must be one the
/// parser takes, so the help, the man page and the completions do not promise what the
/// tool refuses.
#[test]
fn rglare_descriptions_match_the_parsers() {
    let cmds = rdaylight::cli::commands();
    let rglare = cmds.iter().find(|c| c.get_name() == "rglare").unwrap();
    for arg in rglare.get_arguments() {
        let Some(s) = arg.get_short() else { continue };
        let n = arg.get_num_args().map_or(1, |r| r.min_values().max(1));
        let mut args = vec![format!("-{s}")];
        if arg.get_action().takes_values() {
            let v = match s {
                'C' => "l+",
                _ => "1",
            };
            args.extend(std::iter::repeat_n(v.to_string(), n));
        }
        let r = rdaylight::cli::glare::Args::parse(&args);
        assert!(
            !matches!(&r, Err(e) if e.to_string().contains("unknown")),
            "rglare {args:?}: {r:?}"
        );
    }
    let annual = rglare.find_subcommand("annual").unwrap();
    for arg in annual.get_arguments() {
        let id = arg.get_id().as_str();
        if ["help", "version", "cat", "manifests", "scene"].contains(&id) {
            continue;
        }
        let name = match (arg.get_short(), arg.get_long()) {
            (Some(s), _) => format!("-{s}"),
            (None, Some(l)) => format!("--{l}"),
            (None, None) => panic!("{id}: an option without a name"),
        };
        // A whole command line but for the option; one the parser does not know goes on
        // to rdc, whose clap then names it.
        let mut args: Vec<String> = ["-w", "w.epw", "-vta", "-vh", "180", "-vv", "180"]
            .map(String::from)
            .to_vec();
        args.push(name);
        if arg.get_action().takes_values() {
            args.push(match id {
                "ev" => "rays".into(),
                "low-light" => "l+".into(),
                "occupied" => "8-18".into(),
                "shard" => "0/1".into(),
                "jan1" => "Monday".into(),
                _ => "1".into(),
            });
        }
        args.push("room.rad".into());
        let r = rdaylight::cli::glare_annual::AnnualArgs::parse(&args);
        assert!(
            !matches!(&r, Err(e) if e.to_string().contains("rdc options")),
            "rglare annual {args:?}: {r:?}"
        );
    }
    // The check means something: an option nobody knows is named as rdc's.
    let bogus = [
        "-w", "w.epw", "-vta", "-vh", "180", "-vv", "180", "--bogus", "room.rad",
    ]
    .map(String::from);
    let r = rdaylight::cli::glare_annual::AnnualArgs::parse(&bogus);
    assert!(
        matches!(&r, Err(e) if e.to_string().contains("rdc options")),
        "{r:?}"
    );
    let r = rdaylight::cli::glare::Args::parse(&["-Z".to_string()]);
    assert!(
        matches!(&r, Err(e) if e.to_string().contains("unknown")),
        "{r:?}"
    );
}

/// Man pages (issue #21): one per tool with NAME, SYNOPSIS, its options and an EXAMPLES
/// section of real pipelines, and one per subcommand; `man -l` renders each without a
/// warning where `man` is installed.
#[test]
fn man_pages_for_every_tool_and_subcommand() {
    let d = common::tmpdir();
    let files = rdaylight::cli::manual::write_man_pages(d.path()).unwrap();
    for (tool, path) in invocations() {
        let page = if path.is_empty() {
            tool.clone()
        } else {
            format!("{tool}-{}", path.join("-"))
        };
        let file = d.path().join(format!("{page}.1"));
        assert!(files.contains(&file), "{page}.1 not written");
        let text = std::fs::read_to_string(&file).unwrap();
        for section in [
            ".SH NAME",
            ".SH SYNOPSIS",
            ".SH \"EXIT STATUS\"",
            ".SH \"SEE ALSO\"",
        ] {
            assert!(text.contains(section), "{page}.1 has no {section}");
        }
        if path.is_empty() {
            assert!(text.contains(".SH EXAMPLES"), "{page}.1 has no EXAMPLES");
            // Real pipelines: the tool among others, joined by a pipe or by files.
            let examples = &text[text.find(".SH EXAMPLES").unwrap()..];
            assert!(
                examples.contains(&format!("{tool} ")),
                "{page}.1: {examples}"
            );
            assert!(
                examples.contains(" | ") || examples.lines().any(|l| l.ends_with('|')),
                "{page}.1: no pipeline in EXAMPLES"
            );
        }
    }
    // The options of a clap tool and of a hand-parsed one are there.
    let rdc = std::fs::read_to_string(d.path().join("rdc.1")).unwrap();
    assert!(
        rdc.contains("\\-\\-ab") && rdc.contains("\\-\\-no\\-exec"),
        "{rdc}"
    );
    let annual = std::fs::read_to_string(d.path().join("rglare-annual.1")).unwrap();
    assert!(
        annual.contains("\\-\\-views") && annual.contains("EN 17037"),
        "{annual}"
    );

    let Ok(probe) = std::process::Command::new("man").arg("--version").output() else {
        eprintln!("man_pages_for_every_tool_and_subcommand: no man(1); rendering not checked");
        return;
    };
    if !probe.status.success() {
        return;
    }
    for file in &files {
        let out = std::process::Command::new("man")
            .arg("-l")
            .arg(file)
            .env("MANWIDTH", "80")
            .env("MAN_KEEP_FORMATTING", "0")
            .output()
            .unwrap();
        // Bold and underline come as overstrikes (`N\x08N`) when man writes to a pipe.
        let mut shown = String::new();
        for c in String::from_utf8_lossy(&out.stdout).chars() {
            if c == '\x08' {
                shown.pop();
            } else {
                shown.push(c);
            }
        }
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "man -l {}: {err}", file.display());
        assert!(err.trim().is_empty(), "man -l {}: {err}", file.display());
        for section in ["NAME", "SYNOPSIS", "EXIT STATUS"] {
            assert!(shown.contains(section), "{}: {shown}", file.display());
        }
    }
}

/// Shell completions (bash, zsh, fish) for every tool; bash's parse where bash is installed.
#[test]
fn shell_completions_for_every_tool() {
    let d = common::tmpdir();
    let files = rdaylight::cli::manual::write_completions(d.path()).unwrap();
    for cmd in rdaylight::cli::commands() {
        let tool = cmd.get_name();
        for (dir, name) in [
            ("bash", tool.to_string()),
            ("zsh", format!("_{tool}")),
            ("fish", format!("{tool}.fish")),
        ] {
            let f = d.path().join(dir).join(&name);
            assert!(files.contains(&f), "{dir}/{name} not written");
            let text = std::fs::read_to_string(&f).unwrap();
            assert!(text.contains(tool), "{dir}/{name}");
        }
        let bash = d.path().join("bash").join(tool);
        if let Ok(out) = std::process::Command::new("bash")
            .arg("-n")
            .arg(&bash)
            .output()
        {
            assert!(
                out.status.success(),
                "bash -n {tool}: {}",
                String::from_utf8_lossy(&out.stderr)
            );
        }
    }
    // Subcommands are completed.
    let fish = std::fs::read_to_string(d.path().join("fish/rcalib.fish")).unwrap();
    assert!(fish.contains("explain"), "{fish}");
}

/// Progress (issue #21): nothing on standard error in a pipe; on a terminal the stages are
/// drawn there in the shared wording, and standard output has the same bytes either way.
/// The terminal is `script`'s pseudo-terminal, where util-linux is installed.
#[test]
fn progress_is_drawn_on_a_terminal_only_and_never_touches_the_output() {
    let d = common::tmpdir();
    let room = common::repo().join("examples/room");
    let args = format!(
        "-I -h -ab 2 -ad 4096 -lw 1e-3 -m 1 -faf {} {}",
        room.join("room.rad").display(),
        room.join("skydome.rad").display()
    );
    let sensors = std::fs::read(room.join("sensors.pts")).unwrap();
    let piped = run(ours("rdc").args(args.split(' ')), &sensors);
    assert!(piped.status.success());
    assert!(
        piped.stderr.is_empty(),
        "{}",
        String::from_utf8_lossy(&piped.stderr)
    );
    let Ok(probe) = std::process::Command::new("script")
        .arg("--version")
        .output()
    else {
        eprintln!("progress test: no script(1); the terminal case is not checked");
        return;
    };
    if !probe.status.success() {
        return;
    }
    let out = d.path().join("dc.mtx");
    let cmd = format!(
        "{} {args} < {} > {}",
        env!("CARGO_BIN_EXE_rdc"),
        room.join("sensors.pts").display(),
        out.display()
    );
    let tty = std::process::Command::new("script")
        .args(["-qfec", &cmd, "/dev/null"])
        .env("TERM", "xterm")
        .stdin(std::process::Stdio::null())
        .output()
        .unwrap();
    assert!(
        tty.status.success(),
        "{}",
        String::from_utf8_lossy(&tty.stderr)
    );
    let drawn = String::from_utf8_lossy(&tty.stdout);
    assert!(drawn.contains("rdc: tracing"), "{drawn}");
    assert!(drawn.contains("/165 records, "), "{drawn}");
    // -h: no header, so no time stamps; the matrix has the piped run's bytes.
    assert_eq!(std::fs::read(&out).unwrap(), piped.stdout);
}
