//! `rglod`: Geometrical Levels of Detail (the seed's chapter 2): objects, their oriented
//! bounding boxes and levels, and scenes filtered to GLoD0-4. The command line is
//! `rdaylight::cli::rglod`; the analysis is `rdaylight::glod`.

fn main() {
    rdaylight::cli::run("rglod", || {
        let opts = rdaylight::cli::parse_or_exit::<rdaylight::cli::rglod::Options>(
            rdaylight::cli::rglod::radiance_spellings(std::env::args()),
        )?;
        let stdout = std::io::stdout();
        let mut out = std::io::BufWriter::new(stdout.lock());
        rdaylight::cli::rglod::run(&opts, &mut out)?;
        std::io::Write::flush(&mut out).map_err(|e| rdaylight::Error::io("<stdout>", e))
    })
}
