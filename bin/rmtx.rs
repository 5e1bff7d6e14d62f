//! `rmtx`: Radiance matrix conversion, multiplication and concatenation; the start of the
//! `rmtxop`/`dctimestep` counterpart. The command line is `rdaylight::cli::rmtx`; the job
//! (formats, arithmetic, checks) is `rdaylight::formats::matrix::Pipeline`. This file
//! parses, opens standard output and runs the job.

use rdaylight::cli::progress::Bars;
use rdaylight::cli::rmtx::Options;

fn main() {
    rdaylight::cli::run("rmtx", real_main)
}

fn real_main() -> Result<(), rdaylight::Error> {
    let args: Vec<String> = std::env::args().collect();
    let job = Options::parse_from(args.clone())?.to_pipeline(args)?;
    let out = std::io::BufWriter::with_capacity(1 << 16, std::io::stdout().lock());
    job.run(out, "<stdout>", &Bars::stderr("rmtx"))
}
