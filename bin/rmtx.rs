fn main() {
    rdaylight::cli::run("rmtx", || Ok(()))
}
