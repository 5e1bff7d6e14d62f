//! # Progress on standard error: one renderer, the same words in every tool
//!
//! The libraries report stages through [`crate::progress::Progress`]; [`Bars`] draws them
//! with `indicatif`, one line per stage:
//!
//! ```text
//! rdc: tracing [########################>-------------------] 60/165 records, 4.1/s, 26s left
//! rspecsky: atmosphere tables (ms, AOD 0.1) [####>----] 2/4 scattering orders, 3.3 s each, 6s left
//! rmtx: product ⠙ 40960 rows, 9120/s
//! rrecon: planes (RANSAC) ⠹ 3s
//! ```
//!
//! that is the tool, the stage, done/total and the unit, the rate (or the time per unit when
//! a unit takes longer than a second), and the time left (`?` until a unit is done); the
//! bar takes the width the rest leaves. A stage that took a second or
//! more leaves one line when it ends (`rdc: tracing: 165/165 records in 40s`); shorter ones
//! vanish. Nothing is drawn unless standard error is a terminal
//! ([`crate::io::show_progress`]): in pipes, logs and tests the tools are silent, and
//! standard output is never touched.

use crate::progress::{Progress, Reporter};
use indicatif::{ProgressBar, ProgressDrawTarget, ProgressState, ProgressStyle};
use std::fmt::Write as _;
use std::sync::Mutex;
use std::time::Duration;

/// How often a bar is redrawn when no unit finishes (spinner, elapsed time, time left).
const TICK: Duration = Duration::from_millis(200);

/// A finished stage that took at least this long leaves a line.
const KEEP_AFTER: Duration = Duration::from_secs(1);

/// The progress renderer of one tool (`prog` starts every line).
pub struct Bars {
    prog: String,
    target: Target,
    keep_after: Duration,
    current: Mutex<Option<Current>>,
}

enum Target {
    Hidden,
    Stderr,
    #[cfg(test)]
    Memory(indicatif::InMemoryTerm),
}

struct Current {
    bar: ProgressBar,
    counted: Option<bool>,
    unit: String,
}

impl Bars {
    /// Bars on standard error when it is a terminal, else nothing.
    pub fn stderr(prog: &str) -> Bars {
        Bars {
            prog: prog.to_string(),
            target: if crate::io::show_progress() {
                Target::Stderr
            } else {
                Target::Hidden
            },
            keep_after: KEEP_AFTER,
            current: Mutex::new(None),
        }
    }

    /// [`Bars::stderr`] as a shareable [`Reporter`] (for configs that hold one).
    pub fn reporter(prog: &str) -> Reporter {
        Reporter::new(Bars::stderr(prog))
    }

    fn draw_target(&self) -> Option<ProgressDrawTarget> {
        match &self.target {
            Target::Hidden => None,
            Target::Stderr => Some(ProgressDrawTarget::stderr()),
            #[cfg(test)]
            Target::Memory(t) => Some(ProgressDrawTarget::term_like(Box::new(t.clone()))),
        }
    }

    fn lock(&self) -> std::sync::MutexGuard<'_, Option<Current>> {
        self.current.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The line's template: counted stages have a bar and the time left, stages of an
    /// unknown count a spinner and the count, uncounted stages a spinner and the time.
    fn style(&self, counted: Option<bool>, unit: &str, done: bool) -> ProgressStyle {
        let unit = unit.replace('{', "{{").replace('}', "}}");
        // The bar takes the width the rest leaves, so a line fills the terminal and the
        // stage name is never cut (a name too long for the terminal wraps, and indicatif
        // redraws both lines).
        let template = match (counted, done) {
            (Some(true), false) => format!(
                "{{prefix}}: {{msg}} [{{wide_bar}}] {{pos}}/{{len}} {unit}, {{rate}}, {{left}}"
            ),
            (Some(false), false) => {
                format!("{{prefix}}: {{msg}} {{spinner}} {{pos}} {unit}, {{rate}}")
            }
            (None, false) => "{prefix}: {msg} {spinner} {elapsed}".to_string(),
            (Some(true), true) => {
                format!("{{prefix}}: {{msg}}: {{pos}}/{{len}} {unit} in {{elapsed}}")
            }
            (Some(false), true) => format!("{{prefix}}: {{msg}}: {{pos}} {unit} in {{elapsed}}"),
            (None, true) => "{prefix}: {msg} in {elapsed}".to_string(),
        };
        ProgressStyle::with_template(&template)
            .unwrap_or_else(|_| ProgressStyle::default_bar())
            .progress_chars("#>-")
            .with_key("rate", |s: &ProgressState, w: &mut dyn std::fmt::Write| {
                let _ = w.write_str(&rate(s.pos(), s.per_sec()));
            })
            .with_key("left", |s: &ProgressState, w: &mut dyn std::fmt::Write| {
                let _ = w.write_str(&left(s.pos(), s.eta()));
            })
    }
}

/// Units per second, or seconds per unit when units are slow; `?` before the first.
fn rate(pos: u64, per_sec: f64) -> String {
    if pos == 0 || !per_sec.is_finite() || per_sec <= 0.0 {
        "?/s".into()
    } else if per_sec >= 100.0 {
        format!("{per_sec:.0}/s")
    } else if per_sec >= 1.0 {
        format!("{per_sec:.1}/s")
    } else {
        format!("{:.1} s each", 1.0 / per_sec)
    }
}

/// The time left, once a unit is done to estimate it from.
fn left(pos: u64, eta: Duration) -> String {
    if pos == 0 {
        return "? left".into();
    }
    let s = eta.as_secs();
    let mut out = String::new();
    if s >= 3600 {
        let _ = write!(out, "{}h {:02}m", s / 3600, s % 3600 / 60);
    } else if s >= 60 {
        let _ = write!(out, "{}m {:02}s", s / 60, s % 60);
    } else {
        let _ = write!(out, "{s}s");
    }
    out + " left"
}

impl Progress for Bars {
    fn start(&self, stage: &str, total: Option<u64>, unit: &str) {
        self.finish();
        let Some(target) = self.draw_target() else {
            return;
        };
        let counted = (!unit.is_empty()).then_some(total.is_some());
        // Styled and named before anything is drawn.
        let bar = ProgressBar::with_draw_target(total, target)
            .with_style(self.style(counted, unit, false))
            .with_prefix(self.prog.clone())
            .with_message(stage.to_string());
        bar.enable_steady_tick(TICK);
        *self.lock() = Some(Current {
            bar,
            counted,
            unit: unit.to_string(),
        });
    }

    fn advance(&self, n: u64) {
        if let Some(c) = self.lock().as_ref() {
            c.bar.inc(n);
        }
    }

    fn finish(&self) {
        let Some(c) = self.lock().take() else {
            return;
        };
        if c.bar.elapsed() >= self.keep_after {
            c.bar.set_style(self.style(c.counted, &c.unit, true));
            c.bar.abandon();
        } else {
            c.bar.finish_and_clear();
        }
    }
}

/// A tool that ends (an error, a broken pipe) with a stage open clears its line, so the
/// error message starts on a line of its own.
impl Drop for Bars {
    fn drop(&mut self) {
        if let Some(c) = self.lock().take() {
            c.bar.finish_and_clear();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use indicatif::InMemoryTerm;

    fn bars(term: &InMemoryTerm, keep_after: Duration) -> Bars {
        Bars {
            prog: "rdc".into(),
            target: Target::Memory(term.clone()),
            keep_after,
            current: Mutex::new(None),
        }
    }

    /// Wait for a steady tick to draw what was reported.
    fn shown(term: &InMemoryTerm) -> String {
        std::thread::sleep(TICK * 3);
        term.contents().trim_end().to_string()
    }

    #[test]
    fn one_wording_for_every_stage() {
        let term = InMemoryTerm::new(10, 120);
        let b = bars(&term, Duration::ZERO);
        b.start("tracing", Some(10), "records");
        let line = shown(&term);
        assert!(
            line.starts_with("rdc: tracing ") && line.ends_with("] 0/10 records, ?/s, ? left"),
            "{line}"
        );
        // The bar fills the terminal's width, never past it.
        let width = line.chars().count();
        assert!((110..=120).contains(&width), "{width}: {line}");
        b.advance(4);
        let line = shown(&term);
        assert!(
            line.contains("] 4/10 records, ") && line.ends_with(" left"),
            "{line}"
        );
        b.finish();
        assert!(
            term.contents()
                .starts_with("rdc: tracing: 4/10 records in "),
            "{}",
            term.contents()
        );
        b.start("product", None, "rows");
        b.advance(7);
        assert!(
            shown(&term).contains("rdc: product "),
            "{}",
            term.contents()
        );
        assert!(term.contents().contains(" 7 rows, "), "{}", term.contents());
        b.start("planes", None, "");
        assert!(shown(&term).contains("rdc: planes "), "{}", term.contents());
    }

    #[test]
    fn short_stages_vanish_and_an_open_stage_is_cleared() {
        let term = InMemoryTerm::new(10, 120);
        let b = bars(&term, Duration::from_secs(3600));
        b.start("tracing", Some(2), "records");
        b.advance(2);
        shown(&term);
        b.finish();
        assert_eq!(term.contents().trim(), "");
        b.start("tracing", Some(2), "records");
        b.advance(1);
        assert!(!shown(&term).trim().is_empty());
        drop(b);
        assert_eq!(term.contents().trim(), "");
    }

    #[test]
    fn rates_and_times_left_read_naturally() {
        assert_eq!(rate(0, 5.0), "?/s");
        assert_eq!(rate(3, 250.4), "250/s");
        assert_eq!(rate(3, 4.06), "4.1/s");
        assert_eq!(rate(3, 0.1), "10.0 s each");
        assert_eq!(left(0, Duration::from_secs(5)), "? left");
        assert_eq!(left(1, Duration::from_secs(42)), "42s left");
        assert_eq!(left(1, Duration::from_secs(125)), "2m 05s left");
        assert_eq!(left(1, Duration::from_secs(7300)), "2h 01m left");
    }

    #[test]
    fn nothing_is_drawn_without_a_terminal() {
        let b = Bars {
            prog: "rdc".into(),
            target: Target::Hidden,
            keep_after: KEEP_AFTER,
            current: Mutex::new(None),
        };
        b.start("tracing", Some(2), "records");
        b.advance(1);
        assert!(b.lock().is_none());
        b.finish();
    }
}
