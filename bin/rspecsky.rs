//! (being written)
fn main() {
    rdaylight::cli::run("rspecsky", || {
        Err(rdaylight::Error::Usage("not implemented yet".into()))
    })
}
