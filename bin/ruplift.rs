//! `ruplift`: spectral uplifting, RGB -> smooth bounded reflectance spectrum for Radiance 6.
//! The command line is `rdaylight::cli::ruplift`; the commands are
//! `rdaylight::uplift::colours` (rgb, batch) and `rdaylight::uplift::run` (photo, proxy,
//! validate).

use rdaylight::Error;
use rdaylight::cli::ruplift::{Cli, Command};
use rdaylight::error::IoContext;
use rdaylight::uplift::{colours, run};
use std::io::Write;

fn main() {
    rdaylight::cli::run("ruplift", real_main)
}

fn real_main() -> Result<(), Error> {
    let cli = rdaylight::cli::parse_or_exit::<Cli>(std::env::args().collect())?;
    let stdout = std::io::stdout();
    let mut out = std::io::BufWriter::new(stdout.lock());
    let err = &mut std::io::stderr();
    match cli.command {
        Command::Rgb {
            r,
            g,
            b,
            name,
            common,
        } => {
            let item = colours::colour(&name, [r, g, b])?;
            colours::emit(&mut out, err, &[item], &common.to_config())?
        }
        Command::Batch { input, common } => {
            let items = colours::read_batch(&input)?;
            colours::emit(&mut out, err, &items, &common.to_config())?
        }
        Command::Validate { plot } => run::validate_run(plot.as_deref(), &mut out)?,
        Command::Photo(a) => run::photo_run(&a.to_run(), &mut out)?,
        Command::Proxy(a) => run::proxy_run(&a.to_run(), &mut out, err)?,
    }
    out.flush().at_path("<stdout>")
}
