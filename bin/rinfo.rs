fn main() {
    rdaylight::cli::run("rinfo", || Ok(()))
}
