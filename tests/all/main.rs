//! The integration tests, as one test binary (`tests/all/`; issue 21, "The test suite").
//!
//! Each file here was once its own `tests/*.rs` binary linking the whole library; one binary
//! links once (minutes and gigabytes saved on a fresh clone) and its tests run in one
//! process, in parallel threads. Run one file's tests with a module filter:
//! `cargo test --test all rdc_cli::` (or `cargo nextest run --test all rdc_cli::`).
//!
//! Adding a test file `foo.rs` (see tests/README.md):
//! - put it in `tests/all/` and add `mod foo;` below (alphabetical order);
//! - share helpers through `use crate::common;` (never a second `mod common;`);
//! - tests share one process: never change the process's environment or working directory
//!   (pass `.env(..)`/`.current_dir(..)` to the child `Command` instead), and give temporary
//!   files unique names (`common::tmpdir()`), since other files' tests run at the same time;
//! - a case that takes more than about 30 s of CPU goes behind `common::full("why")` (run by
//!   `make test-full`), with a fast representative of the same behaviour left in `make test`.

mod common;

mod bsdf;
mod cal;
mod cli_help;
mod fixtures;
mod geometry;
mod hostile;
mod malformed;
mod material;
mod matrix;
mod picture;
mod rcalib;
mod rcalib_hits;
mod rcalib_independent;
mod rcalib_spectral;
mod rdc_agreement;
mod rdc_api;
mod rdc_cli;
mod rdc_flux;
mod rdc_reweight;
mod rdc_shard;
mod rdc_suns_ab;
mod report_browser;
mod rglare;
mod rglare_annual;
mod rglare_shard;
mod rglod_cli;
mod rmcop;
mod rmetrics;
mod rmtx_hours;
mod rmtx_memory;
mod rrecon_cli;
mod rrecon_pipeline;
mod rspecsky;
mod ruplift;
mod ruplift_images;
mod scene;
mod scene_compiled;
mod scene_mesh;
mod seed_medi;
mod sensors;
mod shading;
mod sky;
mod slurm;
mod spectral_genssky;
mod spectral_metrics;
mod spectral_misc;
mod spectral_rdc;
mod spectral_sky;
mod spectral_skymtx;
mod spectral_specdata;
mod trace;
mod view;
mod weather;
