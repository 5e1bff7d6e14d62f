//! `rcalib`: placeholder until its issue lands.
fn main() {
    eprintln!("rcalib: not implemented yet");
    std::process::exit(1);
}
