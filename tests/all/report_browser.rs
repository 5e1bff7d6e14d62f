//! `rmetrics report` opened in a real headless browser (Debian's `chromium`): the page loads
//! without console errors, every `<img>` decodes (a copy of the page carries a small
//! checker script that writes the counts into the DOM, read back with `--dump-dom`), it
//! references nothing outside itself, and a screenshot is kept as
//! `target/test-artefacts/report_browser.png`.
//!
//! Needs `/usr/bin/chromium` (`make browser` installs it); fails saying so unless
//! `RDAYLIGHT_SKIP_BROWSER=1`.

use crate::common;

use common::{ours, repo, run, tmpdir};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

fn chromium() -> Option<PathBuf> {
    if std::env::var_os("RDAYLIGHT_SKIP_BROWSER").is_some_and(|v| !v.is_empty() && v != "0") {
        return None;
    }
    for p in ["/usr/bin/chromium", "/usr/bin/chromium-browser"] {
        if Path::new(p).exists() {
            return Some(p.into());
        }
    }
    panic!(
        "report_browser: no /usr/bin/chromium; install it (`make browser`, or apt-get install \
         chromium) or set RDAYLIGHT_SKIP_BROWSER=1 to skip this test"
    );
}

/// Run chromium headless on `url` with `extra` arguments; (stdout, stderr). A guard kills a
/// browser that hangs (not a timing assertion).
fn browse(bin: &Path, profile: &Path, extra: &[String], url: &str) -> (String, String) {
    let mut cmd = Command::new(bin);
    cmd.args([
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--disable-quic",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--enable-logging=stderr",
        "--v=0",
        "--run-all-compositor-stages-before-draw",
        "--virtual-time-budget=2000",
        "--window-size=1280,2000",
    ])
    .arg(format!("--user-data-dir={}", profile.display()))
    .args(extra)
    .arg(url)
    .stdin(Stdio::null())
    // Files, not pipes: a DOM larger than a pipe's buffer would block chromium while this
    // loop waits for it to exit.
    .stdout(std::fs::File::create(profile.with_extension("out")).expect("stdout file"))
    .stderr(std::fs::File::create(profile.with_extension("err")).expect("stderr file"));
    let mut child = cmd.spawn().expect("start chromium");
    let start = Instant::now();
    loop {
        if child.try_wait().expect("wait for chromium").is_some() {
            break;
        }
        if start.elapsed() > Duration::from_secs(180) {
            let _ = child.kill();
            panic!("chromium did not finish within 180 s on {url}");
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    let read = |ext| {
        String::from_utf8_lossy(&std::fs::read(profile.with_extension(ext)).unwrap()).into_owned()
    };
    (read("out"), read("err"))
}

/// Console errors and uncaught exceptions as chromium logs them with --enable-logging.
fn console_errors(stderr: &str) -> Vec<&str> {
    stderr
        .lines()
        .filter(|l| l.contains("CONSOLE") || l.contains("Uncaught"))
        .collect()
}

/// A 3 x 2 sensor grid in a 3 x 2 m room with a south window, the 4-day London weather
/// file and an illuminance matrix that falls with depth and follows the sun's hours.
fn fixture(d: &Path) -> (String, String, String, String) {
    let wea = repo()
        .join("radiance-fixtures/weather/london_4days.wea")
        .display()
        .to_string();
    let steps: Vec<f64> = std::fs::read_to_string(&wea)
        .unwrap()
        .lines()
        .skip(6)
        .map(|l| l.split_whitespace().nth(2).unwrap().parse().unwrap())
        .collect();
    let pts: Vec<[f64; 2]> = (0..2)
        .flat_map(|j| (0..3).map(move |i| [0.5 + i as f64, 0.5 + j as f64]))
        .collect();
    let mut m = format!(
        "#?RADIANCE\nNROWS={}\nNCOLS={}\nNCOMP=1\nFORMAT=ascii\n\n",
        pts.len(),
        steps.len()
    );
    for p in &pts {
        let row: Vec<String> = steps
            .iter()
            .map(|h| {
                let day = (std::f64::consts::PI * (h - 6.0) / 12.0).sin().max(0.0);
                format!("{:.1}", 4000.0 * day / (1.0 + 2.0 * p[1]))
            })
            .collect();
        m += &row.join(" ");
        m.push('\n');
    }
    let mtx = d.join("ill.mtx");
    std::fs::write(&mtx, m).unwrap();
    let sensors: String = pts
        .iter()
        .map(|p| format!("{} {} 0.8 0 0 1\n", p[0], p[1]))
        .collect();
    let spts = d.join("s.pts");
    std::fs::write(&spts, sensors).unwrap();
    let scene = d.join("room.rad");
    std::fs::write(
        &scene,
        "void plastic w 0 0 5 .5 .5 .5 0 0\nvoid glass g 0 0 3 .96 .96 .96\n\
         w polygon n 0 0 12 0 2 0 3 2 0 3 2 3 0 2 3\n\
         w polygon e 0 0 12 3 0 0 3 0 3 3 2 3 3 2 0\n\
         w polygon wst 0 0 12 0 0 0 0 2 0 0 2 3 0 0 3\n\
         w polygon s 0 0 12 0 0 0 0 0 0.9 3 0 0.9 3 0 0\n\
         g polygon win 0 0 12 0.5 0 0.9 0.5 0 2.5 2.5 0 2.5 2.5 0 0.9\n",
    )
    .unwrap();
    (
        mtx.display().to_string(),
        spts.display().to_string(),
        wea,
        scene.display().to_string(),
    )
}

#[test]
fn report_opens_in_a_headless_browser() {
    let Some(bin) = chromium() else {
        eprintln!("report_browser: skipped (RDAYLIGHT_SKIP_BROWSER)");
        return;
    };
    let d = tmpdir();
    let (mtx, pts, wea, scene) = fixture(d.path());
    let html = d.path().join("report.html");
    let out = run(
        ours("rmetrics").args([
            "report",
            "-w",
            &wea,
            "--pts",
            &pts,
            "--scene",
            &scene,
            "--setting",
            "rdc=-ab 5 -ad 10000 -lw 1e-5",
            "--command",
            "rdc -I -ab 5 room.rad < s.pts > dc.mtx",
            "--tool",
            "rdc 0.1.0",
            "-o",
            html.to_str().unwrap(),
            &mtx,
        ]),
        b"",
    );
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = std::fs::read_to_string(&html).unwrap();
    // Self-contained: every src/href is a data: URI or an anchor.
    for attr in ["src=\"", "href=\""] {
        for piece in text.split(attr).skip(1) {
            assert!(
                piece.starts_with("data:") || piece.starts_with('#'),
                "external reference {attr}{}",
                &piece[..piece.len().min(60)]
            );
        }
    }
    assert!(!text.contains("<link") && !text.contains("@import"));
    // The content: settings, SHA-256 of the inputs, commands, sensors from 1, warnings.
    assert!(text.contains("-ab 5 -ad 10000 -lw 1e-5"));
    let (hash, _) = rdaylight::metrics::html::sha256_file(&mtx).unwrap();
    assert!(text.contains(&hash), "the matrix's SHA-256 is listed");
    assert!(text.contains("LONDON/GATWICK") || text.contains("LONDON"));
    assert!(text.contains("rdc -I -ab 5 room.rad &lt; s.pts &gt; dc.mtx"));
    assert!(text.contains("ASE not computed"));
    let images = text.matches("<img ").count();
    assert!(
        images >= 8,
        "maps, temporal map and distributions: {images}"
    );

    let img = check_in_browser(&bin, d.path(), &text, &html, images, "report_browser.png");
    assert_eq!(img.width(), 1280);
    // The header's colour (#1f3b57) fills the top band: the page was laid out with its CSS.
    assert_eq!(img.get_pixel(640, 10).0, [0x1f, 0x3b, 0x57]);
    // Figures drew: viridis colours appear somewhere on the first screen.
    let viridis = img
        .pixels()
        .filter(|p| {
            let [r, g, b] = p.0;
            g > 150 && b < 140 && r < 120
        })
        .count();
    assert!(
        viridis > 100,
        "no map colours in the screenshot ({viridis})"
    );
}

/// Open `html` (whose text is `text`, with `images` <img> elements) in headless chromium:
/// a copy with a checker script must see every image loaded and no script error, the
/// console must stay clean, and a screenshot of the page itself is kept as `name` under
/// target/test-artefacts/ and returned.
fn check_in_browser(
    bin: &Path,
    dir: &Path,
    text: &str,
    html: &Path,
    images: usize,
    name: &str,
) -> image::RgbImage {
    let probe = dir.join(format!("probe-{name}.html"));
    let checker = "<script>window.__errors=0;window.addEventListener('error',function(){window.__errors++});\
        window.addEventListener('load',function(){var im=document.images,b=0;\
        for(var i=0;i<im.length;i++){if(!im[i].complete||im[i].naturalWidth===0)b++;}\
        document.body.setAttribute('data-images',im.length);\
        document.body.setAttribute('data-broken',b);\
        document.body.setAttribute('data-errors',window.__errors);});</script>";
    std::fs::write(
        &probe,
        text.replace("</body>", &format!("{checker}</body>")),
    )
    .unwrap();
    let url = format!("file://{}", probe.display());
    let (dom, err) = browse(
        bin,
        &dir.join(format!("profile-{name}")),
        &["--dump-dom".into()],
        &url,
    );
    assert!(
        dom.contains(&format!("data-images=\"{images}\"")),
        "the checker ran and saw every image: {}",
        dom.lines()
            .find(|l| l.contains("<body"))
            .unwrap_or("(no body)")
    );
    assert!(
        dom.contains("data-broken=\"0\""),
        "broken images: {}",
        dom.lines().find(|l| l.contains("<body")).unwrap_or("")
    );
    assert!(dom.contains("data-errors=\"0\""), "script errors");
    let errs = console_errors(&err);
    assert!(errs.is_empty(), "console errors: {errs:#?}");

    // The report itself, as a reader sees it: a screenshot kept as an artefact.
    let art = repo().join("target/test-artefacts");
    std::fs::create_dir_all(&art).unwrap();
    let shot = art.join(name);
    let _ = std::fs::remove_file(&shot);
    let url = format!("file://{}", html.display());
    // A fresh profile: chromium's crash handler may still hold the first one.
    let (_, err) = browse(
        bin,
        &dir.join(format!("profile2-{name}")),
        &[format!("--screenshot={}", shot.display())],
        &url,
    );
    let errs = console_errors(&err);
    assert!(errs.is_empty(), "console errors: {errs:#?}");
    image::open(&shot)
        .unwrap_or_else(|e| panic!("screenshot {}: {e}", shot.display()))
        .to_rgb8()
}

/// rcalib's report shares the frame: a before/after comparison page (made from a small
/// synthetic comparison, no simulation) opens cleanly and is laid out with the frame's CSS.
#[test]
fn rcalib_report_opens_in_a_headless_browser() {
    use rdaylight::calib::compare::{Comparison, SensorRow, StepRow};
    use rdaylight::calib::stats::Stats;
    let Some(bin) = chromium() else {
        eprintln!("report_browser: skipped (RDAYLIGHT_SKIP_BROWSER)");
        return;
    };
    let d = tmpdir();
    let comparison = |label: &str, bias: f64| {
        let pairs: Vec<(f64, f64)> = (1..=20)
            .map(|k| (100.0 * k as f64 * (1.0 + bias), 100.0 * k as f64))
            .collect();
        Comparison {
            label: label.into(),
            overall: Stats::of(&pairs),
            sensors: (0..4)
                .map(|i| SensorRow {
                    id: format!("s{i}"),
                    x: 0.5 + i as f64,
                    y: 1.0,
                    z: 0.8,
                    depth: 0.5 + i as f64,
                    stats: Stats::of(&pairs[i * 5..i * 5 + 5]),
                })
                .collect(),
            steps: (0..5)
                .map(|t| StepRow {
                    month: 6,
                    day: 1 + t,
                    hour: 12.0,
                    sun_altitude: 50.0,
                    clearness: 1.0 + t as f64,
                    dni: 500.0,
                    dhi: 100.0,
                    stats: Stats::of(&pairs[t as usize * 4..t as usize * 4 + 4]),
                })
                .collect(),
            scatter: pairs.iter().map(|p| (p.1, p.0, 0, 0)).collect(),
            windows: vec![[0.0, 0.0, 4.0, 0.0]],
            outline: vec![
                [0.0, 0.0, 4.0, 0.0],
                [4.0, 0.0, 4.0, 2.0],
                [4.0, 2.0, 0.0, 2.0],
                [0.0, 2.0, 0.0, 0.0],
            ],
        }
    };
    let (before, after) = (
        comparison("model.rad", 0.2),
        comparison("calibrated.rad", 0.01),
    );
    let input = d.path().join("model.rad");
    std::fs::write(&input, "void plastic floor_mat 0 0 5 .2 .2 .2 0 0\n").unwrap();
    let text =
        rdaylight::calib::report::html(&[&before, &after], None, &[input.display().to_string()])
            .unwrap();
    let html = d.path().join("rcalib.html");
    std::fs::write(&html, &text).unwrap();
    assert!(text.contains("<header><h1>rcalib compare: the model before and after</h1>"));
    let (hash, _) = rdaylight::metrics::html::sha256_file(&input.display().to_string()).unwrap();
    assert!(text.contains(&hash), "the model's SHA-256 is listed");
    assert!(text.contains(">N</text>"), "the plans have a north arrow");
    let img = check_in_browser(&bin, d.path(), &text, &html, 0, "rcalib_report_browser.png");
    assert_eq!(img.get_pixel(640, 10).0, [0x1f, 0x3b, 0x57]);
}
