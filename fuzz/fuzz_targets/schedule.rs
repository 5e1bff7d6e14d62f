//! Any text fed to rmetrics' schedule inputs gives Ok or Err, never a panic: `--occupied`
//! ranges, `--hours` files (`month day hour` per column), occupancy flag files, and the
//! weekday of an EPW's DATA PERIODS; stamps that parse make a schedule. The first line is
//! the `--occupied` value, the rest the file.
#![no_main]
use libfuzzer_sys::fuzz_target;
use rdaylight::metrics::schedule::{
    Schedule, Weekdays, parse_flags, parse_hours, parse_range, step_hours,
};

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let (range, file) = text.split_once('\n').unwrap_or((text, ""));
    let (start, end) = parse_range(range).unwrap_or((8.0, 18.0));
    let weekdays = Weekdays::from_epw_text(file, "fuzz.epw").ok().flatten();
    if let Ok(stamps) = parse_hours(file, "fuzz-hours.txt") {
        let s = Schedule::from_range(&stamps, start, end, weekdays);
        assert_eq!(s.occupied.len(), stamps.len());
        let _ = s.hours();
        let _ = s.check_columns(stamps.len(), "fuzz.mtx", "fuzz-hours.txt");
        for w in [
            Some(Weekdays {
                jan1: 6,
                leap: true,
            }),
            weekdays,
        ] {
            let _ = Schedule::from_range(&stamps, start, end, w);
        }
    }
    if let Ok(flags) = parse_flags(file, "fuzz-flags.txt") {
        let n = flags.len();
        let s = Schedule::from_flags(flags, step_hours(&[]), "fuzz-flags.txt");
        assert!(s.count() <= n);
    }
});
