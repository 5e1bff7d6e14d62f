//! `rdc`: daylight coefficients, point-in-time values and pictures (rcontrib / rtrace -I /
//! rpict counterpart). The command line is `rdaylight::cli::rdc` (clap, Radiance's option
//! spellings); the tracer and its driver are `rdaylight::rdc`. This file takes the view
//! options out of the command line, parses the rest and calls the driver.

use rdaylight::cli::rdc::{Options, radiance_args};
use rdaylight::formats::view::View;

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
    let opts = rdaylight::cli::parse_or_exit::<Options>(clap_args)?;
    let run = opts.to_run(has_view.then_some(view), &command)?;
    let progress = rdaylight::cli::progress::Bars::stderr("rdc");
    rdaylight::rdc::run::main(&run, &progress)
}
