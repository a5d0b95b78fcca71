//! Partitioning of the sparse FE matrices into interior and interface blocks.

use faer::sparse::{SparseColMat, Triplet};
use faer::Mat;

use super::error::CmsError;
use crate::fe::assembly::SparseMat;

/// Split of the equations into interior (I) and interface/boundary (B) sets.
pub struct Partition {
    /// For every global equation: its interior index, or `None` if it is an interface DOF.
    interior_of: Vec<Option<usize>>,
    /// Global equation of every interior index.
    pub interior: Vec<usize>,
    /// Global equation of every interface index, in the caller's order.
    pub boundary: Vec<usize>,
}

impl Partition {
    /// Interface DOFs `boundary` (global equations, distinct, in range) of an `n`-equation model.
    pub fn new(n: usize, boundary: &[usize]) -> Result<Self, CmsError> {
        if boundary.is_empty() {
            return Err(CmsError::InvalidInput("the interface has no DOF".into()));
        }
        let mut is_boundary = vec![false; n];
        for (i, &g) in boundary.iter().enumerate() {
            if g >= n {
                return Err(CmsError::InvalidInput(format!(
                    "interface DOF {i} is equation {g}, the model has {n}"
                )));
            }
            if is_boundary[g] {
                return Err(CmsError::InvalidInput(format!(
                    "interface DOF {i} (equation {g}) appears twice"
                )));
            }
            is_boundary[g] = true;
        }
        if boundary.len() >= n {
            return Err(CmsError::InvalidInput(format!(
                "all {n} equations are interface DOFs: nothing to reduce"
            )));
        }
        let mut interior = Vec::with_capacity(n - boundary.len());
        let interior_of = is_boundary
            .iter()
            .enumerate()
            .map(|(g, &b)| {
                if b {
                    None
                } else {
                    interior.push(g);
                    Some(interior.len() - 1)
                }
            })
            .collect();
        Ok(Self {
            interior_of,
            interior,
            boundary: boundary.to_vec(),
        })
    }

    /// The interior-interior block of `a` as a sparse matrix.
    pub fn interior_block(&self, a: &SparseMat, what: &str) -> Result<SparseMat, CmsError> {
        let (cp, ri, val) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
        let mut entries = Vec::with_capacity(a.compute_nnz());
        for j in 0..a.ncols() {
            let Some(jj) = self.interior_of[j] else {
                continue;
            };
            for p in cp[j]..cp[j + 1] {
                if let Some(ii) = self.interior_of[ri[p]] {
                    entries.push(Triplet::new(ii, jj, val[p]));
                }
            }
        }
        let ni = self.interior.len();
        SparseColMat::try_new_from_triplets(ni, ni, &entries).map_err(|e| {
            CmsError::Numerical(format!("extracting the interior block of {what}: {e:?}"))
        })
    }

    /// The interior-interface block `A_IB` as a dense matrix (interior rows, interface columns).
    pub fn interior_boundary_block(&self, a: &SparseMat) -> Mat<f64> {
        let (cp, ri, val) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
        let mut out = Mat::<f64>::zeros(self.interior.len(), self.boundary.len());
        for (b, &j) in self.boundary.iter().enumerate() {
            for p in cp[j]..cp[j + 1] {
                if let Some(ii) = self.interior_of[ri[p]] {
                    out[(ii, b)] += val[p];
                }
            }
        }
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dense_example() -> (SparseMat, Mat<f64>) {
        let d = Mat::from_fn(4, 4, |i, j| {
            if i == j {
                4.0 + i as f64
            } else if i.abs_diff(j) == 1 {
                -1.0 - (i + j) as f64 * 0.1
            } else {
                0.0
            }
        });
        let mut entries = Vec::new();
        for j in 0..4 {
            for i in 0..4 {
                if d[(i, j)] != 0.0 {
                    entries.push(Triplet::new(i, j, d[(i, j)]));
                }
            }
        }
        (
            SparseColMat::try_new_from_triplets(4, 4, &entries).unwrap(),
            d,
        )
    }

    #[test]
    fn blocks_match_the_dense_matrix() {
        let (a, d) = dense_example();
        let part = Partition::new(4, &[3, 1]).unwrap();
        assert_eq!(part.interior, vec![0, 2]);
        let ii = part.interior_block(&a, "A").unwrap().to_dense();
        let ib = part.interior_boundary_block(&a);
        for (r, &gr) in [0usize, 2].iter().enumerate() {
            for (c, &gc) in [0usize, 2].iter().enumerate() {
                assert_eq!(ii[(r, c)], d[(gr, gc)]);
            }
            for (c, &gc) in [3usize, 1].iter().enumerate() {
                assert_eq!(ib[(r, c)], d[(gr, gc)]);
            }
        }
    }

    #[test]
    fn bad_interfaces_are_named() {
        assert!(Partition::new(4, &[]).is_err());
        let e = Partition::new(4, &[1, 7]).err().unwrap().to_string();
        assert!(
            e.contains("interface DOF 1") && e.contains("equation 7"),
            "{e}"
        );
        let e = Partition::new(4, &[2, 2]).err().unwrap().to_string();
        assert!(e.contains("appears twice"), "{e}");
        assert!(Partition::new(2, &[0, 1]).is_err());
    }
}
