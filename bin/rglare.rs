//! (being written)
fn main() {
    rdaylight::cli::run("rglare", || {
        Err(rdaylight::Error::Usage("not implemented yet".into()))
    })
}
