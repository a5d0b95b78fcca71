//! A dense square matrix factorised in place, `P A = L U` (faer's partial-pivoting LU; small
//! systems by a plain elimination): the Newton matrix of the dense path and the blocks and
//! capacitance matrix of the block-plus-low-rank path.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::lu::partial_pivoting::{factor, solve};
use faer::perm::PermRef;
use faer::{Mat, MatMut, Par};

/// Systems up to this size are solved by [`DenseLu::solve_small`].
const SMALL_SOLVE: usize = 64;

/// A factorised square matrix `P A = L U`, stored in place.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct DenseLu {
    #[serde(with = "crate::saved_state::dense_matrix")]
    lu: Mat<f64>,
    perm: Vec<usize>,
    perm_inv: Vec<usize>,
    factored: bool,
}

impl DenseLu {
    /// Workspace for an `n × n` system, not yet factored.
    pub fn new(n: usize) -> Self {
        Self {
            lu: Mat::zeros(n, n),
            perm: (0..n).collect(),
            perm_inv: (0..n).collect(),
            factored: false,
        }
    }

    /// Storage to be filled with the matrix before [`Self::factor`].
    pub fn matrix_mut(&mut self) -> &mut Mat<f64> {
        self.factored = false;
        &mut self.lu
    }

    /// Factorises the matrix written through [`Self::matrix_mut`]. Returns `false` when a pivot
    /// is zero or not finite (the matrix is singular to working precision).
    pub fn factor(&mut self) -> bool {
        let n = self.lu.nrows();
        let par = Par::Seq;
        let mut mem = MemBuffer::new(factor::lu_in_place_scratch::<usize, f64>(
            n,
            n,
            par,
            Default::default(),
        ));
        factor::lu_in_place(
            self.lu.as_mut(),
            &mut self.perm,
            &mut self.perm_inv,
            par,
            MemStack::new(&mut mem),
            Default::default(),
        );
        self.factored = (0..n).all(|i| {
            let d = self.lu[(i, i)];
            d != 0.0 && d.is_finite()
        });
        self.factored
    }

    /// Whether the last [`Self::factor`] succeeded (a solve needs one).
    pub fn is_factored(&self) -> bool {
        self.factored
    }

    /// Solves `A x = b` in place. Must follow a successful [`Self::factor`].
    pub fn solve_in_place(&self, b: &mut [f64]) {
        let n = self.lu.nrows();
        if n <= SMALL_SOLVE {
            self.solve_small(b);
            return;
        }
        self.solve_columns_in_place(MatMut::from_column_major_slice_mut(b, n, 1));
    }

    /// Permutation and the two triangular substitutions as plain loops over the factors: for the
    /// engine block's 25–27 unknowns faer's general solve spends most of its ~1 µs setting up
    /// (scratch allocation, dispatch), four times what the `n²` operations take.
    fn solve_small(&self, b: &mut [f64]) {
        let n = self.lu.nrows();
        let mut x = [0.0; SMALL_SOLVE];
        for (xi, &p) in x.iter_mut().zip(&self.perm) {
            *xi = b[p];
        }
        // L (unit lower) column by column, then U from the last column back.
        for c in 0..n {
            let xc = x[c];
            if xc != 0.0 {
                for (xr, l) in x[c + 1..n]
                    .iter_mut()
                    .zip(&self.lu.col_as_slice(c)[c + 1..])
                {
                    *xr -= l * xc;
                }
            }
        }
        for c in (0..n).rev() {
            let col = self.lu.col_as_slice(c);
            x[c] /= col[c];
            let xc = x[c];
            for (xr, u) in x[..c].iter_mut().zip(&col[..c]) {
                *xr -= u * xc;
            }
        }
        b.copy_from_slice(&x[..n]);
    }

    /// Solves `A X = B` in place for all columns of `B` at once.
    pub fn solve_columns_in_place(&self, rhs: MatMut<'_, f64>) {
        let n = self.lu.nrows();
        let par = Par::Seq;
        let mut mem = MemBuffer::new(solve::solve_in_place_scratch::<usize, f64>(
            n,
            rhs.ncols(),
            par,
        ));
        let perm = PermRef::new_checked(&self.perm, &self.perm_inv, n);
        solve::solve_in_place(
            self.lu.as_ref(),
            self.lu.as_ref(),
            perm,
            rhs,
            par,
            MemStack::new(&mut mem),
        );
    }

    /// The raw parts for serialisation: the factor storage, the permutation and the flag.
    pub fn parts(&self) -> (&Mat<f64>, &[usize], &[usize], bool) {
        (&self.lu, &self.perm, &self.perm_inv, self.factored)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_pivoting_system() {
        // Needs a row swap: the (0,0) entry is zero.
        let a = [[0.0, 2.0, 1.0], [1.0, 1.0, 0.0], [3.0, 0.0, 1.0]];
        let x_true = [1.0, -2.0, 0.5];
        let mut lu = DenseLu::new(3);
        for i in 0..3 {
            for j in 0..3 {
                lu.matrix_mut()[(i, j)] = a[i][j];
            }
        }
        assert!(lu.factor());
        let mut b: Vec<f64> = (0..3)
            .map(|i| (0..3).map(|j| a[i][j] * x_true[j]).sum())
            .collect();
        lu.solve_in_place(&mut b);
        for i in 0..3 {
            assert!((b[i] - x_true[i]).abs() < 1e-14);
        }
    }

    #[test]
    fn small_solve_matches_the_general_one() {
        for n in [1usize, 5, 27, 64] {
            let mut lu = DenseLu::new(n);
            let a = Mat::from_fn(n, n, |i, j| {
                let x = (i * 7 + j * 13) as f64;
                (x * 0.37).sin() + if i == j { 0.5 } else { 0.0 }
            });
            lu.matrix_mut().copy_from(&a);
            assert!(lu.factor());
            let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.9).cos()).collect();
            let mut small = b.clone();
            lu.solve_small(&mut small);
            let mut general = b.clone();
            lu.solve_columns_in_place(MatMut::from_column_major_slice_mut(&mut general, n, 1));
            for i in 0..n {
                assert!((small[i] - general[i]).abs() < 1e-10 * (1.0 + general[i].abs()));
                let row: f64 = (0..n).map(|j| a[(i, j)] * small[j]).sum();
                assert!((row - b[i]).abs() < 1e-9, "n={n} row {i}");
            }
        }
    }

    #[test]
    fn reports_singular_matrix() {
        let mut lu = DenseLu::new(2);
        lu.matrix_mut()[(0, 0)] = 1.0;
        lu.matrix_mut()[(0, 1)] = 2.0;
        lu.matrix_mut()[(1, 0)] = 2.0;
        lu.matrix_mut()[(1, 1)] = 4.0;
        assert!(!lu.factor());
    }
}
