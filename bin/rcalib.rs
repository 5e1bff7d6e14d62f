//! `rcalib`: compare a daylight model with measured illuminances, explain the difference by
//! missing physical effects, apply them to the model, and generate hidden-effect test cases.
//! The command line is `rdaylight::cli::rcalib`; the commands are `rdaylight::calib::run`.

use rdaylight::Error;
use rdaylight::calib::run;
use rdaylight::cli::rcalib::{Cli, Cmd, radiance_spellings};

fn main() {
    rdaylight::cli::run("rcalib", real_main)
}

fn real_main() -> Result<(), Error> {
    let cli = rdaylight::cli::parse_or_exit::<Cli>(radiance_spellings(std::env::args()))?;
    if cli.no_exec {
        rdaylight::scene::refuse_exec();
    }
    let stdout = std::io::stdout();
    let out = &mut stdout.lock();
    match cli.cmd {
        Cmd::Compare(a) => run::compare_run(&a.to_run()?, out),
        Cmd::Explain(a) => run::explain_run(&a.to_run()?, out),
        Cmd::Apply(a) => run::apply_run(&a.to_run()?, out, &mut std::io::stderr()),
        Cmd::Tmscan(a) => run::tmscan_run(&a.to_tmscan()?, out),
        Cmd::Synth(a) => run::synth_run(&a.to_run()?, out),
        Cmd::Spectral(a) => run::spectral_run(&a.to_run()?, out),
    }
}
