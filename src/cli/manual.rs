//! # Man pages and shell completions, made from the clap definitions
//!
//! Radiance has one manual page per program whose EXAMPLES are real pipelines (style.md);
//! ours are generated from the same clap definitions `--help` prints ([`super::commands`]),
//! so the two cannot drift apart. `cargo run -p xtask -- man DIR` and `-- completions DIR`
//! write them; `make install` puts them where `man` and the shells look.
//!
//! A tool's page has clap_mangen's NAME, SYNOPSIS, DESCRIPTION, OPTIONS and SUBCOMMANDS, then
//! EXAMPLES: the pipelines of [`pipelines`] (commands of the Makefile's jobs and the README,
//! the tool among the others it works with) followed by the examples of its `--help`; then
//! EXIT STATUS (the convention every tool shares, [`super::run`]), SEE ALSO and VERSION.
//! Each subcommand has its own page, `tool-sub(1)`, as git's do.

use clap::Command;
use std::io::Write;
use std::path::{Path, PathBuf};

/// Real pipelines per tool, from the Makefile's jobs and the README (paths as a user's,
/// the weather file `site.epw`). Every tool's page shows the main job and its own lines.
pub fn pipelines(tool: &str) -> &'static str {
    match tool {
        "rdc" => {
            "Daylight coefficients of the main job (make), then illuminance and metrics:
  rdc -I -ab 5 -ad 10000 -lw 1e-5 -s 1 -m 1 -faf room.rad skydome.rad < sensors.pts > dc.mtx
  rspecsky -m 1 -of site.epw > sky.smx
  rmtx -ff -c 47.4 119.9 11.6 dc.mtx sky.smx > illuminance.mtx
  rmetrics -w site.epw --pts sensors.pts -o metrics.tsv illuminance.mtx
The same product straight from rdc into rmtx and rmetrics, nothing on disk:
  rdc -I -ab 5 -ad 10000 -lw 1e-5 -m 1 -faf room.rad skydome.rad < sensors.pts |
      rmtx -ff -c 47.4 119.9 11.6 - sky.smx |
      rmetrics -w site.epw --pts sensors.pts -
Coefficients for Radiance's own gendaymtx and dctimestep:
  gendaymtx -m 1 -of site.wea > sky.smx
  rdc -I -ab 5 -ad 10000 -lw 1e-5 -m 1 -faf room.rad skydome.rad < sensors.pts > dc.mtx
  dctimestep dc.mtx sky.smx | rmtxop -fa -c 47.4 119.9 11.6 - > ill.txt
As array task K of N (Slurm, GNU parallel), merged into the unsharded run's bytes:
  rdc -I -ab 5 -ad 10000 -m 1 -faf --shard $K/3 --manifest m$K.json room.rad skydome.rad \\
      < sensors.pts > dc.$K.mtx
  rmtx --cat dc.0.mtx dc.1.mtx dc.2.mtx --manifests m0.json m1.json m2.json > dc.mtx"
        }
        "rspecsky" => {
            "The annual sky and sun-only matrices of the main job (make):
  rspecsky -m 1 -of site.epw > sky.smx
  rspecsky -m 6 -5 0.533 -d -of site.epw > sky_sun.smx
Spectral daylight (make spectral-example): 18 bands, times 18-band coefficients:
  rspecsky -cs 18 -m 1 -of site.epw > sky18.smx
  rmtx -ff dc18.mtx sky18.smx | rmetrics melanopic -w site.epw --pts sensors.pts -o medi.mtx -
A genssky sky for real Radiance's rtrace:
  rspecsky genssky 6 21 12 -a 51.15 -o 0.18 -m 0 -c 0.3 -p sky > sky/sky.rad
  oconv sky/sky.rad room.rad > room.oct; rtrace -h -I -cs 18 room.oct < sensors.pts"
        }
        "rmtx" => {
            "The main job's product (make): coefficients times skies, weighted to lux:
  rmtx -ff -c 47.4 119.9 11.6 dc.mtx sky.smx > illuminance.mtx
  rmtx -ff -c 47.4 119.9 11.6 sun.mtx sky_sun.smx > direct_sun.mtx
Streamed into rmetrics (make stream-10k), and back into Radiance's rmtxop:
  rmtx -ff -c 47.4 119.9 11.6 dc.mtx sky.smx | rmetrics -w site.epw --pts sensors.pts -
  rmtx -fc ill.mtx | rmtxop -fa - | head
Radiance's rcontrib coefficients with our sky:
  rcontrib -I+ -ab 5 -ad 10000 -lw 1e-5 -faf -y 165 -e MF:1 -f reinhart.cal -b rbin \\
      -bn Nrbins -m skyglow room.oct < sensors.pts > dc.mtx
  rmtx -c 47.4 119.9 11.6 dc.mtx sky.smx > ill.mtx"
        }
        "rmetrics" => {
            "The main job's metrics and maps (make):
  rmtx -ff -c 47.4 119.9 11.6 dc.mtx sky.smx > illuminance.mtx
  rmetrics -w site.epw --pts sensors.pts --direct-sun direct_sun.mtx \\
      --json metrics.json -o metrics.tsv illuminance.mtx
  rmetrics -w site.epw --pts sensors.pts --map DA --png DA.png illuminance.mtx > /dev/null
Ours against Radiance's (make radiance-example):
  dctimestep dc.mtx sky.smx | rmtxop -ff -c 47.4 119.9 11.6 - > radiance.mtx
  rmetrics -w site.epw --pts sensors.pts -o radiance.tsv radiance.mtx
  rmetrics compare radiance.tsv metrics.tsv
Melanopic m-EDI per sensor and hour (make spectral-example):
  rmtx -ff dc18.mtx sky18.smx | rmetrics melanopic -w site.epw --pts sensors.pts \\
      --summary melanopic.tsv --png medi_days.png -o medi.mtx -"
        }
        "rinfo" => {
            "What the main job reads, before the long run (make):
  rinfo room.rad sensors.pts site.epw
A matrix's size and range as it streams out of rmtx:
  rmtx -ff -c 47.4 119.9 11.6 dc.mtx sky.smx | rinfo --stats -
The permanent shell of a furnished room:
  rglod filter -l 0 room.rad | rinfo -"
        }
        "rglare" => {
            "A fisheye view rendered by rdc, then its glare:
  rdc -vta -vp 3 2 1.2 -vd 0 1 0 -vh 180 -vv 180 -x 512 -y 512 room.rad sky.rad | rglare
Radiance's rpict and our rglare, or our picture and Radiance's evalglare:
  rpict -vta -vp 3 2 1.2 -vd 0 1 0 -vh 180 -vv 180 -x 512 -y 512 room.oct | rglare -d
  rdc -vta -vp 3 2 1.2 -vd 0 1 0 -vh 180 -vv 180 room.rad sky.rad > eye.hdr; evalglare eye.hdr
Annual glare of one view over the weather year:
  rglare annual -w site.epw -vf view.vf -ab 2 room.rad > dgp.txt"
        }
        "ruplift" => {
            "Materials from an RGB colour into a spectral Radiance run:
  ruplift rgb 0.6 0.35 0.2 --name wall > wall.rad
  rdc -I -cs 18 -ab 4 -ad 4096 -m 1 -faf wall.rad room.rad skydome.rad < sensors.pts > dc18.mtx
Many colours at once, from another program's output:
  printf 'wall 0.6 0.35 0.2\\nfloor 0.3 0.25 0.2\\n' | ruplift batch - > materials.rad
Reflectances from a photo and masks, into the scene:
  ruplift photo room.jpg --mask mask.png --legend legend.csv > materials.rad
  rdc -I -ab 5 -ad 10000 -m 1 -faf materials.rad room.rad skydome.rad < sensors.pts > dc.mtx"
        }
        "rcalib" => {
            "Compare, explain, apply, compare again (make calib-example):
  rcalib compare model.rad --sensors sensors.csv --weather weather.wea \\
      --measured measured.csv --report before.html
  rcalib explain model.rad --sensors sensors.csv --weather weather.wea \\
      --measured measured.csv --report explain.html --effects-out effects.txt
  rcalib apply model.rad --sensors sensors.csv $(cat effects.txt) > calibrated.rad
  rcalib apply model.rad --sensors sensors.csv $(cat effects.txt) | rinfo -
  rcalib compare calibrated.rad --before model.rad --sensors sensors.csv \\
      --weather weather.wea --measured measured.csv --report after.html"
        }
        "rrecon" => {
            "A scan reconstructed in one pipe, checked, then the daylight study on it
(make recon-example):
  rrecon simulate rect.rad | rrecon --auto --json summary.json --review review - > recon.rad
  rrecon eval rect.rad recon.rad
  rdc -I -ab 4 -ad 4096 -lw 1e-4 -m 1 -faf recon.rad skydome.rad < sensors.pts > dc.mtx
  rmtx -ff -c 47.4 119.9 11.6 dc.mtx sky.smx | rmetrics -w site.epw --pts sensors.pts -"
        }
        "rglod" => {
            "Objects, levels and the per-level study of a furnished room (make glod-example):
  rglod objects room.rad > objects.tsv
  rglod plan room.rad > plan.svg
  rglod study -w site.epw --pts sensors.pts -ab 4 -ad 4096 -lw 1e-4 --maps glod room.rad
The permanent shell, and one level traced by rdc:
  rglod filter -l 0 room.rad | rinfo -
  rglod filter -l 2 room.rad > glod2.rad
  rdc -I -ab 5 -ad 10000 -lw 1e-5 -m 1 -faf glod2.rad skydome.rad < sensors.pts > dc2.mtx"
        }
        "rmcop" => {
            "After rglod, the GLoD x MCoP study (make glod-mcop-example):
  rmcop study -w site.epw --pts sensors.pts -o mcop room.rad | cut -f1,2,5
Draws spread over array tasks, then merged:
  rmcop study -w site.epw --pts sensors.pts --shard $K/8 --records draws$K.json room.rad
  rmcop merge -o mcop draws*.json"
        }
        _ => "",
    }
}

/// The tools' man pages (`tool.1`, and `tool-sub.1` for each subcommand) in `dir`, which is
/// created; returns the files written.
pub fn write_man_pages(dir: &Path) -> std::io::Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir)?;
    let mut written = Vec::new();
    for cmd in super::commands() {
        let tool = cmd.get_name().to_string();
        let mut cmd = cmd.disable_help_subcommand(true);
        cmd.build();
        write_pages(&cmd, &tool, dir, &mut written)?;
    }
    Ok(written)
}

fn write_pages(
    cmd: &Command,
    tool: &str,
    dir: &Path,
    written: &mut Vec<PathBuf>,
) -> std::io::Result<()> {
    let page = cmd.get_display_name().unwrap_or(cmd.get_name()).to_string();
    let path = dir.join(format!("{page}.1"));
    let mut f = std::io::BufWriter::new(std::fs::File::create(&path)?);
    man_page(cmd, tool, &mut f)?;
    f.flush()?;
    written.push(path);
    for sub in cmd.get_subcommands().filter(|s| !s.is_hide_set()) {
        write_pages(sub, tool, dir, written)?;
    }
    Ok(())
}

/// One page in roff: clap_mangen's sections, then ours.
pub fn man_page(cmd: &Command, tool: &str, w: &mut dyn Write) -> std::io::Result<()> {
    let is_tool = cmd.get_name() == tool;
    let man = clap_mangen::Man::new(cmd.clone()).manual("rdaylight");
    man.render_title(w)?;
    man.render_name_section(w)?;
    man.render_synopsis_section(w)?;
    man.render_description_section(w)?;
    if cmd.get_arguments().any(|a| !a.is_hide_set()) {
        man.render_options_section(w)?;
    }
    if cmd.has_subcommands() {
        man.render_subcommands_section(w)?;
    }
    let examples: Vec<String> = [
        if is_tool { pipelines(tool) } else { "" }.to_string(),
        cmd.get_after_help()
            .map(|h| help_examples(&h.to_string()))
            .unwrap_or_default(),
    ]
    .into_iter()
    .filter(|t| !t.trim().is_empty())
    .collect();
    if !examples.is_empty() {
        writeln!(w, ".SH EXAMPLES")?;
        for (k, text) in examples.iter().enumerate() {
            if k > 0 {
                writeln!(w, ".PP")?;
            }
            writeln!(w, ".nf")?;
            for line in text.lines() {
                writeln!(w, "{}", roff_line(line))?;
            }
            writeln!(w, ".fi")?;
        }
    }
    writeln!(w, ".SH \"EXIT STATUS\"")?;
    writeln!(
        w,
        "0 on success, also when the reader of standard output closes it early (as in \
         \\fB| head\\fR); 1 on any error, with one line on standard error naming the file, \
         line or option. Progress is shown on standard error only when it is a terminal."
    )?;
    writeln!(w, ".SH \"SEE ALSO\"")?;
    // A subcommand's page points to its tool's first (whose page has the pipelines).
    let mut also: Vec<String> = if is_tool {
        vec![]
    } else {
        vec![tool.to_string()]
    };
    also.extend(
        super::commands()
            .iter()
            .map(|c| c.get_name().to_string())
            .filter(|n| n != tool),
    );
    let also: Vec<String> = also.iter().map(|n| format!("\\fB{n}\\fR(1)")).collect();
    writeln!(w, "{}", also.join(", "))?;
    if cmd.get_version().is_some() {
        man.render_version_section(w)?;
    }
    Ok(())
}

/// The examples of a `--help` text for the EXAMPLES section: its own `Examples:` heading
/// dropped (the section is the heading; notes before it stay, a blank line apart) and the
/// lines under it moved left.
fn help_examples(text: &str) -> String {
    let mut out: Vec<&str> = Vec::new();
    let mut under = false;
    for l in text.lines() {
        if l.trim_end() == "Examples:" {
            under = true;
            if out.last().is_some_and(|p| !p.trim().is_empty()) {
                out.push("");
            }
            continue;
        }
        out.push(if under {
            l.strip_prefix("  ").unwrap_or(l)
        } else {
            l
        });
    }
    out.join("\n")
}

/// A line of text for a roff no-fill block: backslashes as roff's `\e`, and a leading `.` or `'`
/// (a request to roff) escaped.
fn roff_line(line: &str) -> String {
    let l = line.replace('\\', "\\e");
    if l.starts_with('.') || l.starts_with('\'') {
        format!("\\&{l}")
    } else {
        l
    }
}

/// Shell completions for every tool: `bash/TOOL`, `zsh/_TOOL`, `fish/TOOL.fish` in `dir`
/// (the names the shells' completion folders expect); returns the files written.
pub fn write_completions(dir: &Path) -> std::io::Result<Vec<PathBuf>> {
    use clap_complete::Shell;
    let mut written = Vec::new();
    for (shell, sub) in [
        (Shell::Bash, "bash"),
        (Shell::Zsh, "zsh"),
        (Shell::Fish, "fish"),
    ] {
        let d = dir.join(sub);
        std::fs::create_dir_all(&d)?;
        for mut cmd in super::commands() {
            let name = cmd.get_name().to_string();
            let file = match shell {
                Shell::Bash => name.clone(),
                Shell::Zsh => format!("_{name}"),
                _ => format!("{name}.fish"),
            };
            let path = d.join(file);
            let mut f = std::io::BufWriter::new(std::fs::File::create(&path)?);
            clap_complete::generate(shell, &mut cmd, &name, &mut f);
            f.flush()?;
            written.push(path);
        }
    }
    Ok(written)
}
