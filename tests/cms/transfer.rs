//! Transfer functions of the chassis alone (paper §5.3, Fig. 8): unit vertical force at the
//! front-left engine-girder mount node → steering-wheel acceleration, 5–150 Hz. The reduced
//! model is checked against direct sparse solves of the full FE model.

use std::sync::OnceLock;

use engine_mount_chassis::cms::{
    reduce_detailed, DampingTable, ModeSelection, PointDof, ReducedChassis, Reduction,
    ReductionSpec, Response,
};
use engine_mount_chassis::eigen::lowest_modes;
use faer::c64;
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::{SparseColMat, Triplet};
use faer::Mat;

const INPUT: PointDof<'static> = PointDof {
    point: "mount_front_left",
    dof: 2,
};
const OUTPUTS: [PointDof<'static>; 2] = [
    PointDof {
        point: "steering_wheel",
        dof: 2,
    },
    PointDof {
        point: "steering_wheel",
        dof: 1,
    },
];

/// Highest frequency of interest of the transfer functions (Hz).
const F_MAX: f64 = 150.0;

fn reduction(selection: ModeSelection) -> Reduction {
    reduce_detailed(&ReductionSpec {
        selection,
        ..ReductionSpec::default()
    })
    .expect("reduction of the default body")
}

/// Fixed-interface modes up to 3x the highest frequency of interest.
fn fine() -> &'static Reduction {
    static R: OnceLock<Reduction> = OnceLock::new();
    R.get_or_init(|| reduction(ModeSelection::CutoffHz(3.0 * F_MAX)))
}

/// Eigenfrequencies (Hz) of the full FE model up to a little beyond F_MAX.
fn full_hz() -> &'static Vec<f64> {
    static F: OnceLock<Vec<f64>> = OnceLock::new();
    F.get_or_init(|| {
        let asm = &fine().assembled;
        let hz = lowest_modes(&asm.k, &asm.m, 80, -1.0)
            .expect("full eigen solve")
            .frequencies_hz();
        assert!(
            *hz.last().unwrap() > 1.1 * F_MAX,
            "need modes beyond {F_MAX} Hz"
        );
        hz
    })
}

/// Full-model accelerance at global equation `out` to a unit force at equation `inp`, by direct
/// sparse LU solves of (K (1 + iωβ) − ω² M) u = e_in: stiffness-proportional damping, which in
/// any M-orthonormal modal basis of the same K is modal with ζ_k = β ω_k / 2.
fn direct_accelerance(r: &Reduction, beta: f64, freqs: &[f64], inp: usize, out: usize) -> Vec<c64> {
    let (k, m) = (&r.assembled.k, &r.assembled.m);
    let n = k.nrows();
    let matrix = |w: f64| {
        let mut entries = Vec::with_capacity(k.compute_nnz() + m.compute_nnz());
        for (a, factor) in [(k, c64::new(1.0, w * beta)), (m, c64::new(-w * w, 0.0))] {
            let (cp, ri, val) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
            for j in 0..a.ncols() {
                for p in cp[j]..cp[j + 1] {
                    entries.push(Triplet::new(ri[p], j, factor * val[p]));
                }
            }
        }
        SparseColMat::<usize, c64>::try_new_from_triplets(n, n, &entries).expect("matrix")
    };
    // Same pattern at every frequency: one symbolic analysis.
    let symbolic = SymbolicLu::try_new(matrix(1.0).symbolic()).expect("symbolic LU");
    freqs
        .iter()
        .map(|f| {
            let w = 2.0 * std::f64::consts::PI * f;
            let a = matrix(w);
            let lu = Lu::try_new_with_symbolic(symbolic.clone(), a.as_ref())
                .expect("K(1+iwb) - w^2 M is regular");
            let mut rhs = Mat::<c64>::zeros(n, 1);
            rhs[(inp, 0)] = c64::new(1.0, 0.0);
            lu.solve_in_place(rhs.as_mut());
            rhs[(out, 0)] * (-w * w)
        })
        .collect()
}

fn global(r: &Reduction, at: PointDof<'_>) -> usize {
    let node = r.reduced.point(at.point).expect("recovery point").node;
    r.assembled.dofs.global(node, at.dof).expect("free DOF")
}

fn with_zeta(r: &ReducedChassis, zeta: impl Fn(f64) -> f64) -> ReducedChassis {
    let mut out = r.clone();
    out.zeta = r.omega.iter().map(|&w| zeta(w)).collect();
    out
}

/// Local maxima of |h| on `freqs` above `fraction` of the largest value: (index, frequency).
fn peaks(freqs: &[f64], h: &[c64], fraction: f64) -> Vec<(usize, f64)> {
    let top = h.iter().map(|v| v.norm()).fold(0.0, f64::max);
    (1..h.len() - 1)
        .filter(|&i| {
            let a = h[i].norm();
            a > h[i - 1].norm() && a >= h[i + 1].norm() && a > fraction * top
        })
        .map(|i| (i, freqs[i]))
        .collect()
}

fn sweep() -> Vec<f64> {
    (0..=7250).map(|i| 5.0 + 0.02 * i as f64).collect()
}

#[test]
fn reduced_transfer_function_converges_to_a_direct_solve_of_the_full_model() {
    let beta = 2.0 * 0.01 / (2.0 * std::f64::consts::PI * 30.0); // ζ = 1 % at 30 Hz
    let coarse = reduction(ModeSelection::Count(20));
    let freqs = [5.0, 20.0, 33.0, 50.0, 62.0, 90.0, 130.0, 150.0];
    for out in OUTPUTS {
        let direct = direct_accelerance(
            fine(),
            beta,
            &freqs,
            global(fine(), INPUT),
            global(fine(), out),
        );
        let error = |r: &Reduction| -> Vec<f64> {
            let reduced = with_zeta(&r.reduced, |w| 0.5 * beta * w);
            let h = reduced
                .transfer_function(INPUT, out, Response::Acceleration, &freqs)
                .expect("transfer function");
            h.iter()
                .zip(&direct)
                .map(|(a, b)| (a - b).norm() / b.norm())
                .collect()
        };
        let (e_coarse, e_fine) = (error(&coarse), error(fine()));
        for (i, f) in freqs.iter().enumerate() {
            println!(
                "{}/{} {f:5.1} Hz: |H| {:.3e} m/s²/N; relative error 20 modes {:.1e}, \
                 modes to {} Hz {:.1e}",
                out.point,
                out.dof,
                direct[i].norm(),
                e_coarse[i],
                3.0 * F_MAX,
                e_fine[i]
            );
            // Truncation error of the fixed-interface modes grows like (f / f_cut)²: about 1 %
            // at a ninth of the cut-off, about 10 % at a third.
            let tolerance = if *f <= F_MAX / 3.0 { 0.01 } else { 0.1 };
            assert!(e_fine[i] < tolerance, "{f} Hz: error {:e}", e_fine[i]);
            assert!(
                e_fine[i] < e_coarse[i],
                "{f} Hz: more modes did not reduce the error ({:e} vs {:e})",
                e_fine[i],
                e_coarse[i]
            );
        }
    }
}

#[test]
fn response_peaks_sit_at_the_full_models_eigenfrequencies() {
    let full = full_hz();
    let freqs = sweep();
    for out in OUTPUTS {
        let h = fine()
            .reduced
            .transfer_function(INPUT, out, Response::Acceleration, &freqs)
            .expect("transfer function");
        let found = peaks(&freqs, &h, 0.05);
        assert!(!found.is_empty());
        for (_, f) in &found {
            let nearest = full
                .iter()
                .map(|m| (f / m - 1.0).abs())
                .fold(f64::INFINITY, f64::min);
            println!(
                "{}/{} peak at {f:.2} Hz, nearest full-model mode {:.2} %",
                out.point,
                out.dof,
                100.0 * nearest
            );
            // Below 100 Hz the modes have 1 % damping: the accelerance peak sits within ζ² of
            // the natural frequency, plus the reduction's frequency error.
            if *f < 100.0 {
                assert!(nearest < 0.005, "peak at {f} Hz is not at a chassis mode");
            }
        }
    }
    // The steering-wheel modes of the body (paper: 31.5 and ~32 Hz) show in its response.
    let h = fine()
        .reduced
        .transfer_function(INPUT, OUTPUTS[1], Response::Acceleration, &freqs)
        .expect("transfer function");
    assert!(peaks(&freqs, &h, 0.05)
        .iter()
        .any(|(_, f)| (31.0..33.0).contains(f)));
}

/// |H − term of the mode nearest to f| / |H|: the relative background of the other modes under
/// a peak (0: a clean single-mode resonance).
fn background(r: &ReducedChassis, out: PointDof<'_>, f: f64, h: c64) -> f64 {
    let w = 2.0 * std::f64::consts::PI * f;
    let k = (0..r.n_modes())
        .min_by(|&a, &b| (r.omega[a] - w).abs().total_cmp(&(r.omega[b] - w).abs()))
        .expect("modes");
    let gain = r.point(INPUT.point).expect("input").shape[k][INPUT.dof]
        * r.point(out.point).expect("output").shape[k][out.dof];
    let (wk, z) = (r.omega[k], r.zeta[k]);
    let term = c64::new(-w * w * gain, 0.0) / c64::new(wk * wk - w * w, 2.0 * z * wk * w);
    (h - term).norm() / h.norm()
}

#[test]
fn doubling_the_modal_damping_halves_the_resonance_peaks() {
    let freqs = sweep();
    let base = DampingTable::default();
    let doubled = base.scaled(2.0);
    let r = &fine().reduced;
    let one = with_zeta(r, |w| base.ratio(w / (2.0 * std::f64::consts::PI)));
    let two = with_zeta(r, |w| doubled.ratio(w / (2.0 * std::f64::consts::PI)));
    assert_eq!(
        &one.zeta, &r.zeta,
        "the reduction applies the default table"
    );
    let mut clean = 0;
    for out in OUTPUTS {
        let h1 = one
            .transfer_function(INPUT, out, Response::Acceleration, &freqs)
            .expect("transfer function");
        let h2 = two
            .transfer_function(INPUT, out, Response::Acceleration, &freqs)
            .expect("transfer function");
        for (i, f) in peaks(&freqs, &h1, 0.05) {
            // Peak of the doubly damped response near the same frequency (±1 Hz).
            let window = (i.saturating_sub(50))..(i + 50).min(freqs.len());
            let p2 = window.map(|j| h2[j].norm()).fold(0.0, f64::max);
            let ratio = h1[i].norm() / p2;
            let beta = background(&one, out, f, h1[i]);
            println!(
                "{}/{} peak at {f:.2} Hz: ratio {ratio:.3}, background of other modes {beta:.3}",
                out.point, out.dof
            );
            // With |b| = β|H| the ratio is at least (1 − β)/(½ + β), above 1 for β < ¼; a peak
            // that is mostly the interference of neighbouring modes may rise with damping.
            if beta < 0.25 {
                assert!(ratio > 1.0, "more damping raised the peak at {f} Hz");
            }
            // Resonant term m ∝ 1/ζ plus a background b, |b| = β|H|, that damping hardly
            // changes: |m + b| / |m/2 + b| lies within 2/(1 ± 3β). Allow 3 % for the shift of
            // the peak and of the background with damping.
            if beta < 0.15 {
                clean += 1;
                let (low, high) = (
                    0.97 * 2.0 / (1.0 + 3.0 * beta),
                    1.03 * 2.0 / (1.0 - 3.0 * beta),
                );
                assert!(
                    (low..=high).contains(&ratio),
                    "peak at {f} Hz: ratio {ratio} outside [{low}, {high}]"
                );
            }
        }
    }
    assert!(clean >= 3, "only {clean} single-mode peaks found");
}
