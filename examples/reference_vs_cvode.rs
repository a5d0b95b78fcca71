//! Cross-checks the tight-tolerance reference of the accuracy benchmark (our BDF at rtol 1e-10)
//! against SUNDIALS CVODE on the same right-hand side, for scene 1 and scene 2 at 2000 rpm.
//! CVODE forms its own finite-difference Jacobian; a mass matrix (scene 1) is inverted in the
//! right-hand side it sees. A second table compares the cost per step of both integrators at
//! working tolerances (1e-4 … 1e-7), with each one's error against the tight reference, so the
//! two can be compared at equal error. Scene 2 here uses a 100 Hz chassis cut-off (97 states):
//! CVODE's dense finite-difference Jacobian of the default 211 states takes minutes.
//!
//! `cargo run --release --example reference_vs_cvode --features bench-cvode`
//! (scripts/bench-accuracy.sh runs it; it installs libsundials-dev).

#[cfg(not(feature = "bench-cvode"))]
fn main() {
    eprintln!("build with --features bench-cvode (scripts/bench-accuracy.sh does)");
}

#[cfg(feature = "bench-cvode")]
fn main() {
    cvode::main();
}

#[cfg(feature = "bench-cvode")]
mod cvode {
    use std::os::raw::{c_int, c_void};
    use std::time::Instant;

    use engine_mount_chassis::cosim::scene::{apply_inputs, build_model, outputs};
    use engine_mount_chassis::cosim::{BodyOptions, ComfortPoints, Inputs, Outputs, Settings};
    use engine_mount_chassis::model::CoupledModel as Scene;
    use engine_mount_chassis::ode::{Bdf, BdfOptions, OdeProblem, Tolerance};
    use faer::linalg::solvers::Solve;
    use faer::Mat;
    use sundials_sys as sun;

    const RTOL: f64 = 1e-10;
    const ATOL: f64 = 1e-13;
    const T_END: f64 = 0.3;

    fn scene(number: i32) -> (Scene, Vec<f64>) {
        let settings = Settings {
            scene: SceneKind::from_number(number).expect("scene"),
            chassis: BodyOptions {
                mode_cutoff_hz: 100.0,
                ..BodyOptions::default()
            },
            ..Settings::default()
        };
        let inputs = Inputs::steady(2000.0);
        let (mut s, _) = build_model(&settings).expect("scene");
        apply_inputs(&mut s, &inputs).expect("inputs");
        let y0 = s.static_equilibrium(0.0).expect("statics");
        (s, y0)
    }

    /// The scene as CVODE sees it: y' = M(y)^-1 f(y).
    struct User {
        scene: Scene,
        mass: Mat<f64>,
    }

    unsafe extern "C" fn rhs(
        t: f64,
        y: sun::N_Vector,
        ydot: sun::N_Vector,
        ud: *mut c_void,
    ) -> c_int {
        // SAFETY: CVODE passes back the user data pointer we registered (a live `User`) and
        // serial vectors of the problem's dimension.
        let u = unsafe { &mut *(ud as *mut User) };
        let n = u.scene.dim();
        let (ys, fs) = unsafe {
            (
                std::slice::from_raw_parts(sun::N_VGetArrayPointer(y), n),
                std::slice::from_raw_parts_mut(sun::N_VGetArrayPointer(ydot), n),
            )
        };
        if u.scene.rhs(t, ys, fs).is_err() {
            return 1;
        }
        if u.scene.has_mass_matrix() {
            if u.scene.mass(t, ys, u.mass.as_mut()).is_err() {
                return 1;
            }
            let lu = u.mass.partial_piv_lu();
            let mut b = Mat::from_fn(n, 1, |i, _| fs[i]);
            lu.solve_in_place(b.as_mut());
            for (i, f) in fs.iter_mut().enumerate() {
                *f = b[(i, 0)];
            }
        }
        if fs.iter().all(|v| v.is_finite()) {
            0
        } else {
            1
        }
    }

    fn run_cvode(scene: Scene, y0: &[f64], rtol: f64, atol: f64) -> (Vec<f64>, u64, f64) {
        let n = y0.len();
        let started = Instant::now();
        let mut out = vec![0.0; n];
        let mut steps: std::os::raw::c_long = 0;
        let mut user = User {
            mass: Mat::zeros(n, n),
            scene,
        };
        // SAFETY: standard CVODE usage: every object is created, used and freed here; the user
        // data outlives the solver; vector lengths equal n.
        unsafe {
            let mut ctx: sun::SUNContext = std::ptr::null_mut();
            assert_eq!(sun::SUNContext_Create(std::ptr::null_mut(), &mut ctx), 0);
            let y = sun::N_VNew_Serial(n as sun::sunindextype, ctx);
            std::slice::from_raw_parts_mut(sun::N_VGetArrayPointer(y), n).copy_from_slice(y0);
            let mem = sun::CVodeCreate(sun::CV_BDF, ctx);
            assert_eq!(sun::CVodeInit(mem, Some(rhs), 0.0, y), 0);
            assert_eq!(
                sun::CVodeSetUserData(mem, &mut user as *mut User as *mut c_void),
                0
            );
            assert_eq!(sun::CVodeSStolerances(mem, rtol, atol), 0);
            let a = sun::SUNDenseMatrix(n as sun::sunindextype, n as sun::sunindextype, ctx);
            let ls = sun::SUNLinSol_Dense(y, a, ctx);
            assert_eq!(sun::CVodeSetLinearSolver(mem, ls, a), 0);
            sun::CVodeSetMaxNumSteps(mem, 50_000_000);
            sun::CVodeSetStopTime(mem, T_END);
            let mut t = 0.0;
            let flag = sun::CVode(mem, T_END, y, &mut t, sun::CV_NORMAL);
            if flag < 0 {
                eprintln!("CVODE failed with flag {flag} at t = {t}");
            }
            out.copy_from_slice(std::slice::from_raw_parts(sun::N_VGetArrayPointer(y), n));
            sun::CVodeGetNumSteps(mem, &mut steps);
            let mut mem_ptr = mem;
            sun::CVodeFree(&mut mem_ptr);
            sun::SUNLinSolFree(ls);
            sun::SUNMatDestroy(a);
            sun::N_VDestroy(y);
            sun::SUNContext_Free(&mut ctx);
        }
        (out, steps as u64, started.elapsed().as_secs_f64())
    }

    fn run_ours(mut scene: Scene, y0: &[f64], rtol: f64, atol: f64) -> (Vec<f64>, u64, f64) {
        let started = Instant::now();
        let opts = BdfOptions {
            rtol,
            atol: Tolerance::Scalar(atol),
            magnitude_cap: Some(scene.magnitude_caps()),
            ..BdfOptions::default()
        };
        let mut bdf = Bdf::new(&mut scene, 0.0, y0, opts).expect("bdf");
        bdf.advance_to(&mut scene, T_END).expect("advance");
        (
            bdf.y().to_vec(),
            bdf.stats().steps,
            started.elapsed().as_secs_f64(),
        )
    }

    fn forces(o: &Outputs) -> Vec<f64> {
        let mut v: Vec<f64> = o.mount_force.iter().flatten().copied().collect();
        v.extend(o.steering_wheel_acceleration);
        v
    }

    pub fn main() {
        println!(
            "{:<8} {:>8} {:>12} {:>10} {:>12} {:>10} {:>14}",
            "scene",
            "states",
            "ours steps",
            "ours [s]",
            "CVODE steps",
            "CVODE [s]",
            "max rel. diff"
        );
        for number in [1, 2] {
            let (s, y0) = scene(number);
            let (ours, ours_steps, ours_t) = run_ours(s.clone(), &y0, RTOL, ATOL);
            let (theirs, cv_steps, cv_t) = run_cvode(s.clone(), &y0, RTOL, ATOL);
            let a = forces(&outputs(&s, ComfortPoints::of(&s), T_END, &ours).expect("outputs"));
            let b = forces(&outputs(&s, ComfortPoints::of(&s), T_END, &theirs).expect("outputs"));
            let scale = b.iter().map(|x| x.abs()).fold(1e-30, f64::max);
            let diff = a
                .iter()
                .zip(&b)
                .map(|(x, y)| (x - y).abs())
                .fold(0.0, f64::max)
                / scale;
            println!(
                "{:<8} {:>8} {:>12} {:>10.2} {:>12} {:>10.2} {:>14.2e}",
                number,
                y0.len(),
                ours_steps,
                ours_t,
                cv_steps,
                cv_t,
                diff
            );
        }
        println!(
            "(mount forces and steering-wheel acceleration at t = {T_END} s, 2000 rpm, rtol {RTOL:e}, \
             atol {ATOL:e}; difference relative to the largest value)"
        );
        per_step_costs();
    }

    /// The cost per step of both integrators at working tolerances, with their error against
    /// our tight reference: the comparison at equal error the speed work is judged by.
    fn per_step_costs() {
        println!();
        println!(
            "{:<6} {:>7} | {:>9} {:>7} {:>9} {:>9} | {:>9} {:>7} {:>9} {:>9}",
            "scene",
            "rtol",
            "ours err",
            "steps",
            "µs/step",
            "ms total",
            "CVODE err",
            "steps",
            "µs/step",
            "ms total"
        );
        for number in [1, 2] {
            let (s, y0) = scene(number);
            let (reference, _, _) = run_ours(s.clone(), &y0, RTOL, ATOL);
            let reference =
                forces(&outputs(&s, ComfortPoints::of(&s), T_END, &reference).expect("outputs"));
            let scale = reference.iter().map(|x| x.abs()).fold(1e-30, f64::max);
            let error = |y: &[f64]| {
                let v = forces(&outputs(&s, ComfortPoints::of(&s), T_END, y).expect("outputs"));
                v.iter()
                    .zip(&reference)
                    .map(|(x, r)| (x - r).abs())
                    .fold(0.0, f64::max)
                    / scale
            };
            for rtol in [1e-4, 1e-5, 1e-6, 1e-7] {
                let atol = rtol * 1e-3;
                // Fastest of three runs each (the machine's timings scatter).
                let best = |run: &dyn Fn() -> (Vec<f64>, u64, f64)| {
                    (0..3)
                        .map(|_| run())
                        .min_by(|a, b| a.2.total_cmp(&b.2))
                        .expect("runs")
                };
                let (ours, ours_steps, ours_t) = best(&|| run_ours(s.clone(), &y0, rtol, atol));
                let (cv, cv_steps, cv_t) = best(&|| run_cvode(s.clone(), &y0, rtol, atol));
                println!(
                    "{:<6} {:>7.0e} | {:>9.1e} {:>7} {:>9.1} {:>9.1} | {:>9.1e} {:>7} {:>9.1} {:>9.1}",
                    number,
                    rtol,
                    error(&ours),
                    ours_steps,
                    ours_t / ours_steps as f64 * 1e6,
                    ours_t * 1e3,
                    error(&cv),
                    cv_steps,
                    cv_t / cv_steps as f64 * 1e6,
                    cv_t * 1e3,
                );
            }
        }
        println!(
            "(0.3 s from the static equilibrium at 2000 rpm, atol = rtol × 1e-3, no communication \
             points; error: max. mount-force / steering-wheel difference at the end against our \
             rtol 1e-10 run, relative to the largest value; CVODE with its dense direct solver and \
             finite-difference Jacobian on the same right-hand side)"
        );
    }
}
