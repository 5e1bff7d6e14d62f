//! The Slurm workflow of `examples/slurm/` on a tiny case: start a single-host Slurm
//! (`start.sh`; installs slurm-wlm and munge with apt-get when missing), run the example
//! room's coefficients as a job array of 3 shards plus the dependent merge (`run.sh`), and
//! require the merged `dc.mtx` to equal an unsharded run's bytes. Then break it: delete
//! shard 1 and flip a bit of shard 2; the merge must stop naming the shard, and
//! `resume.sh` must submit exactly shards 1 and 2 again, leave shard 0's file untouched,
//! and merge into the same bytes.
//!
//! Runs when `RDAYLIGHT_SLURM=1` (`make test` sets it after starting Slurm with
//! `examples/slurm/start.sh`); skipped otherwise, and when `RDAYLIGHT_SKIP_SLURM` is set.
//! With `RDAYLIGHT_SLURM=1` a Slurm that cannot start is a failure whose message is
//! start.sh's one-line reason. About 30 s; Slurm is left running for the next run
//! (`examples/slurm/stop.sh` stops it).

use crate::common;

use common::repo;
use std::process::Command;

#[test]
fn slurm_array_merge_equals_single_run() {
    if std::env::var_os("RDAYLIGHT_SKIP_SLURM").is_some() {
        eprintln!("slurm_array_merge_equals_single_run: skipped (RDAYLIGHT_SKIP_SLURM set)");
        return;
    }
    if std::env::var_os("RDAYLIGHT_SLURM").is_none() {
        eprintln!(
            "slurm_array_merge_equals_single_run: skipped (set RDAYLIGHT_SLURM=1 to run it; \
             make test does)"
        );
        return;
    }
    // Idempotent: says "already running" at once when make test started it.
    let start = Command::new("bash")
        .arg("examples/slurm/start.sh")
        .current_dir(repo())
        .output()
        .expect("bash");
    if !start.status.success() {
        let err = String::from_utf8_lossy(&start.stderr);
        let why = err
            .lines()
            .rev()
            .find(|l| !l.trim().is_empty())
            .unwrap_or("examples/slurm/start.sh failed without a message");
        panic!("{why}");
    }
    // The jobs run the binaries from a path, as a cluster would: the ones this test built.
    let bin = std::path::Path::new(env!("CARGO_BIN_EXE_rdc"))
        .parent()
        .unwrap()
        .to_path_buf();
    let dir = common::tmpdir();
    let sensors = dir.path().join("sensors.pts");
    let all = std::fs::read_to_string(repo().join("examples/room/sensors.pts")).unwrap();
    let few: String = all.lines().step_by(20).map(|l| format!("{l}\n")).collect();
    std::fs::write(&sensors, few).unwrap();
    let out = dir.path().join("out");
    let status = Command::new("bash")
        .arg("examples/slurm/run.sh")
        .current_dir(repo())
        .env("N", "3")
        .env("OUT", &out)
        .env("BIN", &bin)
        .env("SENSORS", &sensors)
        .env("RDC_OPTS", "-ab 2 -ad 64 -s 3")
        .env("TIMEOUT", "300")
        .status()
        .expect("bash");
    assert!(status.success(), "examples/slurm/run.sh failed");
    // run.sh compares too; check the bytes here as well so the test states its outcome.
    let merged = std::fs::read(out.join("dc.mtx")).unwrap();
    let single = std::fs::read(out.join("dc.single.mtx")).unwrap();
    assert!(
        !merged.is_empty() && merged == single,
        "merged shards differ from the single run"
    );
    let metrics = std::fs::read_to_string(out.join("metrics.tsv")).unwrap();
    assert!(
        metrics.lines().any(|l| l.starts_with("room\t")),
        "no room metrics"
    );

    // Break it as a failed job would: shard 1 never written, shard 2 altered after writing.
    use std::os::unix::fs::MetadataExt;
    let shard = |k: usize| out.join(format!("dc.{k}.mtx"));
    let before = std::fs::metadata(shard(0)).unwrap();
    let bytes0 = std::fs::read(shard(0)).unwrap();
    let mut two = std::fs::read(shard(2)).unwrap();
    let n = two.len();
    two[n - 2] ^= 0x01;
    std::fs::write(shard(2), two).unwrap();
    let merge = || {
        let files: Vec<_> = (0..3).map(shard).collect();
        let mans: Vec<_> = (0..3).map(|k| out.join(format!("dc.{k}.json"))).collect();
        let m = Command::new(bin.join("rmtx"))
            .arg("--cat")
            .args(files)
            .arg("--manifests")
            .args(mans)
            .output()
            .unwrap();
        assert!(!m.status.success(), "the merge must stop");
        String::from_utf8_lossy(&m.stderr).into_owned()
    };
    let e = merge();
    assert!(e.contains("dc.2.mtx") && e.contains("corrupt"), "{e}");
    std::fs::remove_file(shard(1)).unwrap();
    let e = merge();
    assert!(e.contains("dc.1.mtx"), "{e}");
    let resume = Command::new("bash")
        .arg("examples/slurm/resume.sh")
        .current_dir(repo())
        .env("N", "3")
        .env("OUT", &out)
        .env("BIN", &bin)
        .env("SENSORS", &sensors)
        .env("RDC_OPTS", "-ab 2 -ad 64 -s 3")
        .env("TIMEOUT", "300")
        .output()
        .expect("bash");
    let said = String::from_utf8_lossy(&resume.stdout);
    assert!(
        resume.status.success(),
        "resume.sh failed: {said}{}",
        String::from_utf8_lossy(&resume.stderr)
    );
    assert!(said.contains("shards 1 2 of 3 resubmitted"), "{said}");
    let after = std::fs::metadata(shard(0)).unwrap();
    assert_eq!(
        (after.ino(), after.mtime(), after.mtime_nsec()),
        (before.ino(), before.mtime(), before.mtime_nsec()),
        "shard 0 was complete: it must not be written again"
    );
    assert_eq!(std::fs::read(shard(0)).unwrap(), bytes0);
    let merged = std::fs::read(out.join("dc.mtx")).unwrap();
    assert!(
        merged == single,
        "after the resume, merged shards differ from the single run"
    );
}
