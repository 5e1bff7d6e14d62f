//! `rmetrics`: annual daylight metrics (TAI, UDI, DA, sDA, ASE) from an illuminance matrix,
//! falsecolor maps, melanopic quantities, and Appendix-A errors between model variants. The
//! command line is `rdaylight::cli::rmetrics`; what is computed and written is
//! `rdaylight::metrics::config`. This file parses options and opens standard output.

use rdaylight::cli::rmetrics::{Command, Options};

fn main() {
    rdaylight::cli::run("rmetrics", real_main)
}

fn real_main() -> Result<(), rdaylight::Error> {
    let cmd = rdaylight::cli::parse_or_exit::<Options>(std::env::args().collect())?
        .to_command(std::env::args().collect())?;
    let mut stdout = std::io::BufWriter::new(std::io::stdout().lock());
    match cmd {
        Command::Annual(c) => c.run(&mut stdout, &|n| eprintln!("rmetrics: note: {n}")),
        Command::Melanopic(c) => c.run(&mut stdout),
        Command::Compare(c) => c.run(&mut stdout),
        Command::Report(c) => c.run(&|n| eprintln!("rmetrics: note: {n}")),
    }
}
