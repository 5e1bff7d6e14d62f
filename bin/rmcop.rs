//! `rmcop`: Material Classes of Precision (the seed's chapter 3): material measurement
//! error propagated to annual metrics per GLoD by path re-weighting. The command line is
//! `rdaylight::cli::rmcop`; the study is `rdaylight::mcop`.

fn main() {
    rdaylight::cli::run("rmcop", || {
        let opts = rdaylight::cli::parse_or_exit::<rdaylight::cli::rmcop::Options>(
            rdaylight::cli::rmcop::radiance_spellings(std::env::args()),
        )?;
        let stdout = std::io::stdout();
        let mut out = std::io::BufWriter::new(stdout.lock());
        rdaylight::cli::rmcop::run(&opts, &mut out)?;
        std::io::Write::flush(&mut out).map_err(|e| rdaylight::Error::io("<stdout>", e))
    })
}
