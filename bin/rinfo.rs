//! `rinfo`: what is in a file, before a long run needs it (the `getinfo` counterpart).
//!
//! The command line is `rdaylight::cli::rinfo`; all summaries are `rdaylight::info`. This
//! file parses options and prints one summary per file.

use rdaylight::cli::rinfo::Options;
use rdaylight::error::IoContext;
use std::io::Write;

fn main() {
    rdaylight::cli::run("rinfo", || {
        let opts = rdaylight::cli::parse_or_exit::<Options>(std::env::args().collect())?;
        let (detail, load) = (opts.detail(), opts.load_options());
        let mut out = std::io::stdout().lock();
        for f in &opts.files {
            let text = rdaylight::info::describe(f, detail, &load)?;
            out.write_all(text.as_bytes()).at_path("<stdout>")?;
        }
        Ok(())
    })
}
