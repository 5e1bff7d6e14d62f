//! (being written)
fn main() {
    rdaylight::cli::run("rmetrics", || {
        Err(rdaylight::Error::Usage("not implemented yet".into()))
    })
}
