//! # Progress of long work: reported by the libraries, rendered by the tools
//!
//! A library that works for more than about a second (tracing, sky matrices, atmosphere
//! tables, matrix products, draws of a study) says how far it got through a [`Progress`]:
//! a *stage* begins with a name, a count of units and their name ([`Progress::start`]),
//! units are done from any thread ([`Progress::advance`]), the stage ends
//! ([`Progress::finish`]). What the user sees is the tools' business: `rdaylight::cli`
//! draws one bar per stage on standard error, in the same words for every tool, and only
//! when standard error is a terminal. Libraries never print progress themselves, and
//! nothing they report changes a byte of their results.
//!
//! [`Quiet`] reports nothing (tests, library callers); [`Reporter`] is a shared handle
//! that configs can hold; [`Stage`] finishes its stage when dropped, so an early `?`
//! return leaves no stage open.

use std::sync::Arc;

/// Where long work reports how far it got. Every method has a do-nothing default.
pub trait Progress: Send + Sync {
    /// Stage `stage` begins: `total` units called `unit` (e.g. 165 "records"), or an
    /// unknown count (`None`); a unit of `""` means the stage is not counted at all.
    fn start(&self, _stage: &str, _total: Option<u64>, _unit: &str) {}
    /// `n` more units of the current stage are done (called from any thread).
    fn advance(&self, _n: u64) {}
    /// The current stage is over.
    fn finish(&self) {}
}

/// Reports nothing.
#[derive(Debug, Clone, Copy, Default)]
pub struct Quiet;

impl Progress for Quiet {}

/// A [`Quiet`] to borrow where a `&dyn Progress` is wanted.
pub static QUIET: Quiet = Quiet;

/// A shared [`Progress`] for configs that are `Clone` and `Debug`; the default is quiet.
#[derive(Clone)]
pub struct Reporter(Arc<dyn Progress>);

impl Reporter {
    pub fn new(p: impl Progress + 'static) -> Reporter {
        Reporter(Arc::new(p))
    }

    pub fn quiet() -> Reporter {
        Reporter::new(Quiet)
    }

    /// The reporter as a `&dyn Progress`.
    pub fn get(&self) -> &dyn Progress {
        &*self.0
    }
}

impl Default for Reporter {
    fn default() -> Self {
        Reporter::quiet()
    }
}

impl std::fmt::Debug for Reporter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("Reporter")
    }
}

/// One stage of `progress`, finished when dropped.
pub struct Stage<'a> {
    progress: &'a dyn Progress,
}

impl<'a> Stage<'a> {
    /// Start stage `name` of `total` units called `unit` ([`Progress::start`]).
    pub fn new(progress: &'a dyn Progress, name: &str, total: Option<u64>, unit: &str) -> Self {
        progress.start(name, total, unit);
        Stage { progress }
    }

    /// A stage that is not counted (a spinner and the time it has taken).
    pub fn uncounted(progress: &'a dyn Progress, name: &str) -> Self {
        Stage::new(progress, name, None, "")
    }

    /// `n` more units done.
    pub fn advance(&self, n: u64) {
        self.progress.advance(n);
    }

    /// The progress this stage reports to (to hand to work that advances it).
    pub fn progress(&self) -> &'a dyn Progress {
        self.progress
    }
}

impl Drop for Stage<'_> {
    fn drop(&mut self) {
        self.progress.finish();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Mutex;

    /// Records every call, for tests of the libraries' reporting.
    #[derive(Default)]
    struct Log(Mutex<Vec<String>>);

    impl Progress for Log {
        fn start(&self, stage: &str, total: Option<u64>, unit: &str) {
            self.0
                .lock()
                .unwrap()
                .push(format!("start {stage} {total:?} {unit}"));
        }
        fn advance(&self, n: u64) {
            self.0.lock().unwrap().push(format!("advance {n}"));
        }
        fn finish(&self) {
            self.0.lock().unwrap().push("finish".into());
        }
    }

    #[test]
    fn a_stage_finishes_when_dropped_even_on_an_early_return() {
        let log = Log::default();
        let work = || -> Result<(), ()> {
            let s = Stage::new(&log, "tracing", Some(3), "records");
            s.advance(2);
            Err(())?;
            s.advance(1);
            Ok(())
        };
        assert!(work().is_err());
        assert_eq!(
            *log.0.lock().unwrap(),
            ["start tracing Some(3) records", "advance 2", "finish"]
        );
    }

    #[test]
    fn a_reporter_is_quiet_by_default_and_shares_its_progress() {
        let r = Reporter::default();
        r.get().start("x", None, "");
        let shared = Reporter::new(Log::default());
        let copy = shared.clone();
        copy.get().advance(1);
        assert_eq!(format!("{shared:?}"), "Reporter");
    }
}
