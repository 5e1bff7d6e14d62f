//! Calibration against field measurements (`rcalib`): compare, explain, apply (issue 7).
