//! Craig-Bampton reduction of a sparse (K, M) pencil with constraint-mode orthogonalisation
//! (paper §3.2.2–3.2.3, eq. 8–15).
//!
//! Basis `T = [Φ_N  Ψ_C]` in the full DOF space: fixed-interface normal modes `Φ_N` (interface
//! rows zero) and constraint modes `Ψ_C` (interface rows identity, interior rows
//! `−K_II⁻¹ K_IB`, one sparse Cholesky). The reduced matrices `T^T K T`, `T^T M T` are formed from
//! the full matrices, not from the ideal block structure, so the orthogonalisation that follows
//! (eq. 14–15: the reduced eigenproblem) diagonalises them to round-off even though the Lanczos
//! modes are only converged to their residual tolerance.

use faer::linalg::matmul::matmul;
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::Llt;
use faer::{Accum, Mat, Side};

use super::error::CmsError;
use super::sparse_ops::Partition;
use super::spec::ModeSelection;
use crate::eigen::block_product::BlockProduct;
use crate::eigen::slicing::{eigenvalue_count, prefer_slicing, sliced_modes, SliceStop};
use crate::eigen::{check_pencil, lowest_modes, Modes};
use crate::fe::assembly::SparseMat;
use crate::fe::FeError;

/// The orthogonalised Craig-Bampton modes of a structure, in the full DOF space.
#[derive(Debug, Clone)]
pub struct CraigBampton {
    /// Natural frequency of every mode (rad/s), ascending.
    pub omega: Vec<f64>,
    /// Mode shapes as columns over all equations; `shapesᵀ M shapes = I`,
    /// `shapesᵀ K shapes = diag(ω²)`.
    pub shapes: Mat<f64>,
    /// Frequencies (Hz) of the fixed-interface normal modes that were kept.
    pub fixed_interface_hz: Vec<f64>,
    /// Number of constraint modes (= interface DOFs).
    pub n_constraint_modes: usize,
}

/// The `count` lowest eigenpairs of (K_II, M_II).
///
/// K_II is positive definite (the interface holds the structure), so shift 0 lies below the
/// lowest fixed-interface eigenvalue. The FE solver sizes its Krylov space by the number of modes
/// asked for, which for a small count can be too small to converge on clustered spectra; then a
/// larger set is asked for and truncated.
fn lowest_of_interior(k_ii: &SparseMat, m_ii: &SparseMat, count: usize) -> Result<Modes, CmsError> {
    let n = k_ii.nrows();
    let mut request = count;
    loop {
        match lowest_modes(k_ii, m_ii, request, 0.0) {
            Ok(modes) if request == count => return Ok(modes),
            Ok(modes) => {
                return Ok(Modes {
                    eigenvalues: modes.eigenvalues[..count].to_vec(),
                    shapes: modes.shapes.subcols(0, count).to_owned(),
                })
            }
            Err(FeError::Numerical(m)) if m.contains("did not converge") && request < n => {
                request = (2 * request).min(n);
            }
            Err(e) => return Err(e.into()),
        }
    }
}

/// Fixed-interface normal modes of (K_II, M_II) as selected.
///
/// Few modes of a small body come from one shift-invert Lanczos run, many modes or a large
/// body from spectrum slicing ([`prefer_slicing`]). A cut-off is turned into a mode count first by a Sturm count at the
/// cut-off (one LDLᵀ of K_II − λ_cut M_II), so no solve is repeated with a larger request.
fn fixed_interface_modes(
    k_ii: &SparseMat,
    m_ii: &SparseMat,
    selection: ModeSelection,
) -> Result<Modes, CmsError> {
    let n = k_ii.nrows();
    let none = || Modes {
        eigenvalues: Vec::new(),
        shapes: Mat::zeros(n, 0),
    };
    match selection {
        ModeSelection::Count(0) => Ok(none()),
        ModeSelection::Count(count) => {
            if count > n {
                return Err(CmsError::InvalidInput(format!(
                    "selection.count = {count} exceeds the {n} interior DOFs"
                )));
            }
            if !prefer_slicing(n, count) {
                lowest_of_interior(k_ii, m_ii, count)
            } else {
                Ok(sliced_modes(k_ii, m_ii, 0.0, SliceStop::Count(count))?)
            }
        }
        ModeSelection::CutoffHz(cutoff) => {
            if !(cutoff.is_finite() && cutoff > 0.0) {
                return Err(CmsError::InvalidInput(format!(
                    "selection.cutoff_hz = {cutoff} must be finite and > 0"
                )));
            }
            let lambda_cut = (2.0 * std::f64::consts::PI * cutoff).powi(2);
            // K_II is positive definite: every eigenvalue lies above 0.
            let (_, count) = eigenvalue_count(k_ii, m_ii, lambda_cut)?;
            let modes = if count == 0 {
                return Ok(none());
            } else if !prefer_slicing(n, count) {
                lowest_of_interior(k_ii, m_ii, count.min(n))?
            } else {
                sliced_modes(k_ii, m_ii, 0.0, SliceStop::Upper(lambda_cut))?
            };
            let keep = modes
                .frequencies_hz()
                .iter()
                .take_while(|&&f| f < cutoff)
                .count();
            Ok(Modes {
                eigenvalues: modes.eigenvalues[..keep].to_vec(),
                shapes: modes.shapes.subcols(0, keep).to_owned(),
            })
        }
    }
}

/// Rows per block in the final T X: bounds the temporary to a few MB instead of a second
/// n × r matrix.
const PROJECTION_CHUNK: usize = 4096;

/// Columns of T per block in [`projected`].
const PROJECTION_COLUMNS: usize = 64;

/// Tᵀ A T for a symmetric A, with A T formed a block of T's columns at a time (one pass over
/// A per eight columns, [`BlockProduct`]).
///
/// The columns before `exact_from` (the normal modes) get their lower triangle only, mirrored:
/// half the dense products. The columns from `exact_from` on (the constraint modes) get both
/// triangles, averaged: their entries are differences of large stiffness terms that cancel to
/// round-off (Ψᵀ K Ψ is the interface's Schur complement), and the average halves that
/// round-off where one triangle alone made the default body's static interface flexibility
/// ten times less accurate (1e-8 instead of 1e-9).
fn projected(
    a: &SparseMat,
    t: &Mat<f64>,
    exact_from: usize,
    product: &mut BlockProduct,
) -> Mat<f64> {
    let (n, r) = (t.nrows(), t.ncols());
    let mut out = Mat::<f64>::zeros(r, r);
    let mut at = Mat::<f64>::zeros(n, PROJECTION_COLUMNS.min(r));
    let starts = (0..exact_from)
        .step_by(PROJECTION_COLUMNS)
        .chain((exact_from..r).step_by(PROJECTION_COLUMNS));
    for start in starts {
        let end = if start < exact_from { exact_from } else { r };
        let w = PROJECTION_COLUMNS.min(end - start);
        product.apply(
            a,
            t.as_ref().subcols(start, w),
            at.as_mut().subcols_mut(0, w),
        );
        let first_row = if start < exact_from { start } else { 0 };
        // (A T_b)ᵀ T: faer streams T faster in this orientation than as Tᵀ (A T_b).
        matmul(
            out.as_mut()
                .submatrix_mut(first_row, start, r - first_row, w)
                .transpose_mut(),
            Accum::Replace,
            at.as_ref().subcols(0, w).transpose(),
            t.as_ref().subcols(first_row, r - first_row),
            1.0,
            faer::get_global_parallelism(),
        );
    }
    for j in 0..r {
        for i in 0..j {
            out[(i, j)] = if j >= exact_from {
                0.5 * (out[(i, j)] + out[(j, i)])
            } else {
                out[(j, i)]
            };
            out[(j, i)] = out[(i, j)];
        }
    }
    out
}

/// Symmetric part of a square matrix.
fn symmetrised(a: &Mat<f64>) -> Mat<f64> {
    Mat::from_fn(a.nrows(), a.ncols(), |i, j| 0.5 * (a[(i, j)] + a[(j, i)]))
}

/// Eigenpairs of the dense pencil (K_r, M_r), M_r positive definite: eigenvalues ascending,
/// eigenvectors `X` with `Xᵀ M_r X = I`.
fn reduced_eigen(k_r: &Mat<f64>, m_r: &Mat<f64>) -> Result<(Vec<f64>, Mat<f64>), CmsError> {
    let llt = m_r.llt(Side::Lower).map_err(|e| {
        CmsError::Numerical(format!(
            "reduced mass matrix is not positive definite ({e:?}): a basis vector carries no mass"
        ))
    })?;
    let l = llt.L();
    // C = L⁻¹ K L⁻ᵀ, symmetric.
    let mut a = k_r.clone();
    l.solve_lower_triangular_in_place(a.as_mut());
    let mut c = a.transpose().to_owned();
    l.solve_lower_triangular_in_place(c.as_mut());
    let c = symmetrised(&c);
    let evd = c
        .self_adjoint_eigen(Side::Lower)
        .map_err(|e| CmsError::Numerical(format!("reduced eigenproblem failed: {e:?}")))?;
    let (s, u) = (evd.S(), evd.U());
    let r = c.nrows();
    let mut order: Vec<usize> = (0..r).collect();
    order.sort_by(|&a, &b| s[a].total_cmp(&s[b]));
    let lambda: Vec<f64> = order.iter().map(|&i| s[i]).collect();
    let mut x = Mat::from_fn(r, r, |i, j| u[(i, order[j])]);
    l.transpose().solve_upper_triangular_in_place(x.as_mut());
    Ok((lambda, x))
}

/// A Craig-Bampton basis and the pencil projected on it, before the orthogonalisation.
#[derive(Debug, Clone)]
pub struct CraigBamptonBasis {
    /// Basis vectors over all equations: the kept fixed-interface modes (unit modal mass), then
    /// the constraint modes in the order of the interface equations (unit interface motion).
    pub t: Mat<f64>,
    /// `Tᵀ K T` (exactly symmetric).
    pub k_r: Mat<f64>,
    /// `Tᵀ M T` (exactly symmetric).
    pub m_r: Mat<f64>,
    /// Frequencies (Hz) of the fixed-interface normal modes that were kept.
    pub fixed_interface_hz: Vec<f64>,
    /// Number of constraint modes (= interface DOFs).
    pub n_constraint_modes: usize,
}

/// The Craig-Bampton basis of the pencil (K, M) on the interface equations `interface`, with
/// the fixed-interface modes chosen by `selection`, and the reduced matrices.
///
/// K must be positive definite on the interior DOFs (the interface fixed), M positive
/// semi-definite.
pub fn craig_bampton_basis(
    k: &SparseMat,
    m: &SparseMat,
    interface: &[usize],
    selection: ModeSelection,
) -> Result<CraigBamptonBasis, CmsError> {
    check_pencil(k, m).map_err(|e| match e {
        FeError::InvalidInput(what) => CmsError::InvalidInput(what),
        other => other.into(),
    })?;
    let n = k.nrows();
    let part = Partition::new(n, interface)?;
    let k_ii = part.interior_block(k, "K")?;
    let m_ii = part.interior_block(m, "M")?;

    // Constraint modes: Ψ_I = −K_II⁻¹ K_IB.
    let llt: Llt<usize, f64> = k_ii.sp_cholesky(Side::Lower).map_err(|e| {
        CmsError::Numerical(format!(
            "K_II is not positive definite ({e:?}): the structure with its interface held still \
             has a mechanism or an unconstrained DOF"
        ))
    })?;
    let mut psi = part.interior_boundary_block(k);
    for v in psi.col_iter_mut() {
        for x in v.iter_mut() {
            *x = -*x;
        }
    }
    llt.solve_in_place(psi.as_mut());
    // At a million DOF every n × r matrix is gigabytes: free what is no longer needed.
    drop(llt);

    let normal = fixed_interface_modes(&k_ii, &m_ii, selection)?;
    drop((k_ii, m_ii));
    let fixed_interface_hz = normal.frequencies_hz();
    let (nf, nb) = (normal.len(), interface.len());
    let r = nf + nb;

    let mut t = Mat::<f64>::zeros(n, r);
    for (ii, &g) in part.interior.iter().enumerate() {
        for c in 0..nf {
            t[(g, c)] = normal.shapes[(ii, c)];
        }
        for b in 0..nb {
            t[(g, nf + b)] = psi[(ii, b)];
        }
    }
    for (b, &g) in part.boundary.iter().enumerate() {
        t[(g, nf + b)] = 1.0;
    }
    drop(psi);
    drop(normal);

    let mut product = BlockProduct::new();
    let m_r = projected(m, &t, nf, &mut product);
    let k_r = projected(k, &t, nf, &mut product);
    Ok(CraigBamptonBasis {
        t,
        k_r,
        m_r,
        fixed_interface_hz,
        n_constraint_modes: nb,
    })
}

/// The orthogonalisation (eq. 14–15) of a reduced pencil (K_r, M_r), M_r positive definite:
/// the frequencies ω (rad/s, ascending) and the coefficients `C` with `Cᵀ M_r C = I` and
/// `Cᵀ K_r C = diag(ω²)`. The modes over the structure are `T C`. Shared by the in-process
/// reduction and the bodies reduced elsewhere ([`crate::cms::reduce_external`]), so both go the same
/// way from the Craig-Bampton matrices to the modes the coupled model gets.
pub fn orthogonalise(k_r: &Mat<f64>, m_r: &Mat<f64>) -> Result<(Vec<f64>, Mat<f64>), CmsError> {
    let r = k_r.nrows();
    if k_r.ncols() != r || m_r.nrows() != r || m_r.ncols() != r {
        return Err(CmsError::InvalidInput(format!(
            "reduced K is {}x{}, reduced M is {}x{}: both must be square and of equal size",
            k_r.nrows(),
            k_r.ncols(),
            m_r.nrows(),
            m_r.ncols()
        )));
    }
    // Unit generalised mass on every basis vector keeps M_r well conditioned (constraint modes
    // in metres carry up to the whole body mass, normal modes one).
    let scale: Vec<f64> = (0..r)
        .map(|i| {
            let mii = m_r[(i, i)];
            if mii > 0.0 && mii.is_finite() {
                Ok(1.0 / mii.sqrt())
            } else {
                Err(CmsError::Numerical(format!(
                    "basis vector {i} has generalised mass {mii}: an interface DOF without mass \
                     coupling"
                )))
            }
        })
        .collect::<Result<_, _>>()?;
    let m_s = Mat::from_fn(r, r, |i, j| m_r[(i, j)] * scale[i] * scale[j]);
    let k_s = Mat::from_fn(r, r, |i, j| k_r[(i, j)] * scale[i] * scale[j]);
    let (lambda, x) = reduced_eigen(&k_s, &m_s)?;
    check_held(&lambda)?;
    if let Some(bad) = lambda.iter().position(|l| !(l.is_finite() && *l > 0.0)) {
        return Err(CmsError::Numerical(format!(
            "reduced mode {bad} has eigenvalue {}: K is not positive definite",
            lambda[bad]
        )));
    }
    let coefficients = Mat::from_fn(r, r, |i, j| scale[i] * x[(i, j)]);
    Ok((lambda.iter().map(|l| l.sqrt()).collect(), coefficients))
}

/// Lowest frequency (Hz) a held body may have: a car body on its suspension has its lowest
/// modes (bounce, pitch, roll) near 1 Hz, two decades above; a rigid-body mode that round-off
/// makes slightly positive lies far below.
pub const RIGID_BODY_HZ: f64 = 0.01;

/// Round-off of an eigenvalue relative to the largest of the reduced pencil: a rigid-body mode
/// comes out as a few thousand ε·λ_max at most (ε the machine epsilon; the reduced matrices are
/// dense products of length n_reduced). This term only matters for λ_max above ~1e10 (s⁻²).
const ROUND_OFF_FACTOR: f64 = 1e3;

/// Refuses a reduced pencil with rigid-body modes (eigenvalues ω² ≈ 0, of either sign): the body
/// is not held (free-free, or a mechanism), which the coupled model cannot carry. The threshold
/// is the larger of (2π·[`RIGID_BODY_HZ`])² and [`ROUND_OFF_FACTOR`]·ε·λ_max; a clearly negative
/// eigenvalue is left to the positive-definiteness check (a K that is wrong, not unheld).
fn check_held(lambda: &[f64]) -> Result<(), CmsError> {
    let largest = lambda.iter().fold(0.0f64, |m, l| m.max(l.abs()));
    let floor = (2.0 * std::f64::consts::PI * RIGID_BODY_HZ)
        .powi(2)
        .max(ROUND_OFF_FACTOR * f64::EPSILON * largest);
    let free: Vec<f64> = lambda
        .iter()
        .copied()
        .filter(|l| l.abs() <= floor)
        .collect();
    if free.is_empty() {
        return Ok(());
    }
    let hz = |l: f64| l.abs().sqrt() / (2.0 * std::f64::consts::PI);
    Err(CmsError::InvalidInput(format!(
        "the body is not held: {} reduced mode(s) have |ω²| ≤ {floor:.3e} s⁻² (below {:.3} Hz; \
         lowest ω² = {:.3e} s⁻²), i.e. it can move as a rigid body or mechanism without \
         deforming (6 such modes: free-free, no SPC and no springs to ground). Add SPCs or \
         springs to ground (CELAS2, CBUSH) at the wheel centres, as the suspension holds the body",
        free.len(),
        hz(floor),
        free.iter().fold(f64::INFINITY, |m, &l| m.min(l))
    )))
}

/// Craig-Bampton reduction of the pencil (K, M) onto the interface equations `interface`,
/// keeping the fixed-interface modes chosen by `selection`, then orthogonalised
/// ([`craig_bampton_basis`], then [`orthogonalise`]).
///
/// K must be positive definite on the interior DOFs (the interface fixed), M positive
/// semi-definite with the reduced mass positive definite.
pub fn craig_bampton(
    k: &SparseMat,
    m: &SparseMat,
    interface: &[usize],
    selection: ModeSelection,
) -> Result<CraigBampton, CmsError> {
    let CraigBamptonBasis {
        mut t,
        k_r,
        m_r,
        fixed_interface_hz,
        n_constraint_modes,
    } = craig_bampton_basis(k, m, interface, selection)?;
    let (omega, x) = orthogonalise(&k_r, &m_r)?;
    // shapes = T X, row block by row block into T's own storage: at a million DOF a second
    // n × r matrix would be gigabytes.
    let n = t.nrows();
    for start in (0..n).step_by(PROJECTION_CHUNK) {
        let len = PROJECTION_CHUNK.min(n - start);
        let rows = t.as_ref().subrows(start, len) * &x;
        t.as_mut().subrows_mut(start, len).copy_from(&rows);
    }
    Ok(CraigBampton {
        omega,
        shapes: t,
        fixed_interface_hz,
        n_constraint_modes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use faer::sparse::{SparseColMat, Triplet};

    /// 42 masses, 2 interface DOFs: 40 interior DOFs, a whole number of the FE Lanczos solver's
    /// blocks of 8, which it needs to return every mode of a small system.
    const N: usize = 42;
    const INTERFACE: [usize; 2] = [13, 29];
    const K: f64 = 1.0e4;
    const MASS: f64 = 2.0;

    /// Chain of N equal masses and springs, grounded at mass 0, free at mass N−1.
    fn chain() -> (SparseMat, SparseMat) {
        let mut k = Vec::new();
        let mut m = Vec::new();
        for i in 0..N {
            // Spring to the left neighbour (or ground) and to the right neighbour if any.
            let diag = if i + 1 < N { 2.0 * K } else { K };
            k.push(Triplet::new(i, i, diag));
            if i + 1 < N {
                k.push(Triplet::new(i, i + 1, -K));
                k.push(Triplet::new(i + 1, i, -K));
            }
            m.push(Triplet::new(i, i, MASS));
        }
        (
            SparseColMat::try_new_from_triplets(N, N, &k).unwrap(),
            SparseColMat::try_new_from_triplets(N, N, &m).unwrap(),
        )
    }

    /// Analytic eigenvalues of the fixed-free chain: (4k/m) sin²((2j−1)π / (2(2N+1))).
    fn exact() -> Vec<f64> {
        (1..=N)
            .map(|j| {
                let s =
                    ((2 * j - 1) as f64 * std::f64::consts::PI / (2.0 * (2 * N + 1) as f64)).sin();
                4.0 * K / MASS * s * s
            })
            .collect()
    }

    #[test]
    fn all_fixed_interface_modes_reproduce_the_analytic_spectrum() {
        let (k, m) = chain();
        let cb = craig_bampton(&k, &m, &INTERFACE, ModeSelection::Count(N - 2)).unwrap();
        assert_eq!(cb.omega.len(), N);
        for (w, l) in cb.omega.iter().zip(exact()) {
            assert!((w * w / l - 1.0).abs() < 1e-10, "{} vs {l}", w * w);
        }
    }

    #[test]
    fn truncated_bases_bound_the_spectrum_from_above() {
        let (k, m) = chain();
        let exact = exact();
        for count in [0, 1, 3, 6] {
            let cb = craig_bampton(&k, &m, &INTERFACE, ModeSelection::Count(count)).unwrap();
            assert_eq!(cb.omega.len(), count + 2);
            for (w, l) in cb.omega.iter().zip(&exact) {
                assert!(w * w >= l * (1.0 - 1e-12), "count {count}: {} < {l}", w * w);
            }
        }
        // A cut-off keeps exactly the fixed-interface modes below it.
        let cb = craig_bampton(&k, &m, &INTERFACE, ModeSelection::CutoffHz(10.0)).unwrap();
        assert!(cb.fixed_interface_hz.iter().all(|&f| f < 10.0));
        let all = craig_bampton(&k, &m, &INTERFACE, ModeSelection::Count(N - 2)).unwrap();
        let below = all.fixed_interface_hz.iter().filter(|&&f| f < 10.0).count();
        assert_eq!(cb.fixed_interface_hz.len(), below);
    }

    #[test]
    fn bad_requests_are_named() {
        let (k, m) = chain();
        let e = craig_bampton(&k, &m, &[4], ModeSelection::Count(N))
            .unwrap_err()
            .to_string();
        assert!(e.contains("selection.count"), "{e}");
        let e = craig_bampton(&k, &m, &[4], ModeSelection::CutoffHz(f64::NAN))
            .unwrap_err()
            .to_string();
        assert!(e.contains("cutoff_hz"), "{e}");
        let e = craig_bampton(&k, &m, &[N], ModeSelection::Count(1))
            .unwrap_err()
            .to_string();
        assert!(e.contains(&format!("equation {N}")), "{e}");
        let massless = SparseColMat::<usize, f64>::try_new_from_triplets(N, N, &[]).unwrap();
        let e = craig_bampton(&k, &massless, &[4], ModeSelection::Count(0))
            .unwrap_err()
            .to_string();
        assert!(e.contains("generalised mass 0"), "{e}");
    }
}
