//! A whole matrix in memory, for the small operands of a multiplication (sky matrices,
//! transmission matrices) and for transposition. Large matrices should be streamed with
//! [`MatrixReader`](super::MatrixReader) instead.
//!
//! Storage is Radiance's (`rmatrix.h: rmx_lval`): row-major, columns within a row, NCOMP
//! components interleaved within a column: element (r, c) starts at `ncomp * (c + ncols*r)`.

use super::reader::ReadOptions;
use super::writer::WriteOptions;
use super::{MatrixInfo, MatrixReader, MatrixWriter};
use crate::error::{Error, Result};
use crate::header::Header;
use crate::radiometry::Channels;
use std::io::{BufRead, Write};

#[derive(Debug, Clone, PartialEq)]
pub struct Matrix {
    pub nrows: usize,
    pub ncols: usize,
    pub channels: Channels,
    /// `nrows * ncols * ncomp` values in Radiance's order.
    pub data: Vec<f64>,
}

impl Matrix {
    /// A matrix of zeros.
    pub fn zeros(nrows: usize, ncols: usize, channels: Channels) -> Self {
        Matrix {
            nrows,
            ncols,
            channels,
            data: vec![0.0; nrows * ncols * channels.ncomp],
        }
    }

    pub fn ncomp(&self) -> usize {
        self.channels.ncomp
    }

    /// Numbers per row.
    pub fn row_len(&self) -> usize {
        self.ncols * self.channels.ncomp
    }

    /// Row `r` (`ncols * ncomp` values). Panics if `r >= nrows` (a programming error).
    pub fn row(&self, r: usize) -> &[f64] {
        let n = self.row_len();
        &self.data[r * n..(r + 1) * n]
    }

    pub fn row_mut(&mut self, r: usize) -> &mut [f64] {
        let n = self.row_len();
        &mut self.data[r * n..(r + 1) * n]
    }

    /// The NCOMP components of element (r, c).
    pub fn get(&self, r: usize, c: usize) -> &[f64] {
        let nc = self.channels.ncomp;
        let i = nc * (c + self.ncols * r);
        &self.data[i..i + nc]
    }

    pub fn get_mut(&mut self, r: usize, c: usize) -> &mut [f64] {
        let nc = self.channels.ncomp;
        let i = nc * (c + self.ncols * r);
        &mut self.data[i..i + nc]
    }

    /// Read all remaining rows of `reader`. Memory grows with the rows actually read, never
    /// from the header's NROWS alone (a damaged header cannot force a huge allocation).
    pub fn read_all<R: BufRead>(reader: &mut MatrixReader<R>) -> Result<Matrix> {
        let n = reader.row_len();
        let mut data = Vec::new();
        let mut row = vec![0.0; n];
        let mut nrows = 0;
        while reader.read_row(&mut row)? {
            data.extend_from_slice(&row);
            nrows += 1;
        }
        Ok(Matrix {
            nrows,
            ncols: reader.ncols(),
            channels: reader.info().channels,
            data,
        })
    }

    /// Load a matrix from a file (`-` = standard input); returns its header information too.
    pub fn load(path: &str, opts: &ReadOptions) -> Result<(Matrix, MatrixInfo)> {
        let mut r = MatrixReader::open(path, opts)?;
        let m = Matrix::read_all(&mut r)?;
        Ok((m, r.info().clone()))
    }

    /// Load from any buffered reader; `name` is used in messages.
    pub fn from_reader<R: BufRead>(r: R, name: &str, opts: &ReadOptions) -> Result<Matrix> {
        let mut r = MatrixReader::new(r, name, opts)?;
        Matrix::read_all(&mut r)
    }

    /// Write with a header carrying `header`'s lines (e.g. a command line).
    pub fn write<W: Write>(
        &self,
        w: W,
        name: &str,
        header: Header,
        opts: WriteOptions,
    ) -> Result<W> {
        let mut mw = MatrixWriter::new(
            w,
            name,
            header,
            Some(self.nrows),
            self.ncols,
            self.channels,
            opts,
        )?;
        for r in 0..self.nrows {
            mw.write_row(self.row(r))?;
        }
        mw.finish()
    }

    /// Save to a file, atomically (nothing is left behind on failure).
    pub fn save(&self, path: &std::path::Path, header: Header, opts: WriteOptions) -> Result<()> {
        let mut opts = opts;
        opts.seekable = true;
        let name = path.display().to_string();
        crate::io::write_atomically(path, |w| self.write(w, &name, header, opts).map(|_| ()))
    }

    /// The transpose (rows become columns; each element keeps its NCOMP components).
    pub fn transpose(&self) -> Matrix {
        let nc = self.channels.ncomp;
        let mut t = Matrix::zeros(self.ncols, self.nrows, self.channels);
        for r in 0..self.nrows {
            for c in 0..self.ncols {
                let src = nc * (c + self.ncols * r);
                let dst = nc * (r + self.nrows * c);
                t.data[dst..dst + nc].copy_from_slice(&self.data[src..src + nc]);
            }
        }
        t
    }

    /// Per-channel product `self · other` (see [`ops`](super::ops)).
    pub fn multiply(&self, other: &Matrix) -> Result<Matrix> {
        super::ops::check_multiply("left", self.shape(), "right", other.shape())?;
        let mut out = Matrix::zeros(self.nrows, other.ncols, self.channels);
        let op = super::Operand::from_matrix(other);
        for r in 0..self.nrows {
            let row = self.row(r);
            let n = out.row_len();
            op.multiply_row(row, &mut out.data[r * n..(r + 1) * n]);
        }
        Ok(out)
    }

    pub fn shape(&self) -> super::Shape {
        super::Shape {
            nrows: Some(self.nrows),
            ncols: self.ncols,
            ncomp: self.channels.ncomp,
        }
    }

    /// Largest relative difference to `other` (|a-b| / max(|a|,|b|, floor)), or an error if
    /// the shapes differ. `floor` keeps near-zero values from dominating.
    pub fn max_rel_diff(&self, other: &Matrix, floor: f64) -> Result<f64> {
        if self.shape() != other.shape() {
            return Err(Error::Mismatch(format!(
                "shapes differ: {} vs {}",
                self.shape(),
                other.shape()
            )));
        }
        Ok(self
            .data
            .iter()
            .zip(&other.data)
            .map(|(a, b)| (a - b).abs() / a.abs().max(b.abs()).max(floor))
            .fold(0.0, f64::max))
    }
}
