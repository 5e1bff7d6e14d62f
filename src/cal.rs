//! Radiance `.cal` expression language (issue 8; placeholder, filled in on its branch).
