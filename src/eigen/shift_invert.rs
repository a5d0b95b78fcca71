//! Lowest eigenpairs of the sparse pencil (K, M) by shift-invert block Lanczos.
//!
//! The operator (K − σM)⁻¹M is self-adjoint in the M inner product; its largest eigenvalues
//! θ = 1/(λ − σ) belong to the λ nearest above σ. K − σM is factored once by faer's sparse
//! Cholesky, so σ must lie below the lowest eigenvalue (use a small negative σ for structures
//! with rigid-body modes). The Krylov basis is grown a block at a time with full
//! M-reorthogonalisation (Gram-Schmidt, repeated until a pass no longer cancels most of the
//! vector), which keeps it orthogonal to working precision; the block width (8) resolves
//! eigenvalues of multiplicity up to 8, e.g. the six rigid-body modes of a free structure. Ritz
//! pairs are accepted when their Lanczos residual is small against their own θ. Converged Ritz
//! pairs whose θ stands more than 1000 times above the next (the rigid-body modes at σ = −1)
//! are locked and the process restarts M-orthogonal to them, so that the projected eigenproblem,
//! solved to ε times its largest θ, keeps the much smaller θ of the other modes accurate.
//!
//! Why not faer's matrix-free `partial_self_adjoint_eigen`: it works in the Euclidean inner
//! product with a single start vector. The pencil would first have to be symmetrised with M^-1/2
//! (M is not diagonal: beams carry 3 × 3 rotary blocks), and a single-vector Krylov method finds
//! exactly repeated eigenvalues (rigid-body modes, symmetric substructures) only by round-off.

use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::Llt;
use faer::sparse::{SparseColMat, Triplet};
use faer::{Mat, Side};

use crate::fe::assembly::{mat_vec, SparseMat};
use crate::fe::error::FeError;

/// Eigenpairs of (K, M), ascending.
#[derive(Debug, Clone)]
pub struct Modes {
    /// Eigenvalues λ = ω² (rad²/s²).
    pub eigenvalues: Vec<f64>,
    /// Mode shapes as columns, M-orthonormal (Φᵀ M Φ = I).
    pub shapes: Mat<f64>,
}

impl Modes {
    /// Natural frequencies f = √λ / 2π (Hz); negative round-off eigenvalues map to 0.
    pub fn frequencies_hz(&self) -> Vec<f64> {
        self.eigenvalues
            .iter()
            .map(|l| l.max(0.0).sqrt() / (2.0 * std::f64::consts::PI))
            .collect()
    }

    /// Number of modes.
    pub fn len(&self) -> usize {
        self.eigenvalues.len()
    }

    /// Whether no mode is held.
    pub fn is_empty(&self) -> bool {
        self.eigenvalues.is_empty()
    }
}

const BLOCK: usize = 8;
const RESIDUAL_TOLERANCE: f64 = 1e-9;
/// Ratio of a converged Ritz value to the next one above which the leading ones are locked.
const LOCK_GAP: f64 = 1e3;

/// K − σM as a new sparse matrix.
fn shifted(k: &SparseMat, m: &SparseMat, shift: f64) -> Result<SparseMat, FeError> {
    let mut entries = Vec::with_capacity(k.compute_nnz() + m.compute_nnz());
    for (a, factor) in [(k, 1.0), (m, -shift)] {
        let (cp, ri, val) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
        for j in 0..a.ncols() {
            for p in cp[j]..cp[j + 1] {
                entries.push(Triplet::new(ri[p], j, factor * val[p]));
            }
        }
    }
    SparseColMat::try_new_from_triplets(k.nrows(), k.ncols(), &entries)
        .map_err(|e| FeError::Numerical(format!("forming K - shift*M: {e:?}")))
}

fn norm2(v: &[f64]) -> f64 {
    v.iter().map(|x| x * x).sum::<f64>().sqrt()
}

/// Deterministic pseudo-random start vectors (xorshift), so results are reproducible; shared
/// with [`super::slicing`].
pub(super) struct Xorshift(pub(super) u64);

impl Xorshift {
    /// The next number, uniform in [−1, 1).
    pub(super) fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    }
}

struct Basis<'a> {
    m: &'a SparseMat,
    q: Mat<f64>,
    mq: Mat<f64>,
    len: usize,
}

impl Basis<'_> {
    /// M-orthogonalises `v` against basis columns `from..len` (twice); returns the projection
    /// coefficients of those columns.
    fn orthogonalise(&self, v: &mut [f64], from: usize) -> Vec<f64> {
        let mut coef = vec![0.0; self.len - from];
        for _ in 0..2 {
            for (k, total) in coef.iter_mut().enumerate() {
                let (mqc, qc) = (self.mq.col(from + k), self.q.col(from + k));
                let dot: f64 = v.iter().zip(mqc.iter()).map(|(a, b)| a * b).sum();
                for (vi, qi) in v.iter_mut().zip(qc.iter()) {
                    *vi -= dot * qi;
                }
                *total += dot;
            }
        }
        coef
    }

    /// M-orthogonalises the columns of `z` against the whole basis (twice, as matrix products);
    /// returns the projection coefficients (basis length × columns of `z`).
    fn orthogonalise_block(&self, z: &mut Mat<f64>) -> Mat<f64> {
        let mut total = Mat::<f64>::zeros(self.len, z.ncols());
        if self.len == 0 {
            return total;
        }
        let q = self.q.as_ref().subcols(0, self.len);
        let mq = self.mq.as_ref().subcols(0, self.len);
        for _ in 0..2 {
            let c = mq.transpose() * z.as_ref();
            *z -= q * &c;
            total += &c;
        }
        total
    }

    /// Appends `v` (already orthogonal) normalised; returns its M-norm before normalisation.
    fn push(&mut self, v: &[f64]) -> f64 {
        let mv = mat_vec(self.m, v);
        let norm = v
            .iter()
            .zip(&mv)
            .map(|(a, b)| a * b)
            .sum::<f64>()
            .max(0.0)
            .sqrt();
        let c = self.len;
        for i in 0..v.len() {
            self.q[(i, c)] = v[i] / norm;
            self.mq[(i, c)] = mv[i] / norm;
        }
        self.len += 1;
        norm
    }
}

/// Checks a pencil (K, M) before any solve: both square, of equal size, every entry finite.
/// Shared by the eigensolvers here and in [`super::slicing`] and by the Craig-Bampton
/// reduction.
pub fn check_pencil(k: &SparseMat, m: &SparseMat) -> Result<(), FeError> {
    let n = k.nrows();
    if k.ncols() != n || m.nrows() != n || m.ncols() != n {
        return Err(FeError::InvalidInput(format!(
            "K is {}x{}, M is {}x{}: both must be square and of equal size",
            k.nrows(),
            k.ncols(),
            m.nrows(),
            m.ncols()
        )));
    }
    if k.val().iter().chain(m.val()).any(|v| !v.is_finite()) {
        return Err(FeError::InvalidInput(
            "K or M contains a non-finite entry".into(),
        ));
    }
    Ok(())
}

fn validate(k: &SparseMat, m: &SparseMat, n_modes: usize, shift: f64) -> Result<(), FeError> {
    check_pencil(k, m)?;
    let n = k.nrows();
    if n_modes == 0 || n_modes > n {
        return Err(FeError::InvalidInput(format!(
            "n_modes = {n_modes} must be in 1..={n}"
        )));
    }
    if !shift.is_finite() {
        return Err(FeError::InvalidInput(format!(
            "shift must be finite, got {shift}"
        )));
    }
    Ok(())
}

/// The `n_modes` eigenpairs of K φ = λ M φ with the smallest λ above `shift`.
///
/// `shift` must lie below the lowest eigenvalue (K − shift·M positive definite); for a free
/// structure use a small negative value such as −1.
///
/// Long on purpose: one shift-invert Lanczos run with its restarts and convergence bookkeeping, all sharing the factorisation and the Krylov basis.
pub fn lowest_modes(
    k: &SparseMat,
    m: &SparseMat,
    n_modes: usize,
    shift: f64,
) -> Result<Modes, FeError> {
    validate(k, m, n_modes, shift)?;
    let n = k.nrows();
    let llt: Llt<usize, f64> = shifted(k, m, shift)?
        .sp_cholesky(Side::Lower)
        .map_err(|e| {
            FeError::Numerical(format!(
            "K - shift*M is not positive definite at shift {shift} ({e:?}): the shift must lie \
             below the lowest eigenvalue, or the model has a mechanism/unconstrained DOF"
        ))
        })?;
    // Ritz vectors of a dense spectrum need a basis several times the number of modes; the
    // shift-invert spectrum of a car body converges 30 modes in about 150 vectors.
    let capacity = n.min((6 * n_modes + 8 * BLOCK).max(n_modes + 100));
    let mut basis = Basis {
        m,
        q: Mat::zeros(n, capacity),
        mq: Mat::zeros(n, capacity),
        len: 0,
    };
    let mut h = Mat::<f64>::zeros(capacity, capacity);
    let mut rng = Xorshift(0x9E37_79B9_7F4A_7C15);

    // Start block: random vectors; any that fall into the span already built are replaced.
    let add_fresh = |basis: &mut Basis, rng: &mut Xorshift| -> Result<(), FeError> {
        for _attempt in 0..10 {
            let mut v: Vec<f64> = (0..n).map(|_| rng.next()).collect();
            let before = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            basis.orthogonalise(&mut v, 0);
            let after = v.iter().map(|x| x * x).sum::<f64>().sqrt();
            if after > 1e-8 * before {
                basis.push(&v);
                return Ok(());
            }
        }
        Err(FeError::Numerical(
            "could not extend the Krylov basis with a new direction".into(),
        ))
    };
    for _ in 0..BLOCK.min(n) {
        add_fresh(&mut basis, &mut rng)?;
    }

    let mut done = 0; // columns whose operator image has been added to the basis
    let mut locked = 0; // leading columns frozen as converged Ritz vectors
    loop {
        let width = (basis.len - done).min(BLOCK);
        // A block whose new directions would not fit makes the residuals unknowable, unless the
        // basis may grow to the whole space (capacity = n): there the residuals vanish.
        if width == 0 || (basis.len + width > capacity && capacity < n) {
            return Err(FeError::Numerical(format!(
                "shift-invert Lanczos did not converge {n_modes} modes within {capacity} vectors"
            )));
        }
        let mut z = Mat::<f64>::zeros(n, width);
        for c in 0..width {
            z.col_mut(c).copy_from(basis.mq.col(done + c));
        }
        llt.solve_in_place(z.as_mut());
        let scales: Vec<f64> = (0..width).map(|c| z.col(c).norm_l2()).collect();
        let block_coef = basis.orthogonalise_block(&mut z);
        let len_before = basis.len;
        for c in 0..width {
            for r in 0..len_before {
                h[(r, done + c)] = block_coef[(r, c)];
            }
            let mut v: Vec<f64> = z.col(c).iter().copied().collect();
            let scale = scales[c];
            let mut before = norm2(&v);
            // Against the vectors this block has added so far.
            let coef = basis.orthogonalise(&mut v, len_before);
            for (k, value) in coef.iter().enumerate() {
                h[(len_before + k, done + c)] = *value;
            }
            let mut rest = norm2(&v);
            // Whenever a pass cancels most of the vector, its rounding (ε times the norm before)
            // is no longer small against what is left, and it lies along the whole basis, not
            // only along the vectors this pass used: repeat against everything until a pass
            // keeps at least half (Daniel-Gragg-Kaufman-Stewart).
            let mut independent = true;
            for pass in 0.. {
                if rest >= 0.5 * before {
                    break;
                }
                if pass == 3 {
                    independent = false;
                    break;
                }
                let coef = basis.orthogonalise(&mut v, 0);
                for (r, value) in coef.iter().enumerate() {
                    h[(r, done + c)] += *value;
                }
                before = rest;
                rest = norm2(&v);
            }
            if basis.len < n {
                // What is left may be 1e-13 of the image and still a genuine direction: the
                // elastic part of a rigid-body-dominated image when θ spans 13 decades.
                if independent && rest > 1e-14 * scale {
                    let norm = basis.push(&v);
                    h[(basis.len - 1, done + c)] = norm;
                } else {
                    // Invariant subspace found: continue with a fresh direction, no coupling.
                    add_fresh(&mut basis, &mut rng)?;
                }
            }
        }
        done += width;
        // Rayleigh-Ritz on the columns whose images are known, apart from the locked ones.
        let active = done - locked;
        let mut t = Mat::<f64>::zeros(active, active);
        for j in 0..active {
            for i in 0..active {
                t[(i, j)] = 0.5 * (h[(locked + i, locked + j)] + h[(locked + j, locked + i)]);
            }
        }
        let evd = t
            .self_adjoint_eigen(Side::Lower)
            .map_err(|e| FeError::Numerical(format!("projected eigenproblem failed: {e:?}")))?;
        let (s, u) = (evd.S(), evd.U());
        let residual = |col: usize| -> f64 {
            let mut sum = 0.0;
            for r in done..basis.len {
                let mut acc = 0.0;
                for i in 0..active {
                    acc += h[(r, locked + i)] * u[(i, col)];
                }
                sum += acc * acc;
            }
            sum.sqrt()
        };
        let converged = |col: usize| s[col] > 0.0 && residual(col) <= RESIDUAL_TOLERANCE * s[col];
        // Locking. The dense eigen solve above is accurate to ε‖T‖ = ε θ_max, so a θ far
        // below the largest is known only to ε θ_max / θ: with σ = −1 on a free steel block
        // (rigid-body θ = 1, first elastic θ ≈ 1e-9) the elastic eigenvalues would carry
        // relative errors of 1e-7. Converged Ritz pairs standing far above the rest are
        // therefore frozen, and the Krylov process restarts M-orthogonal to them: later
        // projected problems hold only the remaining θ.
        if done < n && active > 1 {
            let mut lock = 0;
            for rank in 0..active - 1 {
                let col = active - 1 - rank;
                if !converged(col) {
                    break;
                }
                if s[col] >= LOCK_GAP * s[col - 1].max(0.0) {
                    lock = rank + 1;
                }
            }
            if lock > 0 {
                let mut picked_u = Mat::<f64>::zeros(active, lock);
                for r in 0..lock {
                    picked_u.col_mut(r).copy_from(u.col(active - 1 - r));
                }
                let y = basis.q.as_ref().subcols(locked, active) * &picked_u;
                let my = basis.mq.as_ref().subcols(locked, active) * &picked_u;
                basis.q.as_mut().subcols_mut(locked, lock).copy_from(&y);
                basis.mq.as_mut().subcols_mut(locked, lock).copy_from(&my);
                let kept: Vec<f64> = (0..locked).map(|i| h[(i, i)]).collect();
                h.fill(0.0);
                for (i, theta) in kept.into_iter().enumerate() {
                    h[(i, i)] = theta;
                }
                for r in 0..lock {
                    h[(locked + r, locked + r)] = s[active - 1 - r];
                }
                locked += lock;
                done = locked;
                basis.len = locked;
                for _ in 0..BLOCK.min(n - locked) {
                    add_fresh(&mut basis, &mut rng)?;
                }
                continue;
            }
        }
        if done < n_modes.min(n) {
            continue;
        }
        // Largest θ first, locked and active together: (θ, locked basis column or column of u).
        let mut ritz: Vec<(f64, Result<usize, usize>)> = (0..locked)
            .map(|i| (h[(i, i)], Ok(i)))
            .chain((0..active).map(|c| (s[c], Err(c))))
            .collect();
        ritz.sort_by(|a, b| b.0.total_cmp(&a.0));
        ritz.truncate(n_modes);
        let all_converged = done == n
            || ritz
                .iter()
                .all(|&(_, col)| col.is_ok() || col.is_err_and(converged));
        if all_converged {
            let mut selected = Mat::<f64>::zeros(done, n_modes);
            let mut eigenvalues = Vec::with_capacity(n_modes);
            for (out, &(theta, col)) in ritz.iter().enumerate() {
                if theta.is_nan() || theta <= 0.0 {
                    return Err(FeError::Numerical(format!(
                        "non-positive Ritz value {theta}: K - shift*M is not positive definite"
                    )));
                }
                eigenvalues.push(shift + 1.0 / theta);
                match col {
                    Ok(i) => selected[(i, out)] = 1.0,
                    Err(c) => selected
                        .as_mut()
                        .col_mut(out)
                        .subrows_mut(locked, active)
                        .copy_from(u.col(c)),
                }
            }
            let shapes = basis.q.as_ref().subcols(0, done) * &selected;
            return Ok(Modes {
                eigenvalues,
                shapes,
            });
        }
    }
}
