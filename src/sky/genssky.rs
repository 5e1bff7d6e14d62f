//! genssky-compatible point-in-time spectral sky (issue 8; placeholder, filled in on its branch).
