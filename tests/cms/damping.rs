//! The suspension dampers of the FE model as modal damping: the reduced response around the
//! body's rigid-body modes on the suspension against a direct solve of the full model with its
//! discrete damping matrix C.

use engine_mount_chassis::cms::{
    reduce_detailed, DampingTable, ModeSelection, PointDof, ReductionSpec, Response,
};
use faer::c64;
use faer::linalg::solvers::Solve;
use faer::sparse::linalg::solvers::{Lu, SymbolicLu};
use faer::sparse::{SparseColMat, Triplet};
use faer::Mat;

#[test]
fn suspension_dampers_damp_the_rigid_body_modes_like_the_full_model() {
    // No table damping: all damping comes from the discrete dampers.
    let spec = ReductionSpec {
        selection: ModeSelection::Count(20),
        damping: DampingTable::uniform(0.0),
        discrete_dampers: true,
        ..ReductionSpec::default()
    };
    let r = reduce_detailed(&spec).expect("reduction");
    let hz: Vec<f64> = r
        .reduced
        .omega
        .iter()
        .map(|w| w / (2.0 * std::f64::consts::PI))
        .collect();
    println!("rigid-body modes (Hz) {:.2?}", &hz[..6]);
    println!("damping ratios {:.3?}", &r.reduced.zeta[..6]);
    // The FE description states about 23 % of critical in bounce; every rigid-body mode is damped.
    assert!(r.reduced.zeta[..6].iter().all(|&z| z > 0.05));
    assert!(r.reduced.zeta[0] > 0.15 && r.reduced.zeta[0] < 0.3);

    let (k, m, c) = (&r.assembled.k, &r.assembled.m, &r.assembled.c);
    let n = k.nrows();
    let input = PointDof {
        point: "mount_front_left",
        dof: 2,
    };
    let output = PointDof {
        point: "steering_wheel",
        dof: 2,
    };
    let global = |at: PointDof<'_>| {
        let node = r.reduced.point(at.point).expect("point").node;
        r.assembled.dofs.global(node, at.dof).expect("free DOF")
    };
    let (gi, go) = (global(input), global(output));
    let freqs = [0.8, 1.2, 1.5, 2.0, 3.0, 4.0, 6.0];
    let matrix = |w: f64| {
        let mut entries = Vec::new();
        for (a, factor) in [
            (k, c64::new(1.0, 0.0)),
            (c, c64::new(0.0, w)),
            (m, c64::new(-w * w, 0.0)),
        ] {
            let (cp, ri, val) = (a.symbolic().col_ptr(), a.symbolic().row_idx(), a.val());
            for j in 0..a.ncols() {
                for p in cp[j]..cp[j + 1] {
                    entries.push(Triplet::new(ri[p], j, factor * val[p]));
                }
            }
        }
        SparseColMat::<usize, c64>::try_new_from_triplets(n, n, &entries).expect("matrix")
    };
    let symbolic = SymbolicLu::try_new(matrix(1.0).symbolic()).expect("symbolic LU");
    let reduced = r
        .reduced
        .transfer_function(input, output, Response::Acceleration, &freqs)
        .expect("transfer function");
    let mut undamped = r.reduced.clone();
    undamped.zeta.iter_mut().for_each(|z| *z = 0.0);
    let without = undamped
        .transfer_function(input, output, Response::Acceleration, &freqs)
        .expect("transfer function");
    let (mut worst_with, mut worst_without) = (0.0f64, 0.0f64);
    for ((f, h), h0) in freqs.iter().zip(&reduced).zip(&without) {
        let w = 2.0 * std::f64::consts::PI * f;
        let lu = Lu::try_new_with_symbolic(symbolic.clone(), matrix(w).as_ref()).expect("LU");
        let mut rhs = Mat::<c64>::zeros(n, 1);
        rhs[(gi, 0)] = c64::new(1.0, 0.0);
        lu.solve_in_place(rhs.as_mut());
        let direct = rhs[(go, 0)] * (-w * w);
        let err = (h - direct).norm() / direct.norm();
        let err0 = (h0 - direct).norm() / direct.norm();
        println!(
            "{f:4.1} Hz: |H| direct {:.3e}, reduced {:.3e}; error {err:.3}, without dampers {err0:.3}",
            direct.norm(),
            h.norm()
        );
        worst_with = worst_with.max(err);
        worst_without = worst_without.max(err0);
    }
    // The diagonal of ΦᵀCΦ neglects the coupling that C adds between the closely spaced,
    // heavily damped rigid-body modes: a few per cent. Without the dampers the response near
    // the bounce mode is far off.
    assert!(worst_with < 0.1, "with dampers: error {worst_with}");
    assert!(
        worst_without > 0.5,
        "without dampers: error only {worst_without}"
    );
}
