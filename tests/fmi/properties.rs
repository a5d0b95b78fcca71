//! Property-based tests of the C ABI (issue 28): random call sequences with random values, and
//! damaged saved states. Whatever a master sends, the FMU answers with a status, never crashes,
//! never writes a non-finite output after a successful step, and a refused call changes nothing
//! that a later call could trip over.

use proptest::prelude::*;

use crate::common::*;
use engine_mount_chassis::fmi2::variables::{real, REALS};

/// A value a careless or hostile master might send.
fn wild_value() -> impl Strategy<Value = f64> {
    prop_oneof![
        3 => -10.0..10.0f64,
        2 => 0.0..7000.0f64,
        1 => Just(f64::NAN),
        1 => Just(f64::INFINITY),
        1 => Just(-f64::INFINITY),
        1 => Just(1e300),
        1 => Just(-1e-300),
        1 => any::<f64>(),
    ]
}

/// One call of a master.
#[derive(Debug, Clone)]
enum Call {
    SetInput { input: usize, value: f64 },
    SetDerivative { input: usize, value: f64 },
    SetUnknownVr { vr: u32, value: f64 },
    DoStep { step: f64 },
    DoStepAtWrongTime { offset: f64 },
    GetAll,
    SaveAndRestore,
    Terminate,
    Reset,
    Initialize,
}

fn call() -> impl Strategy<Value = Call> {
    let input = 0..10usize;
    prop_oneof![
        4 => (input.clone(), wild_value()).prop_map(|(input, value)| Call::SetInput { input, value }),
        2 => (input, wild_value()).prop_map(|(input, value)| Call::SetDerivative { input, value }),
        1 => (any::<u32>(), wild_value()).prop_map(|(vr, value)| Call::SetUnknownVr { vr, value }),
        // Finite steps stay short: a master that asks for 1e300 s gets them integrated.
        4 => prop_oneof![
            Just(1e-3),
            Just(2.5e-4),
            -1e-2..1e-2f64,
            Just(f64::NAN),
            Just(f64::INFINITY),
            Just(0.0),
        ]
        .prop_map(|step| Call::DoStep { step }),
        1 => wild_value().prop_map(|offset| Call::DoStepAtWrongTime { offset }),
        2 => Just(Call::GetAll),
        1 => Just(Call::SaveAndRestore),
        1 => Just(Call::Terminate),
        1 => Just(Call::Reset),
        2 => Just(Call::Initialize),
    ]
}

/// The ten continuous inputs: rpm, load torque, four stiffness and four damping scales.
fn inputs() -> Vec<u32> {
    let mut v = vec![real::RPM, real::LOAD_TORQUE];
    v.extend(real::MOUNT_STIFFNESS_SCALE);
    v.extend(real::MOUNT_DAMPING_SCALE);
    v
}

fn statuses_are_fmi(st: u32) -> bool {
    [OK, WARNING, DISCARD, ERROR].contains(&st)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn random_call_sequences_never_crash_or_write_non_finite_outputs(
        calls in proptest::collection::vec(call(), 1..40)
    ) {
        let fmu = Fmu::load();
        let s = fmu.instantiate("properties");
        let inputs = inputs();
        let outputs: Vec<u32> = REALS.iter()
            .filter(|v| {
                v.causality == engine_mount_chassis::fmi2::variables::Causality::Output
                    && v.fmus & engine_mount_chassis::fmi2::variables::ENGINE_FMU != 0
            })
            .map(|v| v.index)
            .collect();
        let mut time = 0.0;
        let mut running = false;
        for c in calls {
            let st = match c {
                Call::SetInput { input, value } => s.set_real(&[inputs[input]], &[value]),
                Call::SetDerivative { input, value } => {
                    s.set_input_derivatives(&[inputs[input]], &[value])
                }
                Call::SetUnknownVr { vr, value } => {
                    // SAFETY: one value reference and one value.
                    unsafe { (s.f().fmi2SetReal)(s.c, &vr, 1, &value) }
                }
                Call::DoStep { step } => {
                    let st = s.do_step(time, step);
                    if st == OK || st == WARNING {
                        time += step;
                        let values = s.reals(&outputs);
                        prop_assert!(values.iter().all(|x| x.is_finite()), "{values:?}");
                    }
                    if st == DISCARD {
                        running = false;
                    }
                    st
                }
                Call::DoStepAtWrongTime { offset } => {
                    let st = s.do_step(time + offset.abs().max(1e-3), 1e-3);
                    prop_assert_ne!(st, OK);
                    st
                }
                Call::GetAll => s.get_real(&outputs).0,
                Call::SaveAndRestore => {
                    let state = s.get_state();
                    if state.is_null() {
                        ERROR
                    } else {
                        let st = s.set_state(state);
                        s.free_state(state);
                        st
                    }
                }
                Call::Terminate => {
                    running = false;
                    s.terminate()
                }
                Call::Reset => {
                    running = false;
                    time = 0.0;
                    s.reset()
                }
                Call::Initialize => {
                    if running {
                        continue;
                    }
                    let a = s.setup(0.0, None);
                    let b = s.enter_init();
                    let c = s.exit_init();
                    time = 0.0;
                    running = c == OK;
                    [a, b, c].into_iter().max().unwrap_or(OK)
                }
            };
            prop_assert!(statuses_are_fmi(st), "status {st}");
        }
    }

    /// Damaged states: random bytes, and valid states with bytes changed and the checksum made
    /// valid again (as a forger would). Refused with an error, or, if accepted, a state that
    /// steps like any other.
    #[test]
    fn damaged_states_are_refused_or_harmless(
        changes in proptest::collection::vec((any::<prop::sample::Index>(), any::<u8>()), 1..6),
        junk in proptest::collection::vec(any::<u8>(), 0..300),
    ) {
        let fmu = Fmu::load();
        let s = fmu.instantiate("damaged-states");
        s.initialize();
        prop_assert_eq!(s.do_step(0.0, 1e-3), OK);
        let state = s.get_state();
        let mut bytes = s.serialize(state);
        s.free_state(state);
        let (st, handle) = s.deserialize(&junk);
        prop_assert_eq!(st, ERROR);
        prop_assert!(handle.is_null());
        let body = 9..bytes.len() - 32;
        for (at, byte) in changes {
            let i = body.start + at.index(body.len());
            bytes[i] = byte;
        }
        crate::bad_inputs::reseal(&mut bytes);
        let (st, handle) = s.deserialize(&bytes);
        prop_assert!(st == OK || st == ERROR, "status {st}");
        if st == OK {
            prop_assert!(!handle.is_null());
            let set = s.set_state(handle);
            prop_assert!(set == OK || set == ERROR);
            if set == OK {
                let t = s.real_status(fmi_sys::fmi2::fmi2StatusKind_fmi2LastSuccessfulTime).1;
                let step = s.do_step(t, 1e-3);
                prop_assert!(statuses_are_fmi(step));
            }
            s.free_state(handle);
        }
    }
}
