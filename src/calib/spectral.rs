//! Spectral calibration (issue 8; placeholder, filled in on its branch).
