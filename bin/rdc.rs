//! (being written)
fn main() {
    rdaylight::cli::run("rdc", || {
        Err(rdaylight::Error::Usage("not implemented yet".into()))
    })
}
