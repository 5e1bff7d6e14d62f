//! `rdc`: daylight coefficients, point-in-time values and pictures (rcontrib / rtrace -I /
//! rpict counterpart). Options, physics and output live in `rdaylight::rdc`; this file
//! takes the view options out of the command line, parses the rest with clap and calls the
//! driver.

use clap::Parser;
use rdaylight::formats::view::View;
use rdaylight::rdc::{Options, options::radiance_args, run};

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
    let opts = Options::try_parse_from(clap_args).unwrap_or_else(|e| e.exit());
    run::main(&opts, has_view.then_some(view), &command)
}
