//! Sparse matrix times a dense block of vectors, reading the sparse matrix once per eight
//! vectors.
//!
//! faer's sparse-dense product goes through the sparse matrix once for every column of the
//! dense one. For the Craig-Bampton projections (K and M times several hundred basis vectors of
//! a million-DOF body) that is hundreds of passes over a stiffness matrix of several hundred
//! megabytes: memory traffic, not arithmetic. Here every nonzero is read once and applied to
//! eight vectors, accumulated row by row in a buffer that is reused between calls.

use faer::reborrow::ReborrowMut;
use faer::{MatMut, MatRef};

use crate::fe::assembly::SparseMat;

/// Vectors carried through one pass over the sparse matrix.
const WIDTH: usize = 8;

/// `A X` for sparse A and dense X, with its row buffer (n × 8 numbers) kept between calls.
#[derive(Debug, Default)]
pub struct BlockProduct {
    rows: Vec<[f64; WIDTH]>,
}

impl BlockProduct {
    /// A product with an empty buffer (it grows to the rows of the largest A on first use).
    pub fn new() -> Self {
        Self::default()
    }

    /// `dst = a x`.
    ///
    /// # Panics
    /// If the shapes do not match (a programming error, as for faer's products).
    pub fn apply(&mut self, a: &SparseMat, x: MatRef<'_, f64>, mut dst: MatMut<'_, f64>) {
        assert!(
            a.ncols() == x.nrows() && a.nrows() == dst.nrows() && x.ncols() == dst.ncols(),
            "block product: A is {}x{}, X {}x{}, destination {}x{}",
            a.nrows(),
            a.ncols(),
            x.nrows(),
            x.ncols(),
            dst.nrows(),
            dst.ncols()
        );
        let (col_ptr, row_idx, values) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
        self.rows.resize(a.nrows(), [0.0; WIDTH]);
        for first in (0..x.ncols()).step_by(WIDTH) {
            let width = WIDTH.min(x.ncols() - first);
            self.rows.fill([0.0; WIDTH]);
            for j in 0..a.ncols() {
                let mut xj = [0.0; WIDTH];
                for (c, v) in xj.iter_mut().enumerate().take(width) {
                    *v = x[(j, first + c)];
                }
                for p in col_ptr[j]..col_ptr[j + 1] {
                    let (row, value) = (&mut self.rows[row_idx[p]], values[p]);
                    for (r, v) in row.iter_mut().zip(&xj) {
                        *r += value * v;
                    }
                }
            }
            for c in 0..width {
                let mut col = dst.rb_mut().col_mut(first + c);
                for (i, row) in self.rows.iter().enumerate() {
                    col[i] = row[c];
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::{SparseColMat, Triplet};
    use faer::Mat;

    #[test]
    fn equals_the_column_by_column_product_for_every_width() {
        // A rectangular, unsymmetric pattern with an empty column and repeated triplets.
        let (rows, cols) = (37, 29);
        let mut t = Vec::new();
        for j in 0..cols {
            if j == 11 {
                continue;
            }
            for k in 0..5 {
                let i = (j * 7 + k * 13) % rows;
                t.push(Triplet::new(
                    i,
                    j,
                    (i as f64 - 1.5 * j as f64 + k as f64) * 0.37,
                ));
            }
        }
        t.push(Triplet::new(3, 4, 2.5));
        let a = SparseColMat::<usize, f64>::try_new_from_triplets(rows, cols, &t).unwrap();
        let mut product = BlockProduct::new();
        for width in [1, 3, 8, 13, 16] {
            let x = Mat::from_fn(cols, width, |i, j| ((i * 5 + j * 3) % 11) as f64 - 4.0);
            let expected = a.as_ref() * x.as_ref();
            let mut got = Mat::from_fn(rows, width, |_, _| f64::NAN);
            product.apply(&a, x.as_ref(), got.as_mut());
            let err = (&got - &expected).norm_max();
            assert!(err <= 1e-12 * expected.norm_max(), "width {width}: {err}");
        }
    }
}
