//! Physically based clear-sky atmosphere (issue 8; placeholder, filled in on its branch).
