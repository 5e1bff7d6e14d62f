//! The malformed-input suite: bad files of every format through a real binary (`rinfo`,
//! which parses each format fully). Each must give exactly one line on stderr naming the
//! file, the line (where the format has lines) and what was expected; exit status 1; nothing
//! on stdout; and never a panic.

use crate::common;
use std::path::Path;

/// Run `rinfo --stats file` and return its single stderr line, checking the contract.
fn one_line_error(dir: &Path, file: &str) -> String {
    let out = common::run(
        common::ours("rinfo")
            .current_dir(dir)
            .args(["--stats", file]),
        b"",
    );
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    assert_eq!(
        out.status.code(),
        Some(1),
        "{file}: exit status, stderr: {err}"
    );
    assert!(out.stdout.is_empty(), "{file}: wrote to stdout");
    assert!(!err.contains("panicked"), "{file}: panic: {err}");
    assert_eq!(err.lines().count(), 1, "{file}: not one line: {err}");
    err.trim_end().to_string()
}

fn write(dir: &Path, name: &str, bytes: &[u8]) {
    std::fs::write(dir.join(name), bytes).unwrap();
}

#[test]
fn scenes() {
    let t = common::tmpdir();
    let d = t.path();
    let red = "void plastic red 0 0 5 1 0 0 0 0\n";
    write(
        d,
        "unknown.rad",
        format!("{red}red polygn p 0 0 9 0 0 0 1 0 0 0 1 0\n").as_bytes(),
    );
    write(
        d,
        "count.rad",
        format!("{red}red polygon win_s\n0\n0\n11 0 0 0 1 0 0 0 1 0 1 1\n").as_bytes(),
    );
    write(d, "undef.rad", b"nored polygon p 0 0 9 0 0 0 1 0 0 0 1 0\n");
    write(d, "short.rad", b"void plastic red 0 0 5 1 0 0 0\n");
    write(
        d,
        "word.rad",
        format!("{red}red sphere s 0 0 4 0 0 x 1\n").as_bytes(),
    );
    assert_eq!(
        one_line_error(d, "unknown.rad"),
        "rinfo: unknown.rad:2:5: unknown primitive type 'polygn'"
    );
    assert_eq!(
        one_line_error(d, "count.rad"),
        "rinfo: count.rad:5:1: polygon 'win_s' expects a multiple of 3 real arguments (at least \
         9), found 11"
    );
    assert_eq!(
        one_line_error(d, "undef.rad"),
        "rinfo: undef.rad:1:1: undefined modifier 'nored'"
    );
    assert!(
        one_line_error(d, "short.rad")
            .starts_with("rinfo: short.rad:2:1: unexpected end of file inside plastic 'red'")
    );
    let e = one_line_error(d, "word.rad");
    assert!(e.starts_with("rinfo: word.rad:2:"), "{e}");
    assert!(e.contains("'x'"), "{e}");
}

#[test]
fn matrices() {
    let t = common::tmpdir();
    let d = t.path();
    let dc = std::fs::read(common::repo().join("radiance-fixtures/dc/office_m1.mtx")).unwrap();
    write(d, "trunc.mtx", &dc[..5000]);
    write(
        d,
        "ncols.mtx",
        b"#?RADIANCE\nNROWS=2\nNCOLS=4\nNCOMP=3\nFORMAT=ascii\n\n1 2 3 4 5 6 7 8 9\n1 2 3 4 5 6 7 8 9\n",
    );
    write(
        d,
        "token.mtx",
        b"#?RADIANCE\nNROWS=2\nNCOLS=2\nNCOMP=1\nFORMAT=ascii\n\n1 2\n3 x\n",
    );
    write(d, "format.mtx", b"#?RADIANCE\nNCOLS=2\nFORMAT=int16\n\n");
    write(d, "noend.mtx", b"#?RADIANCE\nNCOLS=2\nFORMAT=ascii\n");
    assert!(
        one_line_error(d, "trunc.mtx")
            .starts_with("rinfo: trunc.mtx: ends inside row 3 (1315 of 1752 bytes; NCOLS=146")
    );
    assert!(one_line_error(d, "ncols.mtx").starts_with("rinfo: ncols.mtx:8: ends inside row 2"));
    assert_eq!(
        one_line_error(d, "token.mtx"),
        "rinfo: token.mtx:8:3: expected a number, found 'x'"
    );
    assert!(
        one_line_error(d, "format.mtx").starts_with("rinfo: format.mtx:3: FORMAT=int16: expected")
    );
    assert!(
        one_line_error(d, "noend.mtx")
            .starts_with("rinfo: noend.mtx:4: file ends inside the header")
    );
}

#[test]
fn pictures() {
    let t = common::tmpdir();
    let d = t.path();
    let pic =
        std::fs::read(common::repo().join("radiance-fixtures/pictures/office_clear_window.hdr"))
            .unwrap();
    // Corrupt run/literal counts right after the first scanline's new-RLE marker.
    let hdr_end = pic.windows(2).position(|w| w == b"\n\n").unwrap() + 2;
    let data = hdr_end + pic[hdr_end..].iter().position(|&b| b == b'\n').unwrap() + 1;
    let mut rle = pic.clone();
    for b in &mut rle[data + 4..data + 40] {
        *b = 0xff;
    }
    write(d, "rle.hdr", &rle);
    write(d, "trunc.hdr", &pic[..pic.len() / 2]);
    let mut res = pic[..hdr_end].to_vec();
    res.extend_from_slice(b"-Y 256 X 256\n");
    write(d, "res.hdr", &res);
    assert!(one_line_error(d, "rle.hdr").starts_with("rinfo: rle.hdr: scanline 1 of 256:"),);
    assert_eq!(
        one_line_error(d, "trunc.hdr"),
        "rinfo: trunc.hdr: scanline 116 of 256 ends early"
    );
    let e = one_line_error(d, "res.hdr");
    assert!(
        e.starts_with("rinfo: res.hdr:") && e.contains("resolution"),
        "{e}"
    );
}

#[test]
fn weather_and_sensors() {
    let t = common::tmpdir();
    let d = t.path();
    write(
        d,
        "bad.wea",
        b"place London\nlatitude 51.15\nlongitude 0.18\ntime_zone 0\nsite_elevation 62\n\
          weather_data_file_units 1\n1 1 0.5 0 0\n1 1 1.5 0 0 9\n",
    );
    write(d, "bad.pts", b"0 0 0.8 0 0 1\n1 0 0.8 0 0\n");
    let epw = std::fs::read_to_string(
        common::repo().join("examples/weather/GBR_London.Gatwick.037760_IWEC.epw"),
    )
    .unwrap();
    let mut lines: Vec<&str> = epw.lines().take(12).collect();
    let broken = lines[10].replacen(",", ";", 20);
    lines[10] = &broken;
    write(d, "bad.epw", lines.join("\n").as_bytes());
    assert_eq!(
        one_line_error(d, "bad.wea"),
        "rinfo: bad.wea:8: expected 'month day hour value value [aod skycover]', found 6 numbers"
    );
    assert_eq!(
        one_line_error(d, "bad.pts"),
        "rinfo: bad.pts:2: expected 6 numbers (x y z dx dy dz), found 5"
    );
    assert!(one_line_error(d, "bad.epw").starts_with("rinfo: bad.epw:11"));
}
