//! Jacobians of the form `J = blockdiag(J_1, …, J_k) + U Vᵀ` and the Newton solve with
//! `I − γ J` by the Sherman–Morrison–Woodbury identity.
//!
//! A structural model coupled to a modal (Craig-Bampton) body has exactly this shape: the modal
//! equations are uncoupled 2×2 blocks `(η_k, η̇_k)`, the multibody part is one small dense block,
//! and everything that couples them passes through a handful of interface forces (rank = 3 per
//! mount and direction of coupling). Factorising `I − γ J` densely costs `O(n³)`; here it costs
//! the small blocks plus `O(n r²)` for the rank-`r` correction, and a solve costs `O(n r)`, so
//! the chassis may keep thousands of modes.
//!
//! With `D = I − γ blockdiag(J_i)` and `Y = D⁻¹ U`:
//! `(D − γ U Vᵀ)⁻¹ b = D⁻¹ b + γ Y (I_r − γ Vᵀ Y)⁻¹ Vᵀ D⁻¹ b`.

use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, MatMut, MatRef, Par};

use super::dense_lu::DenseLu;

/// Which states form each diagonal block, and the rank of the coupling `U Vᵀ`.
#[derive(Debug, Clone, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct BlockLowRankShape {
    /// State indices of each block; together they must list every state exactly once. Within a
    /// block the order of the indices is the order of the block's rows and columns.
    pub blocks: Vec<Vec<usize>>,
    /// Number of columns of `U` and `V`.
    pub rank: usize,
}

impl BlockLowRankShape {
    /// Checks that the blocks partition `0..n` and the rank is at most `n`.
    pub fn validate(&self, n: usize) -> Result<(), String> {
        let mut seen = vec![false; n];
        for (k, block) in self.blocks.iter().enumerate() {
            if block.is_empty() {
                return Err(format!("block {k} is empty"));
            }
            for &i in block {
                if i >= n {
                    return Err(format!("block {k} names state {i} of a system of {n}"));
                }
                if std::mem::replace(&mut seen[i], true) {
                    return Err(format!("state {i} appears in more than one block"));
                }
            }
        }
        if let Some(i) = seen.iter().position(|s| !s) {
            return Err(format!("state {i} belongs to no block"));
        }
        if self.rank > n {
            return Err(format!("rank {} exceeds the dimension {n}", self.rank));
        }
        Ok(())
    }

    /// Number of states.
    pub fn dim(&self) -> usize {
        self.blocks.iter().map(Vec::len).sum()
    }
}

/// Values of a Jacobian `J = blockdiag(J_1, …, J_k) + U Vᵀ` with a given shape.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
#[serde(into = "SavedBlockLowRank", try_from = "SavedBlockLowRank")]
pub struct BlockLowRankJacobian {
    shape: BlockLowRankShape,
    /// The blocks, column-major, one after the other.
    values: Vec<f64>,
    /// Start of each block in `values` (one more entry than blocks).
    offsets: Vec<usize>,
    u: Mat<f64>,
    v: Mat<f64>,
}

/// A [`BlockLowRankJacobian`] as saved: its shape and values; the offsets follow from the shape.
#[derive(Clone, serde::Serialize, serde::Deserialize)]
struct SavedBlockLowRank {
    shape: BlockLowRankShape,
    values: Vec<f64>,
    #[serde(with = "crate::saved_state::dense_matrix")]
    u: Mat<f64>,
    #[serde(with = "crate::saved_state::dense_matrix")]
    v: Mat<f64>,
}

impl From<BlockLowRankJacobian> for SavedBlockLowRank {
    fn from(j: BlockLowRankJacobian) -> Self {
        Self {
            shape: j.shape,
            values: j.values,
            u: j.u,
            v: j.v,
        }
    }
}

impl TryFrom<SavedBlockLowRank> for BlockLowRankJacobian {
    type Error = String;

    fn try_from(s: SavedBlockLowRank) -> Result<Self, String> {
        s.shape.validate(s.u.nrows())?;
        Self::from_values(s.shape, s.values, s.u, s.v)
            .ok_or_else(|| "the saved Jacobian's sizes do not match its block shape".to_string())
    }
}

impl BlockLowRankJacobian {
    /// A zero Jacobian of the given (validated) shape.
    pub fn new(shape: BlockLowRankShape) -> Self {
        let mut offsets = Vec::with_capacity(shape.blocks.len() + 1);
        let mut end = 0;
        offsets.push(0);
        for b in &shape.blocks {
            end += b.len() * b.len();
            offsets.push(end);
        }
        let n = shape.dim();
        let r = shape.rank;
        Self {
            shape,
            values: vec![0.0; end],
            offsets,
            u: Mat::zeros(n, r),
            v: Mat::zeros(n, r),
        }
    }

    /// The block structure and rank this Jacobian was made for.
    pub fn shape(&self) -> &BlockLowRankShape {
        &self.shape
    }

    /// Number of unknowns `n`.
    pub fn dim(&self) -> usize {
        self.u.nrows()
    }

    /// Block `k` (rows and columns in the order of `shape().blocks[k]`).
    pub fn block(&self, k: usize) -> MatRef<'_, f64> {
        let size = self.shape.blocks[k].len();
        MatRef::from_column_major_slice(
            &self.values[self.offsets[k]..self.offsets[k + 1]],
            size,
            size,
        )
    }

    /// Diagonal block `k` (column-major, in the order of its indices in the shape), for writing.
    pub fn block_mut(&mut self, k: usize) -> MatMut<'_, f64> {
        let size = self.shape.blocks[k].len();
        MatMut::from_column_major_slice_mut(
            &mut self.values[self.offsets[k]..self.offsets[k + 1]],
            size,
            size,
        )
    }

    /// `U` (n × rank).
    pub fn u(&self) -> MatRef<'_, f64> {
        self.u.as_ref()
    }

    /// `U` (n × rank), for writing.
    pub fn u_mut(&mut self) -> MatMut<'_, f64> {
        self.u.as_mut()
    }

    /// `V` (n × rank): the coupling is `U Vᵀ`.
    pub fn v(&self) -> MatRef<'_, f64> {
        self.v.as_ref()
    }

    /// `V` (n × rank), for writing.
    pub fn v_mut(&mut self) -> MatMut<'_, f64> {
        self.v.as_mut()
    }

    /// Sets every value to zero.
    pub fn clear(&mut self) {
        self.values.fill(0.0);
        self.u.fill(0.0);
        self.v.fill(0.0);
    }

    /// Whether every value is finite.
    pub fn is_finite(&self) -> bool {
        self.values.iter().all(|x| x.is_finite())
            && self.u.col_iter().all(|c| c.iter().all(|x| x.is_finite()))
            && self.v.col_iter().all(|c| c.iter().all(|x| x.is_finite()))
    }

    /// Writes the dense `J` into `out` (n × n).
    pub fn to_dense(&self, mut out: MatMut<'_, f64>) {
        matmul(
            out.as_mut(),
            Accum::Replace,
            self.u.as_ref(),
            self.v.transpose(),
            1.0,
            Par::Seq,
        );
        for (k, idx) in self.shape.blocks.iter().enumerate() {
            let b = self.block(k);
            for (c, &j) in idx.iter().enumerate() {
                for (r, &i) in idx.iter().enumerate() {
                    out[(i, j)] += b[(r, c)];
                }
            }
        }
    }

    /// Rebuilds from a shape and raw values; `None` when the sizes do not match the shape.
    pub(super) fn from_values(
        shape: BlockLowRankShape,
        values: Vec<f64>,
        u: Mat<f64>,
        v: Mat<f64>,
    ) -> Option<Self> {
        let mut j = Self::new(shape);
        if values.len() != j.values.len()
            || (u.nrows(), u.ncols()) != (j.u.nrows(), j.u.ncols())
            || (v.nrows(), v.ncols()) != (j.v.nrows(), j.v.ncols())
        {
            return None;
        }
        j.values = values;
        j.u = u;
        j.v = v;
        Some(j)
    }
}

/// Inverse of one diagonal block of `D = I − γ J_block`.
///
/// Every block is applied through its explicit inverse: the blocks are small and well
/// conditioned (`γ J` is of order one at most), and a solve is then one small matrix–vector
/// product instead of two triangular sweeps, which for the few dozen engine states costs less than
/// the call overhead of a general triangular solve.
#[derive(Debug, Clone, PartialEq)]
enum BlockInverse {
    /// 1×1 and 2×2 blocks (the modal pairs), column-major.
    Small([f64; 4]),
    /// Larger blocks: formed with faer's partial-pivoting LU (kept for its storage).
    Dense { lu: DenseLu, inverse: Mat<f64> },
}

/// `I − γ J` for a [`BlockLowRankJacobian`], factorised for repeated solves.
#[derive(Debug, Clone, PartialEq)]
pub struct BlockLowRankLu {
    blocks: Vec<Vec<usize>>,
    inverses: Vec<BlockInverse>,
    /// `Y = D⁻¹ U`.
    correction: Mat<f64>,
    /// `V` of the factorised Jacobian.
    v: Mat<f64>,
    /// `I_r − γ Vᵀ D⁻¹ U`, factorised, and `γ` times its inverse. The solve applies
    /// `Y (γ C⁻¹) Vᵀ` as three thin products (`2 n r + r²` per solve) rather than forming
    /// `Y C⁻¹` at every factorisation (`n r²`, the larger part of a factorisation's cost).
    capacitance: DenseLu,
    capacitance_inverse: Mat<f64>,
    /// `γ` of the last successful factorisation.
    factored_with: Option<f64>,
}

/// A pivot this small relative to the entries that formed it marks a singular 2×2 block.
const SINGULAR_PIVOT: f64 = 1e-14;

/// The inverse of a factorised dense matrix.
fn inverse_of(lu: &DenseLu, n: usize) -> Mat<f64> {
    let mut inv = Mat::<f64>::identity(n, n);
    lu.solve_columns_in_place(inv.as_mut());
    inv
}

impl BlockLowRankLu {
    /// Workspace for a Newton matrix of this shape, not yet factored.
    pub fn new(shape: &BlockLowRankShape) -> Self {
        let n = shape.dim();
        let r = shape.rank;
        Self {
            blocks: shape.blocks.clone(),
            inverses: shape
                .blocks
                .iter()
                .map(|b| {
                    if b.len() <= 2 {
                        BlockInverse::Small([0.0; 4])
                    } else {
                        BlockInverse::Dense {
                            lu: DenseLu::new(b.len()),
                            inverse: Mat::zeros(b.len(), b.len()),
                        }
                    }
                })
                .collect(),
            correction: Mat::zeros(n, r),
            v: Mat::zeros(n, r),
            capacitance: DenseLu::new(r),
            capacitance_inverse: Mat::zeros(r, r),
            factored_with: None,
        }
    }

    /// Whether the last factorisation succeeded (a solve needs one).
    pub fn is_factored(&self) -> bool {
        self.factored_with.is_some()
    }

    /// `γ` of the factorisation in force, if any.
    pub fn factored_gamma(&self) -> Option<f64> {
        self.factored_with
    }

    /// Factorises `I − γ J`. Returns `false` when a block or the capacitance matrix is singular
    /// to working precision.
    pub fn factor(&mut self, j: &BlockLowRankJacobian, gamma: f64) -> bool {
        self.factored_with = None;
        for (k, inverse) in self.inverses.iter_mut().enumerate() {
            let b = j.block(k);
            let ok = match inverse {
                BlockInverse::Small(inv) => invert_small(b, gamma, inv),
                BlockInverse::Dense { lu, inverse } => {
                    let a = lu.matrix_mut();
                    for c in 0..b.ncols() {
                        for r in 0..b.nrows() {
                            a[(r, c)] = -gamma * b[(r, c)] + if r == c { 1.0 } else { 0.0 };
                        }
                    }
                    let ok = lu.factor();
                    if ok {
                        *inverse = inverse_of(lu, b.nrows());
                    }
                    ok
                }
            };
            if !ok {
                return false;
            }
        }
        let r = j.shape().rank;
        if r == 0 {
            self.factored_with = Some(gamma);
            return true;
        }
        // Y = D⁻¹ U.
        let y = &mut self.correction;
        y.copy_from(j.u());
        for (idx, inverse) in self.blocks.iter().zip(&self.inverses) {
            match inverse {
                BlockInverse::Small(inv) => {
                    for c in 0..r {
                        apply_small_inverse(inv, idx, y.col_as_slice_mut(c));
                    }
                }
                BlockInverse::Dense { inverse, .. } => {
                    let rows = Mat::from_fn(idx.len(), r, |i, c| y[(idx[i], c)]);
                    let solved = inverse * &rows;
                    for c in 0..r {
                        for (i, &row) in idx.iter().enumerate() {
                            y[(row, c)] = solved[(i, c)];
                        }
                    }
                }
            }
        }
        self.v.copy_from(j.v());
        let cap = self.capacitance.matrix_mut();
        matmul(
            cap.as_mut(),
            Accum::Replace,
            self.v.transpose(),
            self.correction.as_ref(),
            -gamma,
            Par::Seq,
        );
        for i in 0..r {
            cap[(i, i)] += 1.0;
        }
        if !self.capacitance.factor() {
            return false;
        }
        self.capacitance_inverse = inverse_of(&self.capacitance, r) * gamma;
        self.factored_with = Some(gamma);
        true
    }

    /// Solves `(I − γ J) x = b` in place. Must follow a successful [`Self::factor`].
    pub fn solve_in_place(&self, b: &mut [f64]) {
        block_solve(&self.blocks, &self.inverses, b);
        let (n, r) = (b.len(), self.v.ncols());
        if r == 0 {
            return;
        }
        // x = D⁻¹ b + Y (γ (I − γ Vᵀ Y)⁻¹) Vᵀ D⁻¹ b, the r-vectors on the stack for the usual
        // ranks (6 per mount).
        let mut stack = [0.0; 2 * STACK_RANK];
        let mut heap = Vec::new();
        let buffer: &mut [f64] = if r <= STACK_RANK {
            &mut stack[..2 * r]
        } else {
            heap.resize(2 * r, 0.0);
            &mut heap
        };
        let (s, t) = buffer.split_at_mut(r);
        let x = MatRef::from_column_major_slice(b, n, 1);
        matmul(
            MatMut::from_column_major_slice_mut(s, r, 1),
            Accum::Replace,
            self.v.transpose(),
            x,
            1.0,
            Par::Seq,
        );
        matmul(
            MatMut::from_column_major_slice_mut(t, r, 1),
            Accum::Replace,
            self.capacitance_inverse.as_ref(),
            MatRef::from_column_major_slice(s, r, 1),
            1.0,
            Par::Seq,
        );
        let x = MatMut::from_column_major_slice_mut(b, n, 1);
        matmul(
            x,
            Accum::Add,
            self.correction.as_ref(),
            MatRef::from_column_major_slice(t, r, 1),
            1.0,
            Par::Seq,
        );
    }
}

/// Ranks (and dense block sizes) whose scratch vectors live on the stack in a solve.
const STACK_RANK: usize = 64;

/// Inverse of `I − γ B` for a 1×1 or 2×2 block `B`, column-major in `inv`.
fn invert_small(b: MatRef<'_, f64>, gamma: f64, inv: &mut [f64; 4]) -> bool {
    if b.nrows() == 1 {
        let d = 1.0 - gamma * b[(0, 0)];
        inv[0] = 1.0 / d;
        return d != 0.0 && inv[0].is_finite();
    }
    let (a11, a21) = (1.0 - gamma * b[(0, 0)], -gamma * b[(1, 0)]);
    let (a12, a22) = (-gamma * b[(0, 1)], 1.0 - gamma * b[(1, 1)]);
    let det = a11 * a22 - a12 * a21;
    let scale = (a11 * a22).abs() + (a12 * a21).abs();
    if !(det.is_finite() && det.abs() > SINGULAR_PIVOT * scale) {
        return false;
    }
    *inv = [a22 / det, -a21 / det, -a12 / det, a11 / det];
    true
}

/// `x[idx] ← inv · x[idx]` for a 1×1 or 2×2 block.
fn apply_small_inverse(inv: &[f64; 4], idx: &[usize], x: &mut [f64]) {
    if idx.len() == 1 {
        x[idx[0]] *= inv[0];
    } else {
        let (i, j) = (idx[0], idx[1]);
        let (a, b) = (x[i], x[j]);
        x[i] = inv[0] * a + inv[2] * b;
        x[j] = inv[1] * a + inv[3] * b;
    }
}

/// `x ← D⁻¹ x` block by block.
fn block_solve(blocks: &[Vec<usize>], inverses: &[BlockInverse], x: &mut [f64]) {
    for (idx, inverse) in blocks.iter().zip(inverses) {
        match inverse {
            BlockInverse::Small(inv) => apply_small_inverse(inv, idx, x),
            BlockInverse::Dense { inverse, .. } => {
                let mut stack = [0.0; STACK_RANK];
                let mut heap = Vec::new();
                let out: &mut [f64] = if idx.len() <= STACK_RANK {
                    &mut stack[..idx.len()]
                } else {
                    heap.resize(idx.len(), 0.0);
                    &mut heap
                };
                for (c, &i) in idx.iter().enumerate() {
                    let xc = x[i];
                    for (o, a) in out.iter_mut().zip(inverse.col_as_slice(c)) {
                        *o += a * xc;
                    }
                }
                for (&i, o) in idx.iter().zip(out.iter()) {
                    x[i] = *o;
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 9-state system: a dense 3×3 block on states {0, 4, 8} and three 2×2 pairs, one of them
    /// with its indices in descending order, coupled through rank 2.
    fn example() -> BlockLowRankJacobian {
        let shape = BlockLowRankShape {
            blocks: vec![vec![0, 4, 8], vec![1, 5], vec![2, 6], vec![7, 3]],
            rank: 2,
        };
        assert!(shape.validate(9).is_ok());
        let mut j = BlockLowRankJacobian::new(shape);
        let mut seed = 0.3_f64;
        let mut next = || {
            seed = (seed * 7.31 + 0.17).fract();
            seed - 0.5
        };
        for k in 0..4 {
            let mut b = j.block_mut(k);
            for c in 0..b.ncols() {
                for r in 0..b.nrows() {
                    b[(r, c)] = 40.0 * next() - if r == c { 30.0 } else { 0.0 };
                }
            }
        }
        for c in 0..2 {
            for r in 0..9 {
                j.u_mut()[(r, c)] = 10.0 * next();
                j.v_mut()[(r, c)] = 10.0 * next();
            }
        }
        j
    }

    #[test]
    fn woodbury_solve_equals_the_dense_lu_solve() {
        let j = example();
        let n = j.dim();
        let mut dense = Mat::zeros(n, n);
        j.to_dense(dense.as_mut());
        for gamma in [1e-4, 0.01, 0.3] {
            let mut lu = BlockLowRankLu::new(j.shape());
            assert!(lu.factor(&j, gamma));
            let mut reference = DenseLu::new(n);
            for c in 0..n {
                for r in 0..n {
                    reference.matrix_mut()[(r, c)] =
                        -gamma * dense[(r, c)] + if r == c { 1.0 } else { 0.0 };
                }
            }
            assert!(reference.factor());
            let b: Vec<f64> = (0..n).map(|i| (i as f64 * 0.7).sin() + 0.1).collect();
            let mut x = b.clone();
            lu.solve_in_place(&mut x);
            let mut x_ref = b.clone();
            reference.solve_in_place(&mut x_ref);
            let scale = x_ref.iter().fold(0.0_f64, |a, v| a.max(v.abs()));
            for (a, e) in x.iter().zip(&x_ref) {
                assert!(
                    (a - e).abs() <= 1e-12 * scale,
                    "{a} vs {e} at gamma {gamma}"
                );
            }
        }
    }

    #[test]
    fn dense_expansion_places_blocks_at_their_indices() {
        let j = example();
        let mut dense = Mat::zeros(9, 9);
        j.to_dense(dense.as_mut());
        // Entry (7, 3) comes from block 3 (row 0 ↔ state 7, column 1 ↔ state 3) plus U Vᵀ.
        let uv: f64 = (0..2).map(|c| j.u()[(7, c)] * j.v()[(3, c)]).sum();
        assert_eq!(dense[(7, 3)], j.block(3)[(0, 1)] + uv);
        // States 0 and 1 are in different blocks: only the low-rank part couples them.
        let uv: f64 = (0..2).map(|c| j.u()[(0, c)] * j.v()[(1, c)]).sum();
        assert_eq!(dense[(0, 1)], uv);
    }

    #[test]
    fn singular_pair_is_reported() {
        let shape = BlockLowRankShape {
            blocks: vec![vec![0, 1]],
            rank: 0,
        };
        let mut j = BlockLowRankJacobian::new(shape);
        // I − 1·B = [[0, 0], [0, 1]] is singular.
        j.block_mut(0)[(0, 0)] = 1.0;
        let mut lu = BlockLowRankLu::new(j.shape());
        assert!(!lu.factor(&j, 1.0));
        assert!(!lu.is_factored());
    }

    #[test]
    fn shapes_that_do_not_partition_the_states_are_rejected() {
        let bad = |blocks: Vec<Vec<usize>>, rank| BlockLowRankShape { blocks, rank }.validate(3);
        assert!(bad(vec![vec![0, 1], vec![2]], 1).is_ok());
        assert!(bad(vec![vec![0, 1]], 0).unwrap_err().contains("state 2"));
        assert!(bad(vec![vec![0, 1], vec![1, 2]], 0)
            .unwrap_err()
            .contains("more than one"));
        assert!(bad(vec![vec![0, 1, 2, 3]], 0)
            .unwrap_err()
            .contains("state 3"));
        assert!(bad(vec![vec![0, 1, 2]], 4).unwrap_err().contains("rank"));
        assert!(bad(vec![vec![0, 1, 2], vec![]], 0)
            .unwrap_err()
            .contains("empty"));
    }
}
