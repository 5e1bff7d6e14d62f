//! `rglare`: glare evaluation of fisheye and perspective HDR pictures (DGP, DGI, UGR, VCP,
//! CGI, Ev), evalglare 3.x compatible output. Everything lives in `rdaylight::glare`; see
//! `rdaylight::glare::args` for the options.
fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    rdaylight::cli::run("rglare", || rdaylight::glare::args::run(&args))
}
