//! (being written)
fn main() {
    rdaylight::cli::run("ruplift", || {
        Err(rdaylight::Error::Usage("not implemented yet".into()))
    })
}
