//! `rrecon`: laser scan -> watertight, window-bearing room in `.rad` (seed chapter 4).
//! The command line is `rdaylight::cli::rrecon`; the pipeline and the commands are
//! `rdaylight::recon` (`recon::run`).

use rdaylight::Error;
use rdaylight::cli::rrecon::{Cli, Command};
use rdaylight::recon::run;

fn main() {
    rdaylight::cli::run("rrecon", real_main)
}

fn real_main() -> Result<(), Error> {
    let cli = rdaylight::cli::parse_or_exit::<Cli>(std::env::args().collect())?;
    if cli.no_exec {
        rdaylight::scene::refuse_exec();
    }
    let stdout = std::io::stdout();
    let out = &mut stdout.lock();
    let progress = rdaylight::cli::progress::Bars::stderr("rrecon");
    match &cli.command {
        Some(Command::Simulate(a)) => run::simulate_run(&a.to_run()?, out, &progress),
        Some(Command::Room { name, shell }) => run::room_run(name, *shell, out),
        Some(Command::Eval {
            truth,
            recon,
            samples,
        }) => run::eval_run(truth, recon, *samples, out),
        None => run::reconstruct_run(&cli.recon.to_run()?, out, &mut std::io::stderr(), &progress),
    }
}
