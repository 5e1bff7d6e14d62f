//! Day numbers, one home for the calendar the sky and the schedules share.
//!
//! Two numberings are in use and both are right for their users:
//! - [`julian_day`]: Radiance's `jdate` (`src/gen/sun.c`), 1-based and blind to leap years
//!   (1 Jan = 1, 1 Mar = 60 in any year); solar position and gendaymtx's sky models use it
//!   (gendaymtx shifts days after a 29 Feb record itself, `sky::solar::LeapDayTracker`);
//! - [`day_index`]: the 0-based day of a given year, counting 29 Feb in leap years (1 Jan =
//!   0, 1 Mar = 60 in a leap year, 59 otherwise); weekdays and occupancy schedules use it.

/// Days before the first of each month in a common year.
const MONTH_START: [u32; 12] = [0, 31, 59, 90, 120, 151, 181, 212, 243, 273, 304, 334];

/// Radiance's `jdate`: 1-based day of the year without leap years; `month` 1-12 (clamped).
pub fn julian_day(month: u32, day: u32) -> u32 {
    MONTH_START[(month.clamp(1, 12) - 1) as usize] + day
}

/// 0-based day of the year, 29 February counted when `leap`; `month` 1-12 and `day` >= 1
/// (both clamped).
pub fn day_index(month: u32, day: u32, leap: bool) -> u32 {
    let m = month.clamp(1, 12);
    julian_day(m, day.max(1)) - 1 + u32::from(leap && m > 2)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_two_numberings_differ_by_one_and_by_the_leap_day() {
        assert_eq!((julian_day(1, 1), day_index(1, 1, false)), (1, 0));
        assert_eq!(julian_day(3, 1), 60);
        assert_eq!(day_index(3, 1, false), 59);
        assert_eq!(day_index(3, 1, true), 60);
        assert_eq!(day_index(2, 29, true), 59);
        assert_eq!((julian_day(12, 31), day_index(12, 31, true)), (365, 365));
    }
}
