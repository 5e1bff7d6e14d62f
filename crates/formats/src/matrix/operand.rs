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
        Ok(Operand::read_within(reader, cols, usize::MAX)?.0)
    }

    /// As [`Operand::read`], but stop after the row that takes [`Operand::heap_bytes`]
    /// beyond `budget`: the rows read and whether they are all of them. What a caller does
    /// when an operand turns out larger than the other loop order's memory ([`Outer`]):
    /// how large is known only once the rows are read (a sun-only sky is almost all zeros).
    pub fn read_within<R: BufRead>(
        reader: &mut MatrixReader<R>,
        cols: Option<Range<usize>>,
        budget: usize,
    ) -> Result<(Operand, bool)> {
        let ncomp = reader.ncomp();
        let keep = cols.unwrap_or(0..reader.ncols());
        let mut buf = vec![0.0; reader.row_len()];
        let mut rows = Vec::new();
        let mut bytes = 0usize;
        let mut complete = true;
        while reader.read_row(&mut buf)? {
            let row = Row::from_dense(&buf[keep.start * ncomp..keep.end * ncomp], ncomp);
            bytes += row.heap_bytes();
            rows.push(row);
            if bytes > budget {
                complete = false;
                break;
            }
        }
        let op = Operand {
            nrows: rows.len(),
            ncols: keep.len(),
            channels: reader.info().channels,
            rows,
        };
        Ok((op, complete))
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
        self.rows.iter().map(Row::heap_bytes).sum()
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
            row.add_scaled(ah, out, nc);
        }
    }
}

impl Row {
    /// `out += ah · self` per channel (`ah`: one element's `nc` components): the one
    /// multiply-add of every product here, in both loop orders ([`Operand::multiply_row`],
    /// [`Outer`]), so they give the same bits.
    fn add_scaled(&self, ah: &[f64], out: &mut [f64], nc: usize) {
        match self {
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

    fn heap_bytes(&self) -> usize {
        match self {
            Row::Dense(v) => v.len() * 8,
            Row::Sparse { cols, vals } => cols.len() * 4 + vals.len() * 8,
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

/// The left operand of an [`Outer`] product, transposed (`[h][i][k]`): f32 while every
/// value is one (any float file read as is), f64 from the first value that is not, so the
/// product's bits never depend on the storage.
#[derive(Debug, Clone)]
enum Left {
    F32(Vec<f32>),
    F64(Vec<f64>),
}

/// `L · B` in the other loop order: the left rows `L` held (few: sensors), `B`'s rows read
/// one at a time and added into the whole result, `C[i] += L[i][h] · B[h]` for
/// `h = 0, 1, ...`. Every element of `C` gets the same terms in the same order as
/// [`Operand::multiply_row`] (same skipped zero coefficients, same dense or sparse form of
/// each row of `B`, the same multiply-add: [`Row::add_scaled`]), so both orders give the
/// same bits.
///
/// Memory is `L` (f32 when exact) plus `C` (f64 accumulators), whatever the size of `B`:
/// for 165 sensors x 2306 patches (MF 4) x 8760 hours x RGB, 4.6 + 34.7 MB, where holding
/// the MF 4 sky takes 283 MB (half its hours are night: zero) and dctimestep 254 MB
/// (measured, `benches/memory.sh`). With few sensors and many time steps this is the
/// smaller of the two; [`Outer::bytes`] says how small.
#[derive(Debug, Clone)]
pub struct Outer {
    nc: usize,
    nleft: usize,
    inner: usize,
    ncols: usize,
    left: Left,
    out: Vec<f64>,
    /// Rows of `B` added so far.
    added: usize,
}

impl Outer {
    /// Memory of the product of `nleft x inner` by `inner x ncols` matrices of `nc`
    /// components (left in f32, result in f64).
    pub fn bytes(nleft: usize, inner: usize, ncols: usize, nc: usize) -> usize {
        nleft.saturating_mul(nc).saturating_mul(
            inner
                .saturating_mul(4)
                .saturating_add(ncols.saturating_mul(8)),
        )
    }

    /// A zero product of `nleft` rows by `inner x ncols` of `nc` components; set the left
    /// rows with [`Outer::set_left_row`] before adding rows of `B`.
    pub fn new(nleft: usize, inner: usize, ncols: usize, nc: usize) -> Outer {
        Outer {
            nc,
            nleft,
            inner,
            ncols,
            left: Left::F32(vec![0.0; nleft * inner * nc]),
            out: vec![0.0; nleft * ncols * nc],
            added: 0,
        }
    }

    /// Left row `i` (`inner * nc` numbers).
    pub fn set_left_row(&mut self, i: usize, row: &[f64]) {
        let (nc, nl) = (self.nc, self.nleft);
        if let Left::F32(v) = &self.left {
            if row
                .iter()
                .any(|&x| f64::from(x as f32).to_bits() != x.to_bits())
            {
                self.left = Left::F64(v.iter().map(|&x| f64::from(x)).collect());
            }
        }
        for (h, e) in row.chunks_exact(nc).enumerate() {
            let at = (h * nl + i) * nc;
            match &mut self.left {
                Left::F32(v) => {
                    for (d, &x) in v[at..at + nc].iter_mut().zip(e) {
                        *d = x as f32;
                    }
                }
                Left::F64(v) => v[at..at + nc].copy_from_slice(e),
            }
        }
    }

    /// Add the next row of `B` (`ncols * nc` numbers, dense).
    pub fn add_values(&mut self, values: &[f64]) {
        self.add_row(&Row::from_dense(values, self.nc));
    }

    /// Add the rows of `op`, the next rows of `B`.
    pub fn add_operand(&mut self, op: &Operand) {
        for r in &op.rows {
            self.add_row(r);
        }
    }

    fn add_row(&mut self, row: &Row) {
        let (nc, h) = (self.nc, self.added);
        self.added += 1;
        // More rows than `L` has columns: counted, and refused by the caller's shape check.
        if h >= self.inner {
            return;
        }
        let rl = self.ncols * nc;
        let mut ah = vec![0.0; nc];
        for (i, out) in self.out.chunks_exact_mut(rl).enumerate() {
            let at = (h * self.nleft + i) * nc;
            match &self.left {
                Left::F32(v) => {
                    for (a, &x) in ah.iter_mut().zip(&v[at..at + nc]) {
                        *a = f64::from(x);
                    }
                }
                Left::F64(v) => ah.copy_from_slice(&v[at..at + nc]),
            }
            if ah.iter().all(|&v| v == 0.0) {
                continue;
            }
            row.add_scaled(&ah, out, nc);
        }
    }

    /// Rows of `B` added so far.
    pub fn rows_added(&self) -> usize {
        self.added
    }

    /// Result rows (`nleft`).
    pub fn nrows(&self) -> usize {
        self.nleft
    }

    /// Result columns.
    pub fn ncols(&self) -> usize {
        self.ncols
    }

    /// Result row `i` (`ncols * nc` numbers).
    pub fn row(&self, i: usize) -> &[f64] {
        let rl = self.ncols * self.nc;
        &self.out[i * rl..(i + 1) * rl]
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

    /// `Outer` against `multiply_row`, row by row, bit for bit: a dense, a sparse and a
    /// zero row of `B`, left rows with zero elements (skipped alike), and a left value
    /// that is not an f32 (stored as f64 from then on), then a NaN coefficient.
    #[test]
    fn outer_order_gives_the_row_orders_bits() {
        let b = sample();
        let op = Operand::from_matrix(&b);
        let mut left: Vec<Vec<f64>> = vec![
            vec![0.5, 1.25, 0.0, 0.0, 3.0, 0.75],
            vec![0.0; 6],
            vec![1.0, 2.0, 4.0, 8.0, 16.0, 32.0],
        ];
        for pass in 0..3 {
            if pass == 1 {
                left[1] = vec![0.1, 0.2, 0.3, 0.0, 0.7, 1.0 / 3.0];
            }
            if pass == 2 {
                left[2][3] = f64::NAN;
            }
            let mut outer = Outer::new(left.len(), 3, 5, 2);
            for (i, a) in left.iter().enumerate() {
                outer.set_left_row(i, a);
            }
            assert_eq!(matches!(outer.left, Left::F32(_)), pass == 0);
            for r in 0..3 {
                outer.add_values(b.row(r));
            }
            assert_eq!(outer.rows_added(), 3);
            for (i, a) in left.iter().enumerate() {
                let mut want = vec![0.0; 10];
                op.multiply_row(a, &mut want);
                let got: Vec<u64> = outer.row(i).iter().map(|v| v.to_bits()).collect();
                let want: Vec<u64> = want.iter().map(|v| v.to_bits()).collect();
                assert_eq!(got, want, "pass {pass}, row {i}");
            }
        }
    }

    #[test]
    fn outer_memory_is_the_left_in_f32_and_the_result_in_f64() {
        // 165 sensors x 2306 patches (MF 4) x 8760 hours x RGB: 4.6 + 34.7 MB.
        assert_eq!(
            Outer::bytes(165, 2306, 8760, 3),
            165 * 3 * (2306 * 4 + 8760 * 8)
        );
        assert_eq!(Outer::bytes(usize::MAX, 2, 2, 3), usize::MAX);
    }

    #[test]
    fn reading_within_a_budget_stops_after_the_row_that_passes_it() {
        let mut bytes = b"#?RADIANCE\nNROWS=3\nNCOLS=5\nNCOMP=2\nFORMAT=ascii\n\n".to_vec();
        let m = sample();
        for r in 0..3 {
            let line: Vec<String> = m.row(r).iter().map(|v| v.to_string()).collect();
            bytes.extend_from_slice(format!("{}\n", line.join(" ")).as_bytes());
        }
        let opts = crate::matrix::ReadOptions::default();
        let mut r = MatrixReader::new(&bytes[..], "m", &opts).unwrap();
        // The dense first row alone (80 bytes) passes a budget of 50.
        let (op, complete) = Operand::read_within(&mut r, None, 50).unwrap();
        assert!(!complete && op.nrows == 1 && op.heap_bytes() == 80);
        let mut r = MatrixReader::new(&bytes[..], "m", &opts).unwrap();
        let (op, complete) = Operand::read_within(&mut r, None, 100).unwrap();
        assert!(complete && op == Operand::from_matrix(&m));
    }
}
