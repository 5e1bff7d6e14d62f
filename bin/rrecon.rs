//! `rrecon`: placeholder until its issue lands.
fn main() {
    eprintln!("rrecon: not implemented yet");
    std::process::exit(1);
}
