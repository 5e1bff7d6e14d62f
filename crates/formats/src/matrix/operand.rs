//! # Right operands of streamed products: held row by row, dense or sparse
//!
//! `rmtx dc.mtx sky.smx` streams the left matrix row by row and holds the right one
//! ([`super::RowOps`]). A Perez sky matrix (146 x 8760 x RGB) is half non-zero (the night
//! hours are zero) and costs 30.7 MB as f64. A sun-only sky matrix (`rspecsky -m 6 -5 0.533
//! -d`, gendaymtx `-5 .533 -d`: 5186 suns x 8760 hours, 545 MB of float) is almost all
//! zeros: each hour's sun lies in one patch (measured on the London year: 6.3e-5 of its
//! numbers are non-zero). Held dense as f64 it took 1.09 GB whatever the number of sensors
//! (measured: `rmtx -ff -c 47.4 119.9 11.6 sun.mtx sky_sun.smx`, peak RSS 1,068,200 KiB for
//! the 165 sensors of `make`), so every row is kept in whichever form is smaller:
//!
//! - dense: `ncols * ncomp` f64;
//! - sparse: the non-zero elements' columns (u32) and their `ncomp` values (f64), which
//!   also stands for an all-zero row (no elements).
//!
//! Rows are read one at a time from the [`MatrixReader`], so the dense matrix never exists
//! in memory, and with `cols` (an hour chunk, `rmtx --hours`) only those columns are kept.
//!
//! The product is the same: `out[j] = Σ_h a[h] · b[h][j]` is summed over `h` in the same
//! order with the same operations; an element left out would only have added
//! `a[h] · 0 = ±0`, which changes no sum of finite values of one sign (daylight
//! coefficients and skies are never negative). With an infinite or NaN coefficient the
//! dense form would spread NaN to every column, this one to the non-zero ones.

use super::{Matrix, MatrixReader, Shape};
use crate::error::Result;
use crate::radiometry::Channels;
use std::io::BufRead;
use std::ops::Range;

/// One row of an [`Operand`].
#[derive(Debug, Clone, PartialEq)]
enum Row {
    Dense(Vec<f64>),
    /// Columns of the non-zero elements and their components, `ncomp` per column.
    Sparse {
        cols: Vec<u32>,
        vals: Vec<f64>,
    },
}

/// A right operand of a streamed product (see the module documentation).
#[derive(Debug, Clone, PartialEq)]
pub struct Operand {
    pub nrows: usize,
    pub ncols: usize,
    pub channels: Channels,
    rows: Vec<Row>,
}

impl Operand {
    /// Read the remaining rows of `reader`, keeping columns `cols` only when given (which
    /// must lie within NCOLS). Memory grows with the rows read and their non-zeros.
    pub fn read<R: BufRead>(
        reader: &mut MatrixReader<R>,
        cols: Option<Range<usize>>,
    ) -> Result<Operand> {
        let ncomp = reader.ncomp();
        let keep = cols.unwrap_or(0..reader.ncols());
        let mut buf = vec![0.0; reader.row_len()];
        let mut rows = Vec::new();
        while reader.read_row(&mut buf)? {
            rows.push(Row::from_dense(
                &buf[keep.start * ncomp..keep.end * ncomp],
                ncomp,
            ));
        }
        Ok(Operand {
            nrows: rows.len(),
            ncols: keep.len(),
            channels: reader.info().channels,
            rows,
        })
    }

    /// The operand of a matrix already in memory.
    pub fn from_matrix(m: &Matrix) -> Operand {
        Operand::from_values(m.nrows, m.ncols, m.channels, &m.data)
    }

    /// The operand of `nrows` rows of `ncols * channels.ncomp` values in [`Matrix`]'s
    /// order, borrowed (an array the caller owns, e.g. a NumPy array: no dense copy first).
    /// Panics if `data` is shorter than that (a programming error).
    pub fn from_values(nrows: usize, ncols: usize, channels: Channels, data: &[f64]) -> Operand {
        let n = ncols * channels.ncomp;
        Operand {
            nrows,
            ncols,
            channels,
            rows: (0..nrows)
                .map(|r| Row::from_dense(&data[r * n..(r + 1) * n], channels.ncomp))
                .collect(),
        }
    }

    pub fn ncomp(&self) -> usize {
        self.channels.ncomp
    }

    /// Numbers per row of the product (`ncols * ncomp`).
    pub fn row_len(&self) -> usize {
        self.ncols * self.channels.ncomp
    }

    pub fn shape(&self) -> Shape {
        Shape {
            nrows: Some(self.nrows),
            ncols: self.ncols,
            ncomp: self.channels.ncomp,
        }
    }

    /// Bytes held by the rows' values and indices (what the operand costs in memory).
    pub fn heap_bytes(&self) -> usize {
        self.rows
            .iter()
            .map(|r| match r {
                Row::Dense(v) => v.len() * 8,
                Row::Sparse { cols, vals } => cols.len() * 4 + vals.len() * 8,
            })
            .sum()
    }

    /// `out = a · self` for one row `a` (`nrows * ncomp` numbers), per channel: `out` has
    /// [`Operand::row_len`] numbers.
    pub fn multiply_row(&self, a: &[f64], out: &mut [f64]) {
        let nc = self.channels.ncomp;
        out.iter_mut().for_each(|v| *v = 0.0);
        for (ah, row) in a.chunks_exact(nc).zip(&self.rows) {
            // Zero coefficients (e.g. ground or unseen patches) are common: skip their rows.
            if ah.iter().all(|&v| v == 0.0) {
                continue;
            }
            match row {
                Row::Dense(brow) => {
                    for (o, bv) in out.chunks_exact_mut(nc).zip(brow.chunks_exact(nc)) {
                        for k in 0..nc {
                            o[k] += ah[k] * bv[k];
                        }
                    }
                }
                Row::Sparse { cols, vals } => {
                    for (&j, bv) in cols.iter().zip(vals.chunks_exact(nc)) {
                        let o = &mut out[j as usize * nc..(j as usize + 1) * nc];
                        for k in 0..nc {
                            o[k] += ah[k] * bv[k];
                        }
                    }
                }
            }
        }
    }
}

impl Row {
    /// The smaller of the two forms of `values` (`ncomp` per element).
    fn from_dense(values: &[f64], ncomp: usize) -> Row {
        let nonzero = values
            .chunks_exact(ncomp)
            .filter(|e| e.iter().any(|&v| v != 0.0))
            .count();
        // Sparse costs 4 bytes of column index plus the values per non-zero element.
        if nonzero * (4 + 8 * ncomp) >= values.len() * 8 {
            return Row::Dense(values.to_vec());
        }
        let mut cols = Vec::with_capacity(nonzero);
        let mut vals = Vec::with_capacity(nonzero * ncomp);
        for (j, e) in values.chunks_exact(ncomp).enumerate() {
            if e.iter().any(|&v| v != 0.0) {
                cols.push(j as u32);
                vals.extend_from_slice(e);
            }
        }
        Row::Sparse { cols, vals }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 3 x 5 x 2 matrix with a dense row, a sparse row and a zero row.
    fn sample() -> Matrix {
        let mut m = Matrix::zeros(
            3,
            5,
            Channels {
                ncomp: 2,
                ..Channels::rgb()
            },
        );
        for (i, v) in m.row_mut(0).iter_mut().enumerate() {
            *v = 0.25 * i as f64 + 0.1;
        }
        m.get_mut(1, 3).copy_from_slice(&[2.5, 0.0]);
        m
    }

    #[test]
    fn rows_take_the_smaller_form() {
        let op = Operand::from_matrix(&sample());
        assert!(matches!(op.rows[0], Row::Dense(_)));
        assert_eq!(
            op.rows[1],
            Row::Sparse {
                cols: vec![3],
                vals: vec![2.5, 0.0]
            }
        );
        assert!(matches!(&op.rows[2], Row::Sparse { cols, .. } if cols.is_empty()));
        assert_eq!(op.heap_bytes(), 10 * 8 + 4 + 2 * 8);
    }

    #[test]
    fn a_sun_only_sky_costs_its_suns_not_its_size() {
        // 5186 sun patches x 48 hours, one sun per hour (as rspecsky -m 6 -5 0.533 -d):
        // 5.98 MB as dense f64, 48 x (4 + 24) bytes here.
        let mut m = Matrix::zeros(5186, 48, Channels::rgb());
        for t in 0..48 {
            m.get_mut((t * 97) % 5186, t)
                .copy_from_slice(&[1e6, 9e5, 8e5]);
        }
        let op = Operand::from_matrix(&m);
        assert_eq!(op.heap_bytes(), 48 * 28);
        let a: Vec<f64> = (0..5186 * 3).map(|i| (i % 7) as f64 * 1e-3).collect();
        let (mut got, mut want) = (vec![0.0; 144], vec![0.0; 144]);
        op.multiply_row(&a, &mut got);
        for j in 0..48 {
            for k in 0..3 {
                want[j * 3 + k] = (0..5186).fold(0.0, |s, h| s + a[h * 3 + k] * m.get(h, j)[k]);
            }
        }
        assert!(got == want && got.iter().any(|&v| v > 0.0));
    }

    #[test]
    fn product_equals_the_dense_triple_loop_bit_for_bit() {
        let b = sample();
        let op = Operand::from_matrix(&b);
        let a: Vec<f64> = (0..6).map(|i| (i as f64 + 1.0).sqrt()).collect();
        let mut out = vec![f64::NAN; 10];
        op.multiply_row(&a, &mut out);
        for j in 0..5 {
            for k in 0..2 {
                let want = (0..3).fold(0.0, |s, h| s + a[h * 2 + k] * b.get(h, j)[k]);
                assert_eq!(out[j * 2 + k].to_bits(), want.to_bits(), "({j}, {k})");
            }
        }
    }
}
