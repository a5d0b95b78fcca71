//! Many eigenpairs of (K, M) by spectrum slicing: shift-invert block Lanczos at several shifts,
//! each slice's completeness proved by Sturm counts.
//!
//! [`super::shift_invert::lowest_modes`] runs one Lanczos process at one shift and keeps every Krylov
//! vector; its basis grows to several times the number of modes asked for, so its
//! reorthogonalisation costs O(n·m²) and its Rayleigh-Ritz steps O(m³) for m modes, and its
//! memory is 2·n·6m numbers. Above a few hundred modes that is what limits the reduction.
//! Production eigensolvers (Grimes, Lewis & Simon 1994, the Lanczos of MSC/NX Nastran; SLEPc's
//! Krylov-Schur with spectrum slicing) cut the wanted interval into slices instead:
//!
//! - **Factor once per shift.** K − σM is factored as LDLᵀ (faer's sparse supernodal LDLᵀ
//!   without pivoting; it works for the indefinite matrices of interior shifts, where faer's
//!   Cholesky fails). By Sylvester's law of inertia the number of negative entries of D is the
//!   number of eigenvalues below σ: a **Sturm count**, exact as long as the factorization is
//!   backward stable. Each factorization is checked by the residual of one solve and the shift
//!   is moved if that residual is poor (a pivot close to zero: σ next to an eigenvalue).
//!   Shifts are put in the middle of gaps between Ritz values for the same reason.
//! - **Sweep upward.** The shifts σ₀ = `lower` < σ₁ < … are visited one after another (one
//!   factorization in memory at a time). At σⱼ a Lanczos process with a bounded basis converges
//!   the eigenvalues nearest σⱼ, on both sides. The slice (σⱼ₋₁, σⱼ\] is complete when the
//!   eigenpairs found in it, by this run or already by the one before, number exactly
//!   ν(σⱼ) − ν(σⱼ₋₁); the ones found above σⱼ are kept for the next slice. A run that
//!   converges only part of its slice within its basis locks what it has and restarts at the
//!   same shift (the factorization is reused).
//! - **Deflate neighbours only.** Each run's Krylov vectors are M-orthogonalised against the
//!   eigenvectors already found near its shift (the slice below and those found above), never
//!   against all modes found so far, so the work per slice is O(n·b·(b + p)) for a basis of b
//!   vectors and p neighbours, and the total grows about linearly with the number of slices.
//!
//! The next shift is extrapolated from the eigenvalue density of the slice just done, aiming at
//! about [`SLICE_MODES`] new modes per slice. Eigenpairs are accepted when their Lanczos residual
//! ‖(K − σM)⁻¹M φ − θ φ‖_M is below 10⁻⁹·|θ|, the criterion of the single-shift solver, so both
//! give the same frequencies to far better than 10⁻⁹. Eigenvectors of different slices are
//! M-orthogonal to the residual tolerance, not to round-off: a caller that needs exact
//! orthogonality (the Craig-Bampton reduction does) re-orthogonalises in its reduced space.
//!
//! [`lowest_modes_auto`] and [`modes_in_interval`] choose between this and the single-shift
//! solver by [`prefer_slicing`]: for few modes of a small model one Lanczos run is as fast (one
//! factorization, no counting); for many modes, or a model so large that the single-shift basis
//! would not fit in a gigabyte, slicing.

use faer::dyn_stack::{MemBuffer, MemStack};
use faer::linalg::cholesky::ldlt::factor::LdltRegularization;
use faer::linalg::matmul::matmul;
use faer::reborrow::{Reborrow, ReborrowMut};
use faer::sparse::linalg::cholesky::supernodal::SupernodalLdltRef;
use faer::sparse::linalg::cholesky::{
    factorize_symbolic_cholesky, LdltRef, SymbolicCholesky, SymbolicCholeskyRaw, SymmetricOrdering,
};
use faer::sparse::linalg::matmul::sparse_dense_matmul;
use faer::sparse::{SparseColMat, SymbolicSparseColMat, Triplet};
use faer::{Accum, Conj, Mat, MatMut, MatRef, Par, Side};

use super::shift_invert::{check_pencil, lowest_modes, Modes, Xorshift};
use crate::fe::assembly::SparseMat;
use crate::fe::error::FeError;

/// Mode count from which [`prefer_slicing`] picks spectrum slicing. Measured on the
/// 15,300-DOF default body (docs, evidence "Production size"): 80 modes take 1.1 s either way,
/// 209 modes 4.4 s single-shift against 3.3 s sliced, 1,044 modes 486 s against 33 s.
pub const SLICING_MIN_MODES: usize = 120;

/// Largest Krylov basis (bytes) [`prefer_slicing`] lets the single-shift solver allocate: it
/// keeps 2 × n × (6m + 64) numbers for m modes, 8 GB for 80 modes of a million-DOF body, and
/// its reorthogonalisation time grows with the same product.
pub const SINGLE_SHIFT_MAX_BASIS_BYTES: usize = 1 << 30;

/// Whether `n_modes` eigenpairs of an `n`-DOF pencil are computed by spectrum slicing rather
/// than by one shift-invert Lanczos run: from [`SLICING_MIN_MODES`] modes on, or when the
/// single-shift basis would exceed [`SINGLE_SHIFT_MAX_BASIS_BYTES`].
pub fn prefer_slicing(n: usize, n_modes: usize) -> bool {
    let basis = n.min((6 * n_modes + 64).max(n_modes + 100));
    n_modes >= SLICING_MIN_MODES || 2 * 8 * n * basis > SINGLE_SHIFT_MAX_BASIS_BYTES
}

/// New modes aimed for per slice. Larger slices need fewer factorizations but a larger Krylov
/// basis (memory n × basis, cost n·basis²).
pub const SLICE_MODES: usize = 64;

const BLOCK: usize = 8;
const RESIDUAL_TOLERANCE: f64 = 1e-9;
/// Relative residual of one solve above which a factorization is taken as unstable.
const SOLVE_RESIDUAL_LIMIT: f64 = 1e-6;

/// Where the sweep stops.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SliceStop {
    /// The `n` lowest eigenpairs above the lower end.
    Count(usize),
    /// Every eigenpair with eigenvalue in (lower, upper\].
    Upper(f64),
}

/// K and M on the union of their patterns, so that K − σM is one value array per shift.
struct Pencil {
    pattern: SymbolicSparseColMat<usize>,
    k: Vec<f64>,
    m: Vec<f64>,
}

impl Pencil {
    fn new(k: &SparseMat, m: &SparseMat) -> Result<Self, FeError> {
        let n = k.nrows();
        let mut entries = Vec::with_capacity(k.compute_nnz() + m.compute_nnz());
        for a in [k, m] {
            let (cp, ri) = (a.symbolic().col_ptr(), a.symbolic().row_idx());
            for j in 0..n {
                for &i in &ri[cp[j]..cp[j + 1]] {
                    // The factorization reads the lower triangle only.
                    if i >= j {
                        entries.push(Triplet::new(i, j, 1.0));
                    }
                }
            }
        }
        let ones = SparseColMat::<usize, f64>::try_new_from_triplets(n, n, &entries)
            .map_err(|e| FeError::Numerical(format!("pattern of K - shift*M: {e:?}")))?;
        drop(entries);
        let pattern = ones.symbolic().to_owned().map_err(|e| {
            FeError::Numerical(format!("pattern of K - shift*M: out of memory ({e:?})"))
        })?;
        let on_pattern = |a: &SparseMat| {
            let mut v = vec![0.0; pattern.row_idx().len()];
            let (cp, ri, val) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
            let (pcp, pri) = (pattern.col_ptr(), pattern.row_idx());
            for j in 0..n {
                let rows = &pri[pcp[j]..pcp[j + 1]];
                for p in cp[j]..cp[j + 1] {
                    if ri[p] >= j {
                        // Rows of a column are sorted in the pattern built from triplets.
                        let at = rows
                            .binary_search(&ri[p])
                            .expect("entry in the union pattern");
                        v[pcp[j] + at] += val[p];
                    }
                }
            }
            v
        };
        let kv = on_pattern(k);
        let mv = on_pattern(m);
        Ok(Pencil {
            pattern,
            k: kv,
            m: mv,
        })
    }

    fn shifted(&self, shift: f64) -> SparseColMat<usize, f64> {
        let values = self
            .k
            .iter()
            .zip(&self.m)
            .map(|(k, m)| k - shift * m)
            .collect();
        SparseColMat::new(self.pattern.clone(), values)
    }
}

/// LDLᵀ of K − σM with its inertia.
struct Factor {
    shift: f64,
    values: Vec<f64>,
    /// Number of eigenvalues of (K, M) below the shift.
    below: usize,
}

/// The symbolic analysis shared by every shift, and the parallelism used.
struct Factorizer<'a> {
    pencil: Pencil,
    symbolic: SymbolicCholesky<usize>,
    par: Par,
    k: &'a SparseMat,
    m: &'a SparseMat,
}

impl<'a> Factorizer<'a> {
    fn new(k: &'a SparseMat, m: &'a SparseMat) -> Result<Self, FeError> {
        let pencil = Pencil::new(k, m)?;
        let symbolic = factorize_symbolic_cholesky(
            pencil.pattern.as_ref(),
            Side::Lower,
            SymmetricOrdering::Amd,
            Default::default(),
        )
        .map_err(|e| FeError::Numerical(format!("symbolic LDL^T of K - shift*M: {e:?}")))?;
        Ok(Factorizer {
            pencil,
            symbolic,
            par: faer::get_global_parallelism(),
            k,
            m,
        })
    }

    /// LDLᵀ at `shift`, or at a shift moved up by a small step when the factorization is
    /// singular or unstable there.
    fn factor(&self, shift: f64, scale: f64) -> Result<Factor, FeError> {
        let mut sigma = shift;
        let mut last = String::new();
        for attempt in 0..6 {
            if attempt > 0 {
                // A pivot near zero means an eigenvalue near σ: step away by a fraction of the
                // spectrum's scale that is still far below the slice width.
                sigma = shift + scale * 1e-5 * (1 << attempt) as f64;
            }
            match self.try_factor(sigma) {
                Ok(f) => return Ok(f),
                Err(e) => last = e,
            }
        }
        Err(FeError::Numerical(format!(
            "LDL^T of K - shift*M near shift {shift} failed: {last}"
        )))
    }

    fn try_factor(&self, sigma: f64) -> Result<Factor, String> {
        let a = self.pencil.shifted(sigma);
        let mut values = vec![0.0; self.symbolic.len_val()];
        let params = Default::default();
        let mut mem = MemBuffer::new(
            self.symbolic
                .factorize_numeric_ldlt_scratch::<f64>(self.par, params),
        );
        self.symbolic
            .factorize_numeric_ldlt(
                &mut values,
                a.as_ref(),
                Side::Lower,
                LdltRegularization::default(),
                self.par,
                MemStack::new(&mut mem),
                params,
            )
            .map_err(|e| format!("{e:?}"))?;
        drop(mem);
        if values.iter().any(|v| !v.is_finite()) {
            return Err("non-finite factor".into());
        }
        let below = negative_pivots(&self.symbolic, &values);
        let factor = Factor {
            shift: sigma,
            values,
            below,
        };
        // One solve against a random right-hand side: a small residual means a backward
        // stable factorization, whose inertia is that of K − σM.
        let n = self.k.nrows();
        let mut rng = Xorshift(0x2545_F491_4F6C_DD1D);
        let b = Mat::<f64>::from_fn(n, 1, |_, _| rng.next());
        let mut x = b.clone();
        self.solve(&factor, x.as_mut(), &mut self.solve_scratch(1));
        let kx = self.k.as_ref() * x.as_ref();
        let mx = self.m.as_ref() * x.as_ref();
        let r = &kx - sigma * &mx - &b;
        let scale = b.norm_l2() + kx.norm_l2() + sigma.abs() * mx.norm_l2();
        let rel = r.norm_l2() / scale;
        if rel.is_nan() || rel > SOLVE_RESIDUAL_LIMIT {
            return Err(format!(
                "relative solve residual {rel:.1e} at shift {sigma}"
            ));
        }
        Ok(factor)
    }

    /// Scratch for [`Self::solve`] of up to `cols` right-hand sides.
    fn solve_scratch(&self, cols: usize) -> MemBuffer {
        MemBuffer::new(self.symbolic.solve_in_place_scratch::<f64>(cols, self.par))
    }

    /// `rhs ← (K − σM)⁻¹ rhs` with `mem` from [`Self::solve_scratch`] for at least as many
    /// columns.
    fn solve(&self, factor: &Factor, rhs: MatMut<'_, f64>, mem: &mut MemBuffer) {
        LdltRef::new(&self.symbolic, &factor.values).solve_in_place_with_conj(
            Conj::No,
            rhs,
            self.par,
            MemStack::new(mem),
        );
    }
}

/// Number of negative entries of D in an LDLᵀ factor.
fn negative_pivots(symbolic: &SymbolicCholesky<usize>, values: &[f64]) -> usize {
    match symbolic.raw() {
        SymbolicCholeskyRaw::Simplicial(s) => {
            let cp = s.col_ptr();
            (0..s.nrows()).filter(|&j| values[cp[j]] < 0.0).count()
        }
        SymbolicCholeskyRaw::Supernodal(s) => {
            let l = SupernodalLdltRef::new(s, values);
            (0..s.n_supernodes())
                .map(|i| {
                    let v = l.supernode(i).val();
                    (0..v.ncols()).filter(|&j| v[(j, j)] < 0.0).count()
                })
                .sum()
        }
    }
}

/// Number of eigenvalues of K φ = λ M φ below `shift` (Sturm count from the inertia of
/// LDLᵀ = K − shift·M). The shift is moved up slightly if K − shift·M is singular or its
/// factorization unstable there; the count is for the shift actually used, returned first.
pub fn eigenvalue_count(k: &SparseMat, m: &SparseMat, shift: f64) -> Result<(f64, usize), FeError> {
    check_pencil(k, m)?;
    let f = Factorizer::new(k, m)?;
    let factor = f.factor(shift, shift.abs().max(1.0))?;
    Ok((factor.shift, factor.below))
}

/// Eigenpairs found so far, in blocks as they were found.
struct Found {
    blocks: Vec<(Vec<f64>, Mat<f64>)>,
}

impl Found {
    fn eigenvalues(&self) -> Vec<f64> {
        let mut all: Vec<f64> = self.blocks.iter().flat_map(|(l, _)| l.clone()).collect();
        all.sort_by(f64::total_cmp);
        all
    }

    fn count_in(&self, lo: f64, hi: f64) -> usize {
        self.blocks
            .iter()
            .flat_map(|(l, _)| l.iter())
            .filter(|&&l| l > lo && l <= hi)
            .count()
    }

    /// Blocks holding an eigenvalue at or above `from`: the neighbours a run deflates.
    fn near(&self, from: f64) -> Vec<MatRef<'_, f64>> {
        self.blocks
            .iter()
            .filter(|(l, _)| l.iter().any(|&x| x >= from))
            .map(|(_, v)| v.as_ref())
            .collect()
    }

    /// The eigenpairs in (lo, hi\], ascending; the blocks are consumed one at a time.
    fn into_modes(self, n: usize, lo: f64, hi: f64, limit: usize) -> Modes {
        let mut picked: Vec<(f64, usize, usize)> = Vec::new();
        for (b, (l, _)) in self.blocks.iter().enumerate() {
            for (c, &x) in l.iter().enumerate() {
                if x > lo && x <= hi {
                    picked.push((x, b, c));
                }
            }
        }
        picked.sort_by(|a, b| a.0.total_cmp(&b.0));
        picked.truncate(limit);
        let mut shapes = Mat::<f64>::zeros(n, picked.len());
        let mut by_block: Vec<Vec<(usize, usize)>> = vec![Vec::new(); self.blocks.len()];
        for (out, &(_, b, c)) in picked.iter().enumerate() {
            by_block[b].push((out, c));
        }
        for ((_, v), cols) in self.blocks.into_iter().zip(by_block) {
            for (out, c) in cols {
                shapes.col_mut(out).copy_from(v.col(c));
            }
        }
        Modes {
            eigenvalues: picked.iter().map(|p| p.0).collect(),
            shapes,
        }
    }
}

/// What one Lanczos run at a shift must converge.
struct Goal {
    /// Lower end of the slice (exclusive); the slice is (lower, shift\].
    lower: f64,
    /// Eigenpairs in the slice not found yet.
    in_slice: usize,
    /// Eigenpairs above the shift to converge as well, nearest first (first run only).
    above: usize,
}

/// The outcome of a run: converged pairs above `lower`, and every Ritz value of the last
/// Rayleigh-Ritz step (converged or not) as eigenvalue estimates for placing the next shift.
struct RunResult {
    eigenvalues: Vec<f64>,
    shapes: Mat<f64>,
    estimates: Vec<f64>,
    complete: bool,
}

/// Buffers of the Lanczos runs of one sweep, allocated once. At a million DOF the basis is
/// gigabytes and every n × 8 block 60 MB: allocated afresh on every use, the allocator maps
/// them and the kernel zeroes every page again (13 % of the time of 500 modes at 928,000 DOF
/// went to page faults before this).
struct Workspace {
    /// Krylov basis, n × capacity; columns beyond the current length are stale.
    q: Mat<f64>,
    /// The block being orthogonalised.
    z: Mat<f64>,
    /// M times a block.
    mz: Mat<f64>,
    /// M times the vectors of the block being appended.
    mq: Mat<f64>,
    /// Scratch of the LDLᵀ solves of one block.
    solve: MemBuffer,
}

impl Workspace {
    fn new(f: &Factorizer, capacity: usize) -> Self {
        let n = f.k.nrows();
        Workspace {
            q: Mat::zeros(n, capacity),
            z: Mat::zeros(n, BLOCK),
            mz: Mat::zeros(n, BLOCK),
            mq: Mat::zeros(n, BLOCK),
            solve: f.solve_scratch(BLOCK),
        }
    }
}

fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// `y -= alpha · x`.
fn subtract_scaled(y: &mut [f64], alpha: f64, x: &[f64]) {
    for (yi, xi) in y.iter_mut().zip(x) {
        *yi -= alpha * xi;
    }
}

/// `dst = M src`.
fn m_times(m: &SparseMat, dst: MatMut<'_, f64>, src: MatRef<'_, f64>, par: Par) {
    sparse_dense_matmul(dst, Accum::Replace, m.as_ref(), src, 1.0, par);
}

/// `(vᵀ mz)ᵀ = mzᵀ v` (mz.ncols() × v.ncols()): the M-inner products of a block with the
/// vectors `v`. In this orientation faer's product streams `v` (the basis, gigabytes at a
/// million DOF) 1.4× faster than as `vᵀ mz` (10 against 7 GB/s here): the few columns of
/// the block are what it packs.
fn coefficients(v: MatRef<'_, f64>, mz: MatRef<'_, f64>, par: Par) -> Mat<f64> {
    let mut c = Mat::<f64>::zeros(mz.ncols(), v.ncols());
    matmul(c.as_mut(), Accum::Replace, mz.transpose(), v, 1.0, par);
    c
}

/// M-orthogonalises the columns of `z` against the deflation set and the basis `q`; `mz` is
/// scratch of `z`'s shape. Returns the coefficients on `q` (q.ncols() × z.ncols()).
///
/// The image of a Lanczos block lies mostly along the two newest blocks (the block
/// three-term recurrence): those are removed first, a cheap local pass. What is left along the
/// rest of the basis and the deflation set is rounding, so one full pass removes it — the
/// expensive part, reading the whole basis, memory-bound at a million DOF — and a second full
/// pass follows only where the first still cancelled more than half of a column's M-norm
/// (Daniel-Gragg-Kaufman-Stewart). Two full passes every time made 500 modes cost 30 % more
/// at 234,000 DOF and 6 % more at 928,000 DOF, for the same eigenpairs.
fn orthogonalise(
    m: &SparseMat,
    deflate: &[MatRef<'_, f64>],
    q: MatRef<'_, f64>,
    mut z: MatMut<'_, f64>,
    mut mz: MatMut<'_, f64>,
    par: Par,
) -> Mat<f64> {
    let (len, width) = (q.ncols(), z.ncols());
    let mut total = Mat::<f64>::zeros(len, width);
    let m_norms = |z: MatRef<'_, f64>, mz: MatRef<'_, f64>| -> Vec<f64> {
        (0..width)
            .map(|c| z.col(c).transpose() * mz.col(c))
            .collect()
    };
    let local = len.min(2 * BLOCK);
    if local > 0 && local < len {
        let start = len - local;
        m_times(m, mz.rb_mut(), z.rb(), par);
        let qs = q.subcols(start, local);
        let c = coefficients(qs, mz.rb(), par);
        matmul(z.rb_mut(), Accum::Add, qs, c.transpose(), -1.0, par);
        total
            .as_mut()
            .subrows_mut(start, local)
            .copy_from(c.transpose());
    }
    m_times(m, mz.rb_mut(), z.rb(), par);
    for pass in 0..2 {
        let before = m_norms(z.rb(), mz.rb());
        for d in deflate {
            let c = coefficients(*d, mz.rb(), par);
            matmul(z.rb_mut(), Accum::Add, *d, c.transpose(), -1.0, par);
        }
        if len > 0 {
            let c = coefficients(q, mz.rb(), par);
            matmul(z.rb_mut(), Accum::Add, q, c.transpose(), -1.0, par);
            total += c.transpose();
        }
        if pass == 0 {
            m_times(m, mz.rb_mut(), z.rb(), par);
            let after = m_norms(z.rb(), mz.rb());
            if before.iter().zip(&after).all(|(b, a)| *a >= 0.5 * b) {
                break;
            }
        }
    }
    total
}

/// One restart-free block Lanczos process at `factor.shift` with at most `capacity` vectors,
/// M-orthogonal to `deflate`.
///
/// Long on purpose: one block Lanczos recurrence (expand, orthonormalise against the basis and
/// `deflate`, Rayleigh-Ritz on the columns whose images are known, convergence) sharing its
/// basis and block buffers, which the steps change in place.
fn lanczos_run(
    f: &Factorizer,
    factor: &Factor,
    deflate: &[MatRef<'_, f64>],
    goal: &Goal,
    ws: &mut Workspace,
    seed: u64,
) -> Result<RunResult, FeError> {
    let n = f.k.nrows();
    let m = f.m;
    let par = f.par;
    let shift = factor.shift;
    let deflated: usize = deflate.iter().map(|d| d.ncols()).sum();
    let capacity = ws.q.ncols().min(n.saturating_sub(deflated)).max(1);
    let mut len = 0usize;
    let mut h = Mat::<f64>::zeros(capacity, capacity);
    let mut rng = Xorshift(seed);

    // Appends the first `width` columns of the block buffer (orthogonal to the basis) one by
    // one, orthonormalised among themselves; a column that vanishes is replaced by a fresh
    // random direction. Returns, per column, its coefficients on the vectors this call added
    // (the last one its norm).
    let push_block = |ws: &mut Workspace,
                      width: usize,
                      len: &mut usize,
                      scales: &[f64],
                      rng: &mut Xorshift|
     -> Result<Vec<Vec<f64>>, FeError> {
        let Workspace { q, z, mz, mq, .. } = ws;
        let start = *len;
        let mut coefs = Vec::with_capacity(width);
        // Removes from column `c` of z its components along the vectors added so far.
        let in_block = |z: &mut Mat<f64>, q: &Mat<f64>, mq: &Mat<f64>, c: usize, added: usize| {
            let mut coef = vec![0.0; added];
            for _ in 0..2 {
                for (k, total) in coef.iter_mut().enumerate() {
                    let v = z.col_as_slice_mut(c);
                    let d = dot(v, mq.col_as_slice(k));
                    subtract_scaled(v, d, q.col_as_slice(start + k));
                    *total += d;
                }
            }
            coef
        };
        for (c, &scale) in scales.iter().enumerate().take(width) {
            let added = *len - start;
            let mut coef = in_block(z, q, mq, c, added);
            if *len >= capacity {
                coefs.push(coef);
                continue;
            }
            let rest = dot(z.col_as_slice(c), z.col_as_slice(c)).sqrt();
            let mut coupled = true;
            if rest.is_nan() || rest <= 1e-10 * scale {
                // Invariant subspace: continue with a fresh direction, no coupling.
                coupled = false;
                for x in z.col_as_slice_mut(c) {
                    *x = rng.next();
                }
                let before = dot(z.col_as_slice(c), z.col_as_slice(c)).sqrt();
                orthogonalise(
                    m,
                    deflate,
                    q.as_ref().subcols(0, *len),
                    z.as_mut().subcols_mut(c, 1),
                    mz.as_mut().subcols_mut(0, 1),
                    par,
                );
                in_block(z, q, mq, c, added);
                let after = dot(z.col_as_slice(c), z.col_as_slice(c)).sqrt();
                if after.is_nan() || after <= 1e-8 * before {
                    return Err(FeError::Numerical(
                        "could not extend the Krylov basis with a new direction".into(),
                    ));
                }
            }
            m_times(
                m,
                mq.as_mut().subcols_mut(added, 1),
                z.as_ref().subcols(c, 1),
                par,
            );
            let norm = dot(z.col_as_slice(c), mq.col_as_slice(added))
                .max(0.0)
                .sqrt();
            for (qi, vi) in q.col_as_slice_mut(*len).iter_mut().zip(z.col_as_slice(c)) {
                *qi = vi / norm;
            }
            for x in mq.col_as_slice_mut(added) {
                *x /= norm;
            }
            *len += 1;
            coef.push(if coupled { norm } else { 0.0 });
            coefs.push(coef);
        }
        Ok(coefs)
    };

    let width0 = BLOCK.min(capacity);
    for c in 0..width0 {
        for x in ws.z.col_as_slice_mut(c) {
            *x = rng.next();
        }
    }
    orthogonalise(
        m,
        deflate,
        ws.q.as_ref().subcols(0, 0),
        ws.z.as_mut().subcols_mut(0, width0),
        ws.mz.as_mut().subcols_mut(0, width0),
        par,
    );
    let ones = vec![ws.z.as_ref().subcols(0, width0).norm_l2(); width0];
    push_block(ws, width0, &mut len, &ones, &mut rng)?;

    let mut done = 0usize;
    let mut next_check = (goal.in_slice + goal.above).max(BLOCK);
    loop {
        let width = (len - done).min(BLOCK);
        let full = width == 0 || len + width > capacity;
        if !full {
            m_times(
                m,
                ws.z.as_mut().subcols_mut(0, width),
                ws.q.as_ref().subcols(done, width),
                par,
            );
            f.solve(factor, ws.z.as_mut().subcols_mut(0, width), &mut ws.solve);
            let scales: Vec<f64> = (0..width).map(|c| ws.z.col(c).norm_l2()).collect();
            let len_before = len;
            let block_coef = orthogonalise(
                m,
                deflate,
                ws.q.as_ref().subcols(0, len),
                ws.z.as_mut().subcols_mut(0, width),
                ws.mz.as_mut().subcols_mut(0, width),
                par,
            );
            let coefs = push_block(ws, width, &mut len, &scales, &mut rng)?;
            for c in 0..width {
                for r in 0..len_before {
                    h[(r, done + c)] = block_coef[(r, c)];
                }
                for (k, value) in coefs[c].iter().enumerate() {
                    h[(len_before + k, done + c)] = *value;
                }
            }
            done += width;
            if done < next_check && len < n.saturating_sub(deflated) {
                continue;
            }
        }
        next_check = done + (done / 8).max(BLOCK);
        // Rayleigh-Ritz on the columns whose images are known.
        let t = Mat::<f64>::from_fn(done, done, |i, j| 0.5 * (h[(i, j)] + h[(j, i)]));
        let evd = t
            .self_adjoint_eigen(Side::Lower)
            .map_err(|e| FeError::Numerical(format!("projected eigenproblem failed: {e:?}")))?;
        let (s, u) = (evd.S(), evd.U());
        let exhausted = done >= n.saturating_sub(deflated);
        let converged: Vec<bool> = (0..done)
            .map(|col| {
                let theta = s[col];
                if theta == 0.0 || !theta.is_finite() {
                    return false;
                }
                if exhausted {
                    return true;
                }
                let mut residual = 0.0;
                for r in done..len {
                    let mut acc = 0.0;
                    for i in 0..done {
                        acc += h[(r, i)] * u[(i, col)];
                    }
                    residual += acc * acc;
                }
                residual.sqrt() <= RESIDUAL_TOLERANCE * theta.abs()
            })
            .collect();
        let lambda = |col: usize| shift + 1.0 / s[col];
        let in_slice = (0..done)
            .filter(|&c| converged[c] && lambda(c) > goal.lower && s[c] < 0.0)
            .count();
        // Largest positive θ first: the nearest eigenvalues above the shift.
        let above_ok = (0..done)
            .rev()
            .take_while(|&c| s[c] > 0.0)
            .take(goal.above)
            .all(|c| converged[c])
            && (0..done).filter(|&c| s[c] > 0.0).count() >= goal.above;
        let complete = in_slice >= goal.in_slice && above_ok;
        if complete || full || exhausted {
            let estimates = (0..done).map(lambda).collect();
            let keep: Vec<usize> = (0..done)
                .filter(|&c| converged[c] && lambda(c) > goal.lower)
                .collect();
            let mut selected = Mat::<f64>::zeros(done, keep.len());
            for (out, &c) in keep.iter().enumerate() {
                selected.col_mut(out).copy_from(u.col(c));
            }
            let shapes = ws.q.as_ref().subcols(0, done) * &selected;
            return Ok(RunResult {
                eigenvalues: keep.iter().map(|&c| lambda(c)).collect(),
                shapes,
                estimates,
                complete,
            });
        }
    }
}

/// The eigenpairs of K φ = λ M φ above `lower`, by spectrum slicing: the `n` lowest
/// ([`SliceStop::Count`]) or all up to an upper end ([`SliceStop::Upper`]), ascending.
///
/// `lower` need not lie below the spectrum (the Sturm count at `lower` is subtracted), but for
/// a free structure it must lie below the rigid-body eigenvalues (e.g. −1) if those are wanted.
/// Errors when a slice cannot be completed (a count that does not match after restarts).
///
/// Long on purpose: the sweep over shifts with its bookkeeping of which slice is complete.
pub fn sliced_modes(
    k: &SparseMat,
    m: &SparseMat,
    lower: f64,
    stop: SliceStop,
) -> Result<Modes, FeError> {
    check_pencil(k, m)?;
    let n = k.nrows();
    if !lower.is_finite() {
        return Err(FeError::InvalidInput(format!(
            "lower end must be finite, got {lower}"
        )));
    }
    match stop {
        SliceStop::Count(c) if c == 0 || c > n => {
            return Err(FeError::InvalidInput(format!(
                "n_modes = {c} must be in 1..={n}"
            )))
        }
        SliceStop::Upper(u) if !(u.is_finite() && u > lower) => {
            return Err(FeError::InvalidInput(format!(
                "upper end {u} must be finite and above the lower end {lower}"
            )))
        }
        _ => {}
    }
    let f = Factorizer::new(k, m)?;
    let mut found = Found { blocks: Vec::new() };
    let mut ws = Workspace::new(&f, (4 * SLICE_MODES + 4 * BLOCK).min(n));

    // First run at the lower end: the nearest modes above it, as the single-shift solver does.
    let first = f.factor(lower, lower.abs().max(1.0))?;
    let (lower, below_lower) = (first.shift, first.below);
    let first_goal = match stop {
        SliceStop::Count(c) => c.min(SLICE_MODES),
        SliceStop::Upper(_) => SLICE_MODES,
    }
    .min(n - below_lower);
    let mut a = lower;
    let mut below_a = below_lower;
    let mut estimates = run_slice(
        &f,
        &first,
        &mut found,
        Goal {
            lower: a,
            in_slice: 0,
            above: first_goal,
        },
        &mut ws,
    )?;
    drop(first);
    let mut previous_width: Option<(f64, usize)> = None;
    loop {
        let all = found.eigenvalues();
        let top = all.last().copied().unwrap_or(a).max(a);
        // Slices done: stop when the verified interval (lower, a] covers the request.
        let verified = below_a - below_lower;
        let finished = match stop {
            SliceStop::Count(c) => verified >= c,
            SliceStop::Upper(u) => a >= u,
        };
        if finished {
            let (hi, limit) = match stop {
                SliceStop::Count(c) => (a, c),
                SliceStop::Upper(u) => (u, usize::MAX),
            };
            // The basis is gigabytes at a million DOF: gone before the modes are gathered.
            drop(ws);
            return Ok(found.into_modes(n, lower, hi, limit));
        }
        // Density of eigenvalues (per unit λ) from the last slice, else from what is found.
        let density = match previous_width {
            Some((w, c)) if w > 0.0 && c > 0 => c as f64 / w,
            _ => {
                let c = all.iter().filter(|&&l| l > lower).count().max(1);
                c as f64 / (top - lower).max(f64::MIN_POSITIVE)
            }
        };
        let mut target = top + SLICE_MODES as f64 / density.max(f64::MIN_POSITIVE);
        if let SliceStop::Count(c) = stop {
            // Enough found already: one more count just above the c-th proves it.
            let above: Vec<f64> = all.iter().copied().filter(|&l| l > lower).collect();
            if above.len() >= c {
                // Not inside a cluster of (nearly) equal eigenvalues: past its last member.
                let last = above[c - 1];
                let tol = 1e-8 * last.abs().max(f64::MIN_POSITIVE);
                if let Some(&next) = above[c..].iter().find(|&&l| l > last + tol) {
                    target = 0.5 * (last + next);
                }
            }
        }
        let mut sigma = gap_midpoint(target, &estimates, &all, top);
        if let SliceStop::Upper(u) = stop {
            if sigma >= u {
                sigma = u;
            }
        }
        let factor = f.factor(sigma, (sigma - a).abs().max(f64::MIN_POSITIVE))?;
        if factor.below < below_a {
            return Err(FeError::Numerical(format!(
                "Sturm counts decrease from shift {a} ({below_a}) to {} ({}): unstable \
                 factorization",
                factor.shift, factor.below
            )));
        }
        let in_slice = factor.below - below_a;
        let have = found.count_in(a, factor.shift);
        if have > in_slice {
            return Err(FeError::Numerical(format!(
                "slice ({a}, {}] holds {in_slice} eigenvalues by Sturm count but {have} were \
                 found: an eigenvalue sits on a slice boundary",
                factor.shift
            )));
        }
        estimates = run_slice(
            &f,
            &factor,
            &mut found,
            Goal {
                lower: a,
                in_slice: in_slice - have,
                above: 0,
            },
            &mut ws,
        )?;
        previous_width = Some((factor.shift - a, in_slice));
        a = factor.shift;
        below_a = factor.below;
    }
}

/// The shift for a target λ: the midpoint of the gap between the eigenvalue estimates (Ritz
/// values and eigenvalues found) that holds `target`, so that the shift is not next to an
/// eigenvalue; never at or below `floor`.
fn gap_midpoint(target: f64, estimates: &[f64], found: &[f64], floor: f64) -> f64 {
    let mut points: Vec<f64> = estimates
        .iter()
        .chain(found)
        .copied()
        .filter(|x| x.is_finite() && *x >= floor)
        .collect();
    points.push(floor);
    points.sort_by(f64::total_cmp);
    let below = points.iter().copied().rfind(|&x| x <= target);
    let above = points.iter().copied().find(|&x| x > target);
    match (below, above) {
        (Some(lo), Some(hi)) => 0.5 * (lo + hi),
        _ => target,
    }
}

/// Lanczos runs at one factorization until the goal is met (locking converged pairs and
/// restarting when the basis is full); the converged pairs join `found`. Returns eigenvalue
/// estimates for the next shift.
fn run_slice(
    f: &Factorizer,
    factor: &Factor,
    found: &mut Found,
    goal: Goal,
    ws: &mut Workspace,
) -> Result<Vec<f64>, FeError> {
    if goal.in_slice == 0 && goal.above == 0 {
        return Ok(Vec::new());
    }
    let mut goal = goal;
    let mut stalls = 0;
    let mut seed = 0x9E37_79B9_7F4A_7C15u64 ^ factor.shift.to_bits();
    // Deflate everything found at or above the slice's mirror image below its lower end.
    let from = goal.lower - (factor.shift - goal.lower).abs();
    loop {
        let result = {
            let deflate = found.near(from);
            lanczos_run(f, factor, &deflate, &goal, ws, seed)?
        };
        seed = seed.wrapping_mul(6_364_136_223_846_793_005).wrapping_add(1);
        let new_in_slice = result
            .eigenvalues
            .iter()
            .filter(|&&l| l > goal.lower && l <= factor.shift)
            .count();
        let new_above = result
            .eigenvalues
            .iter()
            .filter(|&&l| l > factor.shift)
            .count();
        let progress = !result.eigenvalues.is_empty();
        if progress {
            found
                .blocks
                .push((result.eigenvalues.clone(), result.shapes));
        }
        if result.complete {
            if new_in_slice > goal.in_slice {
                return Err(FeError::Numerical(format!(
                    "slice ({}, {}] should hold {} more eigenvalues but {new_in_slice} \
                     converged",
                    goal.lower, factor.shift, goal.in_slice
                )));
            }
            return Ok(result.estimates);
        }
        goal.in_slice = goal.in_slice.saturating_sub(new_in_slice);
        goal.above = goal.above.saturating_sub(new_above);
        if goal.in_slice == 0 && goal.above == 0 {
            return Ok(result.estimates);
        }
        stalls = if new_in_slice == 0 { stalls + 1 } else { 0 };
        if stalls >= 3 || (!progress && stalls >= 2) {
            return Err(FeError::Numerical(format!(
                "spectrum slicing: {} eigenvalues of slice ({}, {}] (Sturm count) not found \
                 after restarts",
                goal.in_slice, goal.lower, factor.shift
            )));
        }
    }
}

/// The `n_modes` lowest eigenpairs above `shift`: the single-shift solver ([`lowest_modes`])
/// or spectrum slicing ([`sliced_modes`]), as [`prefer_slicing`] decides.
pub fn lowest_modes_auto(
    k: &SparseMat,
    m: &SparseMat,
    n_modes: usize,
    shift: f64,
) -> Result<Modes, FeError> {
    if !prefer_slicing(k.nrows(), n_modes) {
        lowest_modes(k, m, n_modes, shift)
    } else {
        sliced_modes(k, m, shift, SliceStop::Count(n_modes))
    }
}

/// Every eigenpair with eigenvalue in (lower, upper\], ascending. Sturm counts give their
/// number; then the single-shift solver (one run with the count known, no retries) or spectrum
/// slicing computes them, as [`prefer_slicing`] decides.
pub fn modes_in_interval(
    k: &SparseMat,
    m: &SparseMat,
    lower: f64,
    upper: f64,
) -> Result<Modes, FeError> {
    check_pencil(k, m)?;
    let n = k.nrows();
    if !(lower.is_finite() && upper.is_finite() && upper > lower) {
        return Err(FeError::InvalidInput(format!(
            "interval ({lower}, {upper}] must be finite and non-empty"
        )));
    }
    let f = Factorizer::new(k, m)?;
    let at_upper = f.factor(upper, upper.abs().max(1.0))?;
    let at_lower = f.factor(lower, lower.abs().max(1.0))?;
    let count = at_upper.below.saturating_sub(at_lower.below);
    drop((at_upper, at_lower, f));
    if count == 0 {
        return Ok(Modes {
            eigenvalues: Vec::new(),
            shapes: Mat::zeros(n, 0),
        });
    }
    if !prefer_slicing(n, count) {
        // One more than the count when possible, so the gap above the last one is resolved.
        let request = (count + 1).min(n);
        let modes = lowest_modes(k, m, request, lower)?;
        let keep = modes.eigenvalues.iter().filter(|&&l| l <= upper).count();
        return Ok(Modes {
            eigenvalues: modes.eigenvalues[..keep].to_vec(),
            shapes: modes.shapes.subcols(0, keep).to_owned(),
        });
    }
    sliced_modes(k, m, lower, SliceStop::Upper(upper))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Fixed-free chain of `n` equal masses: analytic eigenvalues (4k/m) sin²((2j−1)π/(2(2n+1))).
    fn chain(n: usize) -> (SparseMat, SparseMat, Vec<f64>) {
        let mut k = Vec::new();
        let mut m = Vec::new();
        for i in 0..n {
            k.push(Triplet::new(i, i, if i + 1 < n { 2.0 } else { 1.0 }));
            if i + 1 < n {
                k.push(Triplet::new(i, i + 1, -1.0));
                k.push(Triplet::new(i + 1, i, -1.0));
            }
            m.push(Triplet::new(i, i, 1.0));
        }
        let exact = (1..=n)
            .map(|j| {
                let s =
                    ((2 * j - 1) as f64 * std::f64::consts::PI / (2.0 * (2 * n + 1) as f64)).sin();
                4.0 * s * s
            })
            .collect();
        (
            SparseColMat::try_new_from_triplets(n, n, &k).unwrap(),
            SparseColMat::try_new_from_triplets(n, n, &m).unwrap(),
            exact,
        )
    }

    #[test]
    fn sturm_counts_match_the_analytic_spectrum() {
        let (k, m, exact) = chain(300);
        for sigma in [0.01, 0.5, 1.7, 3.99] {
            let (used, count) = eigenvalue_count(&k, &m, sigma).unwrap();
            assert_eq!(
                count,
                exact.iter().filter(|&&l| l < used).count(),
                "σ = {sigma}"
            );
        }
    }

    #[test]
    fn slicing_finds_every_chain_mode_in_order() {
        let (k, m, exact) = chain(1500);
        let modes = sliced_modes(&k, &m, 0.0, SliceStop::Count(400)).unwrap();
        assert_eq!(modes.len(), 400);
        for (l, e) in modes.eigenvalues.iter().zip(&exact) {
            assert!((l / e - 1.0).abs() < 1e-9, "{l} vs {e}");
        }
    }
}
