//! `rdc`: daylight coefficients, point-in-time values and pictures (rcontrib / rtrace -I /
//! rpict counterpart). Options, physics and output live in `rdaylight::rdc`; this file
//! takes the view options out of the command line, parses the rest with clap and calls the
//! driver.

use clap::Parser;
use rdaylight::formats::view::View;
use rdaylight::rdc::options::{Uplift, radiance_args};
use rdaylight::rdc::{Options, run};

fn main() {
    rdaylight::cli::run("rdc", real_main)
}

fn real_main() -> Result<(), rdaylight::Error> {
    let argv: Vec<String> = std::env::args().collect();
    let command: Vec<String> = std::iter::once("rdc".to_string())
        .chain(argv.iter().skip(1).cloned())
        .collect();
    // View options first (-vta, -vp x y z, -vf file): clap cannot parse them.
    let mut view = View::default();
    let rest = view.extract_args(argv.iter().skip(1))?;
    let has_view = rest.len() + 1 != argv.len();
    let mut clap_args = vec!["rdc".to_string()];
    clap_args.extend(radiance_args(&rest));
    let opts = match Options::try_parse_from(clap_args) {
        Ok(o) => o,
        Err(e) if !e.use_stderr() => e.exit(), // --help: print and exit 0
        // One line and status 1 like every other error (clap would print a block, status 2).
        Err(e) => {
            let text = e.to_string();
            let first = text.lines().next().unwrap_or("bad command line");
            return Err(rdaylight::Error::Usage(
                first.trim_start_matches("error: ").to_string(),
            ));
        }
    };
    if opts.output.is_some() && (!has_view || opts.mf.is_some() || opts.suns.is_some()) {
        return Err(rdaylight::Error::Usage(
            "-o FILE writes pictures: give view options (-vt.. -vp ..) and no -m/--suns".into(),
        ));
    }
    if opts.uplift != Uplift::Radiance && !opts.channels()?.is_spectral() {
        return Err(rdaylight::Error::Usage(
            "--uplift basis|jakob changes spectral runs only: add -cs N (N > 3)".into(),
        ));
    }
    run::main(&opts, has_view.then_some(view), &command)
}
