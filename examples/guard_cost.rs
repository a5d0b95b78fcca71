//! What the one-call-at-a-time guard costs a master: the time of the cheapest entry point
//! (`fmi2GetRealStatus`, the guard and almost nothing else), of the busy flag alone (the atomic
//! exchange and release each call now makes), and of one communication step with its outputs
//! (`fmi2DoStep` + `fmi2GetReal`, 1 ms at 2000 rpm) in scenes 1 and 2; the flag's share of a
//! step is the number to hold against the run-to-run scatter of the `realtime` example.
//!
//! `cargo run --release --example guard_cost -- [--repeat N]`

use std::ffi::CString;
use std::hint::black_box;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

use engine_mount_chassis::fmi2::abi::*;
use engine_mount_chassis::variables::{integer, real, GUID, INTEGERS, REALS};
use fmi_sys::fmi2::*;

/// Seconds per call of `f`: the fastest of five runs of `calls` calls.
fn per_call(calls: usize, mut f: impl FnMut()) -> f64 {
    (0..5)
        .map(|_| {
            let start = Instant::now();
            for _ in 0..calls {
                f();
            }
            start.elapsed().as_secs_f64() / calls as f64
        })
        .fold(f64::INFINITY, f64::min)
}

fn instance(scene: i32) -> fmi2Component {
    let name = CString::new("guard-cost").unwrap();
    let guid = CString::new(GUID).unwrap();
    let callbacks = Box::leak(Box::new(fmi2CallbackFunctions {
        logger: None,
        allocateMemory: None,
        freeMemory: None,
        stepFinished: None,
        componentEnvironment: std::ptr::null_mut(),
    }));
    let c = fmi2Instantiate(
        name.as_ptr(),
        fmi2Type_fmi2CoSimulation,
        guid.as_ptr(),
        std::ptr::null(),
        callbacks,
        0,
        0,
    );
    assert!(!c.is_null());
    let ok = |s| assert_eq!(s, fmi2Status_fmi2OK);
    ok(fmi2SetupExperiment(c, 0, 0.0, 0.0, 0, 0.0));
    ok(fmi2SetInteger(
        c,
        &INTEGERS[integer::SCENE as usize].vr,
        1,
        &scene,
    ));
    ok(fmi2SetReal(c, &REALS[real::RPM as usize].vr, 1, &2000.0));
    ok(fmi2EnterInitializationMode(c));
    ok(fmi2ExitInitializationMode(c));
    c
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let repeat = args
        .iter()
        .position(|a| a == "--repeat")
        .and_then(|i| args.get(i + 1)?.parse().ok())
        .unwrap_or(3);
    println!("| repeat | busy flag alone (ns) | fmi2GetRealStatus (ns) | scene 1 step (µs) | scene 2 step (µs) | flag / scene-1 step | flag / scene-2 step |");
    println!("|---:|---:|---:|---:|---:|---:|---:|");
    let flag = AtomicBool::new(false);
    let outputs: Vec<u32> = real::MOUNT_F
        .iter()
        .flatten()
        .chain(&real::STEERING_WHEEL_A)
        .map(|&i| REALS[i as usize].vr)
        .collect();
    for r in 1..=repeat {
        let busy = per_call(10_000_000, || {
            let taken = flag
                .compare_exchange(false, true, Ordering::Acquire, Ordering::Relaxed)
                .is_ok();
            black_box(taken);
            flag.store(false, Ordering::Release);
        });
        let c = instance(1);
        let mut t = 0.0;
        let status = per_call(2_000_000, || {
            let mut last = 0.0;
            black_box(fmi2GetRealStatus(
                c,
                fmi2StatusKind_fmi2LastSuccessfulTime,
                &mut last,
            ));
        });
        let mut values = vec![0.0; outputs.len()];
        let mut step = |c: fmi2Component, t: &mut f64| {
            fmi2DoStep(c, *t, 1e-3, 1);
            *t += 1e-3;
            fmi2GetReal(c, outputs.as_ptr(), outputs.len(), values.as_mut_ptr());
        };
        let scene1 = per_call(2_000, || step(c, &mut t));
        fmi2FreeInstance(c);
        let c = instance(2);
        let mut t = 0.0;
        let scene2 = per_call(500, || step(c, &mut t));
        fmi2FreeInstance(c);
        println!(
            "| {r} | {:.1} | {:.1} | {:.1} | {:.1} | {:.1e} | {:.1e} |",
            busy * 1e9,
            status * 1e9,
            scene1 * 1e6,
            scene2 * 1e6,
            2.0 * busy / scene1,
            2.0 * busy / scene2
        );
    }
    println!("A step makes two guarded calls (fmi2DoStep, fmi2GetReal): its share is twice the flag's cost over the step's.");
}
