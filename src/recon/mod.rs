//! Reconstruction of a room from a laser scan (`rrecon`): planes, watertight shell, windows
//! (issue 9).
