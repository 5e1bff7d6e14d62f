//! `--help` and `--version` in every tool and every subcommand (issue #21: `--version` was
//! refused by every clap subcommand, e.g. `rcalib compare --version`, and nothing checked
//! the subcommands). The tools and subcommands come from `rdaylight::cli::commands()`, the
//! clap definitions of every tool, so a new subcommand is covered without touching this
//! file.

mod common;
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
