//! `rspecsky`: Perez all-weather sky matrices from a weather file (the `gendaymtx`
//! counterpart), physically based spectral matrices (`--model atmosphere`, the
//! `gensdaymtx` counterpart) and point-in-time skies as scene text (the `gendaylit` and
//! `genssky` counterparts). The command line is `rdaylight::cli::rspecsky`; the models and
//! their typed configs are `rdaylight::sky::config`. This file parses, opens standard
//! output and calls the config's `write`.

use rdaylight::cli::rspecsky::{Command, Stderr, command};
use std::io::BufWriter;

fn main() {
    rdaylight::cli::run("rspecsky", real_main)
}

fn real_main() -> Result<(), rdaylight::Error> {
    let cmd = command(std::env::args().collect())?;
    let msgs = Stderr::new();
    let stdout = std::io::stdout().lock();
    match cmd {
        Command::Matrix(c) => c.write(BufWriter::with_capacity(1 << 16, stdout), "<stdout>", &msgs),
        Command::Point(c) => c.write(stdout, "<stdout>"),
        Command::Genssky(c) => c.write(stdout, "<stdout>", &msgs),
    }
}
