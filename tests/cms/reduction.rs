//! Verification of the Craig-Bampton reduction of the chassis against the full FE model:
//! Ritz upper bounds and convergence of the frequencies, static exactness at the interface,
//! orthogonality of the final modes in the full matrices.

use std::sync::OnceLock;

use engine_mount_chassis::chassis::config::ChassisConfig;
use engine_mount_chassis::chassis::{Chassis, MountLayout};
use engine_mount_chassis::cms::{
    reduce, reduce_detailed, InterfaceDofs, ModeSelection, ReducedChassis, Reduction, ReductionSpec,
};
use engine_mount_chassis::eigen::lowest_modes;
use engine_mount_chassis::fe::assembly::{mat_vec, SparseMat};
use faer::linalg::solvers::Solve;
use faer::{Mat, Side};

/// Lowest modes of the full model: 6 rigid-body modes on the suspension + 20 elastic.
const N_FULL: usize = 26;

fn reduction_40() -> &'static Reduction {
    static R: OnceLock<Reduction> = OnceLock::new();
    R.get_or_init(|| {
        let spec = ReductionSpec {
            selection: ModeSelection::Count(40),
            ..ReductionSpec::default()
        };
        reduce_detailed(&spec).expect("reduction of the default body")
    })
}

fn full_hz() -> &'static Vec<f64> {
    static F: OnceLock<Vec<f64>> = OnceLock::new();
    F.get_or_init(|| {
        let asm = &reduction_40().assembled;
        lowest_modes(&asm.k, &asm.m, N_FULL, -1.0)
            .expect("full eigen solve")
            .frequencies_hz()
    })
}

fn hz(omega: &[f64]) -> Vec<f64> {
    omega
        .iter()
        .map(|w| w / (2.0 * std::f64::consts::PI))
        .collect()
}

/// Σ_ij |a_i| |K_ij| |b_j|: the scale of the round-off in evaluating aᵀ K b in floating point.
fn abs_form(k: &SparseMat, a: &[f64], b: &[f64]) -> f64 {
    let (cp, ri, val) = (k.symbolic().col_ptr(), k.symbolic().row_idx(), k.val());
    let mut acc = 0.0;
    for (c, bc) in b.iter().enumerate() {
        for p in cp[c]..cp[c + 1] {
            acc += a[ri[p]].abs() * val[p].abs() * bc.abs();
        }
    }
    acc
}

#[test]
fn final_modes_are_mass_orthonormal_and_stiffness_diagonal_in_the_full_matrices() {
    let r = reduction_40();
    let (k, m) = (&r.assembled.k, &r.assembled.m);
    let s = &r.modes.shapes;
    let n_modes = s.ncols();
    assert_eq!(n_modes, 40 + 12);
    let cols: Vec<Vec<f64>> = (0..n_modes)
        .map(|c| s.col(c).iter().copied().collect())
        .collect();
    let omega = &r.modes.omega;
    let max_stiffness = omega.iter().fold(0.0f64, |a, w| a.max(w * w));
    let (mut worst_mass, mut worst_normwise, mut worst_pairwise, mut worst_omega) =
        (0.0f64, 0.0f64, 0.0f64, 0.0f64);
    for j in 0..n_modes {
        let mj = mat_vec(m, &cols[j]);
        let kj = mat_vec(k, &cols[j]);
        for i in 0..n_modes {
            let mij: f64 = cols[i].iter().zip(&mj).map(|(a, b)| a * b).sum();
            let kij: f64 = cols[i].iter().zip(&kj).map(|(a, b)| a * b).sum();
            worst_mass = worst_mass.max((mij - if i == j { 1.0 } else { 0.0 }).abs());
            // Evaluating φ_iᵀ K φ_j in f64 cannot be more exact than this, whatever the shapes.
            let floor = 10.0 * f64::EPSILON * abs_form(k, &cols[i], &cols[j]);
            let pairwise = (omega[i] * omega[j]).max(f64::MIN_POSITIVE);
            if i == j {
                let w2 = omega[i] * omega[i];
                worst_omega = worst_omega.max(((kij - w2).abs() - floor).max(0.0) / w2);
            } else {
                worst_normwise = worst_normwise.max(kij.abs() / max_stiffness);
                worst_pairwise = worst_pairwise.max((kij.abs() - floor).max(0.0) / pairwise);
            }
        }
    }
    println!(
        "|PhiT M Phi - I| {worst_mass:.1e}; PhiT K Phi off-diagonal / max omega^2 \
         {worst_normwise:.1e}, beyond round-off / (omega_i omega_j) {worst_pairwise:.1e}; \
         diagonal vs omega^2 beyond round-off {worst_omega:.1e}"
    );
    assert!(worst_mass < 1e-10, "PhiT M Phi - I: {worst_mass:e}");
    assert!(
        worst_normwise < 1e-10,
        "PhiT K Phi off-diagonal: {worst_normwise:e}"
    );
    assert!(
        worst_pairwise < 1e-10,
        "PhiT K Phi off-diagonal: {worst_pairwise:e}"
    );
    assert!(
        worst_omega < 1e-10,
        "PhiT K Phi diagonal vs omega^2: {worst_omega:e}"
    );
    assert!(r.reduced.omega.windows(2).all(|w| w[0] <= w[1]));
}

/// Flexibility Σ_k φ_a,k φ_b,k / ω_k² of the reduced chassis between the local DOFs `local` of
/// its mount points, from the recovery rows.
fn reduced_flexibility(r: &ReducedChassis, local: &[usize]) -> Mat<f64> {
    let mounts: Vec<_> = r
        .points
        .iter()
        .filter(|p| p.name.starts_with("mount_"))
        .collect();
    let nl = local.len();
    let nb = mounts.len() * nl;
    Mat::from_fn(nb, nb, |a, b| {
        let (pa, da) = (mounts[a / nl], local[a % nl]);
        let (pb, db) = (mounts[b / nl], local[b % nl]);
        (0..r.n_modes())
            .map(|k| pa.shape[k][da] * pb.shape[k][db] / r.omega[k].powi(2))
            .sum()
    })
}

/// Flexibility of the full model between the given equations: K u = e_b by its own Cholesky.
fn full_flexibility(k: &SparseMat, equations: &[usize]) -> Mat<f64> {
    let llt = k.sp_cholesky(Side::Lower).expect("K is positive definite");
    let nb = equations.len();
    let mut rhs = Mat::<f64>::zeros(k.nrows(), nb);
    for (b, &g) in equations.iter().enumerate() {
        rhs[(g, b)] = 1.0;
    }
    llt.solve_in_place(rhs.as_mut());
    Mat::from_fn(nb, nb, |a, b| rhs[(equations[a], b)])
}

/// max |G_reduced − G_full| / max diag G_full.
fn flexibility_error(reduced: &Mat<f64>, full: &Mat<f64>) -> f64 {
    let n = full.nrows();
    assert_eq!(reduced.nrows(), n);
    let scale = (0..n).map(|i| full[(i, i)]).fold(0.0, f64::max);
    let mut worst = 0.0f64;
    for a in 0..n {
        for b in 0..n {
            worst = worst.max((reduced[(a, b)] - full[(a, b)]).abs() / scale);
        }
    }
    worst
}

#[test]
fn static_interface_flexibility_equals_the_full_models() {
    let r = reduction_40();
    let full = full_flexibility(&r.assembled.k, &r.interface);
    let guyan = reduce(&ReductionSpec {
        selection: ModeSelection::Count(0),
        ..ReductionSpec::default()
    })
    .expect("static reduction");
    for (what, reduced) in [("40 modes", &r.reduced), ("0 modes", &guyan)] {
        let worst = flexibility_error(&reduced_flexibility(reduced, &[0, 1, 2]), &full);
        println!("{what}: max |G_red - G_full| / max G_full = {worst:.2e}");
        assert!(
            worst < 1e-8,
            "{what}: interface flexibility error {worst:e}"
        );
    }
}

/// The procedural body's three-mount layout (paper §7.1): its mount nodes by name.
fn three_mount_nodes() -> Vec<String> {
    Chassis::build(&ChassisConfig::default())
        .expect("chassis")
        .mount_nodes(MountLayout::Three)
        .expect("mounts")
        .into_iter()
        .map(|(name, _)| name)
        .collect()
}

#[test]
fn six_dof_interface_of_the_three_mount_layout_is_statically_exact() {
    let spec = ReductionSpec {
        interface: three_mount_nodes(),
        interface_dofs: InterfaceDofs::All,
        selection: ModeSelection::Count(0),
        ..ReductionSpec::default()
    };
    let r = reduce_detailed(&spec).expect("reduction");
    let mounts = r.chassis.mount_nodes(MountLayout::Three).expect("mounts");
    let names: Vec<&str> = r.reduced.points.iter().map(|p| p.name.as_str()).collect();
    let mut expected: Vec<&str> = mounts.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(expected, three_mount_nodes());
    expected.extend(["steering_wheel", "seat_rail"]);
    assert_eq!(names, expected);
    assert_eq!(r.reduced.n_modes(), 3 * 6);
    let full = full_flexibility(&r.assembled.k, &r.interface);
    let worst = flexibility_error(&reduced_flexibility(&r.reduced, &[0, 1, 2, 3, 4, 5]), &full);
    println!("3 mounts x 6 DOFs: max |G_red - G_full| / max G_full = {worst:.2e}");
    assert!(worst < 1e-8, "interface flexibility error {worst:e}");
}

#[test]
fn frequencies_converge_from_above_as_fixed_interface_modes_are_added() {
    let full = full_hz();
    // 3x the highest of the compared frequencies (the 20th elastic mode).
    let cutoff = 3.0 * full[N_FULL - 1];
    let mut previous: Option<Vec<f64>> = None;
    for selection in [
        ModeSelection::Count(0),
        ModeSelection::Count(10),
        ModeSelection::Count(20),
        ModeSelection::Count(40),
        ModeSelection::CutoffHz(cutoff),
    ] {
        let reduced = if selection == ModeSelection::Count(40) {
            reduction_40().reduced.clone()
        } else {
            reduce(&ReductionSpec {
                selection,
                ..ReductionSpec::default()
            })
            .expect("reduction")
        };
        let f = hz(&reduced.omega);
        let compared = f.len().min(N_FULL);
        let worst_elastic = (6..compared)
            .map(|i| f[i] / full[i] - 1.0)
            .fold(0.0, f64::max);
        println!(
            "{selection:?}: {} modes, max elastic error {:.3} %",
            f.len(),
            100.0 * worst_elastic
        );
        for i in 0..compared {
            assert!(
                f[i] >= full[i] * (1.0 - 1e-8),
                "{selection:?}: mode {i} at {} Hz is below the full model's {} Hz",
                f[i],
                full[i]
            );
        }
        if let Some(prev) = &previous {
            for i in 0..compared.min(prev.len()) {
                assert!(
                    f[i] <= prev[i] * (1.0 + 1e-8),
                    "{selection:?}: mode {i} rose from {} to {} Hz with more modes",
                    prev[i],
                    f[i]
                );
            }
        }
        previous = Some(f);
    }
    let last = previous.expect("at least one reduction");
    assert!(last.len() >= N_FULL);
    for i in 6..N_FULL {
        let err = last[i] / full[i] - 1.0;
        assert!(
            err < 0.005,
            "elastic mode {i}: {} Hz vs full {} Hz ({:.3} %) with modes to {cutoff} Hz",
            last[i],
            full[i],
            100.0 * err
        );
    }
}
