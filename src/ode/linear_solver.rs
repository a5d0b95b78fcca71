//! The Newton iteration matrix `M − γ J`: the Jacobian it is built from and its factorisation,
//! dense (faer's partial-pivoting LU) or block-diagonal plus low rank ([`super::block_low_rank`]).

use faer::Mat;

use super::block_low_rank::{BlockLowRankJacobian, BlockLowRankLu, BlockLowRankShape};
use super::dense_lu::DenseLu;

/// The saved Jacobian and the factorised iteration matrix built from it.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(into = "SavedIterationMatrix", try_from = "SavedIterationMatrix")]
pub enum IterationMatrix {
    /// Any problem: `J` dense (analytic or by finite differences), `M − γ J` by dense LU.
    Dense { saved_j: Mat<f64>, lu: DenseLu },
    /// Problems that supply `J = blockdiag + U Vᵀ` (with `M = I`): Woodbury solve, no n × n matrix.
    BlockLowRank {
        saved_j: Box<BlockLowRankJacobian>,
        lu: Box<BlockLowRankLu>,
    },
}

/// How an [`IterationMatrix`] is saved: the dense factorisation as it is (its pivoting is not
/// reproducible from `J` alone once `M` varies); the block-plus-low-rank one as the Jacobian
/// and the `γ` it was factorised with, refactorised on loading (deterministic, so bit for bit).
#[derive(Clone, serde::Serialize, serde::Deserialize)]
enum SavedIterationMatrix {
    Dense {
        #[serde(with = "crate::saved_state::dense_matrix")]
        saved_j: Mat<f64>,
        lu: DenseLu,
    },
    BlockLowRank {
        saved_j: BlockLowRankJacobian,
        factored_gamma: Option<f64>,
    },
}

impl From<IterationMatrix> for SavedIterationMatrix {
    fn from(m: IterationMatrix) -> Self {
        match m {
            IterationMatrix::Dense { saved_j, lu } => Self::Dense { saved_j, lu },
            IterationMatrix::BlockLowRank { saved_j, lu } => Self::BlockLowRank {
                saved_j: *saved_j,
                factored_gamma: lu.factored_gamma(),
            },
        }
    }
}

impl TryFrom<SavedIterationMatrix> for IterationMatrix {
    type Error = String;

    fn try_from(m: SavedIterationMatrix) -> Result<Self, String> {
        match m {
            SavedIterationMatrix::Dense { saved_j, lu } => {
                let n = saved_j.nrows();
                let (lu_values, perm, perm_inv, _) = lu.parts();
                if saved_j.ncols() != n
                    || (lu_values.nrows(), lu_values.ncols()) != (n, n)
                    || perm.len() != n
                    || perm_inv.len() != n
                    || (0..n).any(|i| perm[i] >= n || perm_inv[i] >= n || perm_inv[perm[i]] != i)
                {
                    return Err("the saved dense iteration matrix is inconsistent".into());
                }
                Ok(Self::Dense { saved_j, lu })
            }
            SavedIterationMatrix::BlockLowRank {
                saved_j,
                factored_gamma,
            } => {
                let mut lu = BlockLowRankLu::new(saved_j.shape());
                if let Some(gamma) = factored_gamma {
                    if !lu.factor(&saved_j, gamma) {
                        return Err("the saved iteration matrix is singular".into());
                    }
                }
                Ok(Self::BlockLowRank {
                    saved_j: Box::new(saved_j),
                    lu: Box::new(lu),
                })
            }
        }
    }
}

impl IterationMatrix {
    /// The dimension of the system.
    pub fn dim(&self) -> usize {
        match self {
            Self::Dense { saved_j, .. } => saved_j.nrows(),
            Self::BlockLowRank { saved_j, .. } => saved_j.dim(),
        }
    }

    pub fn dense(n: usize) -> Self {
        Self::Dense {
            saved_j: Mat::zeros(n, n),
            lu: DenseLu::new(n),
        }
    }

    pub fn block_low_rank(shape: BlockLowRankShape) -> Self {
        Self::BlockLowRank {
            lu: Box::new(BlockLowRankLu::new(&shape)),
            saved_j: Box::new(BlockLowRankJacobian::new(shape)),
        }
    }

    pub fn is_factored(&self) -> bool {
        match self {
            Self::Dense { lu, .. } => lu.is_factored(),
            Self::BlockLowRank { lu, .. } => lu.is_factored(),
        }
    }

    /// Whether `other` has the same kind, dimension and block shape (snapshots must match).
    pub fn same_structure(&self, other: &Self) -> bool {
        match (self, other) {
            (Self::Dense { saved_j: a, .. }, Self::Dense { saved_j: b, .. }) => {
                a.nrows() == b.nrows()
            }
            (Self::BlockLowRank { saved_j: a, .. }, Self::BlockLowRank { saved_j: b, .. }) => {
                a.shape() == b.shape()
            }
            _ => false,
        }
    }

    /// Solves `(M − γ J) x = b` in place with the last factorisation.
    pub fn solve_in_place(&self, b: &mut [f64]) {
        match self {
            Self::Dense { lu, .. } => lu.solve_in_place(b),
            Self::BlockLowRank { lu, .. } => lu.solve_in_place(b),
        }
    }
}
