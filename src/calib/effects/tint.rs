//! Glazing spectral tint effect (issue 8; placeholder, filled in on its branch).
