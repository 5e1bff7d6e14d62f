//! Fingerprints of files and data. Not cryptographic: they tell inputs apart (and catch
//! damaged files), they do not protect them.
//!
//! - [`Fnv64`]: 64-bit FNV-1a (Fowler, Noll, Vo; offset basis 0xcbf29ce484222325, prime
//!   0x100000001b3), byte by byte: the fingerprint of every cache key and checksum in the
//!   project (rcalib's coefficient cache, the atmosphere table cache, shard manifests).
//! - [`wide64`]: a word-wide hash for hundreds of megabytes (a compiled scene file and the
//!   scene files it was made from): FNV-1a's one multiply per byte reads about 1 GB/s, which
//!   is most of the 0.3 s a 1M-triangle compiled scene may take to load (issue 18); this one
//!   takes 8 bytes per step in four independent lanes.

/// A running FNV-1a hash.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Fnv64(pub u64);

impl Default for Fnv64 {
    fn default() -> Self {
        Fnv64::new()
    }
}

impl Fnv64 {
    pub const fn new() -> Fnv64 {
        Fnv64(0xcbf2_9ce4_8422_2325)
    }

    pub fn write(&mut self, bytes: &[u8]) {
        for &b in bytes {
            self.0 = (self.0 ^ u64::from(b)).wrapping_mul(0x0000_0100_0000_01b3);
        }
    }

    pub fn finish(&self) -> u64 {
        self.0
    }

    /// The hash as 16 lower-case hex digits.
    pub fn hex(&self) -> String {
        format!("{:016x}", self.0)
    }
}

/// An odd constant with well-mixed bits (2^64 / golden ratio).
const K: u64 = 0x9e37_79b9_7f4a_7c15;

/// The 64-bit finaliser of MurmurHash3 (Appleby): every input bit flips each output bit
/// with probability about 1/2.
fn avalanche(mut x: u64) -> u64 {
    x ^= x >> 33;
    x = x.wrapping_mul(0xff51_afd7_ed55_8ccd);
    x ^= x >> 33;
    x = x.wrapping_mul(0xc4ce_b9fe_1a85_ec53);
    x ^ (x >> 33)
}

/// One step of a lane: xor the word in, multiply by an odd constant, rotate. Each is a
/// bijection of the lane for a fixed word and of the word for a fixed lane, so two inputs
/// that differ in one word leave that lane different.
#[inline(always)]
fn step(lane: u64, w: u64) -> u64 {
    (lane ^ w).wrapping_mul(K).rotate_left(29)
}

/// The word-wide hash of `bytes` (see the module documentation): 8-byte little-endian
/// words go round-robin into four lanes; the tail (under 32 bytes) goes word by word into
/// the first lanes, its last partial word padded with zeros; the lanes and the length are
/// then folded and avalanched. Stable across platforms and versions: compiled scene files
/// store it (`docs/scene-binary-formats.md`).
pub fn wide64(bytes: &[u8]) -> u64 {
    let word = |c: &[u8]| u64::from_le_bytes(c.try_into().unwrap_or([0; 8]));
    let mut lanes = [K, K.rotate_left(16), K.rotate_left(32), K.rotate_left(48)];
    let mut blocks = bytes.chunks_exact(32);
    for b in blocks.by_ref() {
        for (i, lane) in lanes.iter_mut().enumerate() {
            *lane = step(*lane, word(&b[8 * i..8 * i + 8]));
        }
    }
    let tail = blocks.remainder();
    for (i, c) in tail.chunks(8).enumerate() {
        let mut w = [0u8; 8];
        w[..c.len()].copy_from_slice(c);
        lanes[i] = step(lanes[i], u64::from_le_bytes(w));
    }
    let mut h = (bytes.len() as u64).wrapping_mul(K);
    for lane in lanes {
        h = step(h, avalanche(lane));
    }
    avalanche(h)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wide64_is_stable_and_sees_every_byte() {
        // The value is part of a file format: it must never change.
        assert_eq!(wide64(b""), 0xc172_e3f4_96d3_27b2);
        let data: Vec<u8> = (0..1000u32).map(|i| (i * 7 + 3) as u8).collect();
        let h = wide64(&data);
        for n in 0..data.len() {
            assert_ne!(wide64(&data[..n]), h, "prefix {n}");
        }
        for k in 0..data.len() {
            for bit in [0x01u8, 0x80] {
                let mut d = data.clone();
                d[k] ^= bit;
                assert_ne!(wide64(&d), h, "byte {k} bit {bit:#x}");
            }
        }
        // Zeros appended are seen (the length is hashed).
        let mut longer = data.clone();
        longer.push(0);
        assert_ne!(wide64(&longer), h);
    }

    #[test]
    fn fnv1a_known_values() {
        let mut h = Fnv64::new();
        assert_eq!(h.hex(), "cbf29ce484222325");
        h.write(b"a");
        assert_eq!(h.hex(), "af63dc4c8601ec8c");
    }
}
