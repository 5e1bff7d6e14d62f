//! Build chores that are not tools (the cargo `xtask` pattern): kept out of `bin/` so
//! `make install` installs only the tools. The work is `rdaylight::cli::manual`.
//!
//! ```text
//! cargo run -p xtask -- man DIR            man pages (tool.1, tool-sub.1) into DIR
//! cargo run -p xtask -- completions DIR    DIR/bash/TOOL, DIR/zsh/_TOOL, DIR/fish/TOOL.fish
//! ```

use rdaylight::cli::manual;
use std::path::Path;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let result = match args.as_slice() {
        [what, dir] if what == "man" => manual::write_man_pages(Path::new(dir)),
        [what, dir] if what == "completions" => manual::write_completions(Path::new(dir)),
        _ => {
            eprintln!("usage: xtask man DIR | xtask completions DIR");
            std::process::exit(1);
        }
    };
    match result {
        Ok(files) => eprintln!("xtask: {} files in {}", files.len(), args[1]),
        Err(e) => {
            eprintln!("xtask: {}: {e}", args[1]);
            std::process::exit(1);
        }
    }
}
