//! Colour science, one home for the whole stack: the CIE tables and observers ([`cie`]),
//! band integrals and Radiance 6's cumulative observer tables ([`bands`]), and the CIE S 026
//! melanopic quantities ([`melanopic`]). It sits in the lowest layer because Radiance's own
//! formats need it (`rmtxop -c` on spectral matrices weights bands with these tables).

pub mod bands;
pub mod cie;
pub mod melanopic;
