//! `rglare`: glare evaluation of fisheye and perspective HDR pictures (DGP, DGI, UGR, VCP,
//! CGI, Ev), evalglare 3.x compatible output. The analysis is `rdaylight::glare`; the command
//! line (evalglare's letters, and `rglare annual`) is `rdaylight::cli::glare`.
fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    rdaylight::cli::run("rglare", || rdaylight::cli::glare::run(&args))
}
