//! `<ModelStructure>` says what really depends on what: in scenes 1 and 2 outputs change only in
//! `fmi2DoStep` (the only direct feedthrough is from the external body's motion, scene 3, see
//! `coupling.rs`), and every initial unknown's declared dependencies include each input that
//! changes it.

use crate::common::*;
use engine_mount_chassis::fmi2::variables::Causality;
use engine_mount_chassis::fmi2::variables::{real, ENGINE_FMU, REALS};
use engine_mount_chassis::fmi2::MODEL_DESCRIPTION_XML;

/// Value references of the Real inputs and outputs.
fn inputs_and_outputs() -> (Vec<u32>, Vec<u32>) {
    let pick = |c: Causality| {
        REALS
            .iter()
            .filter(|v| v.causality == c && v.fmus & ENGINE_FMU != 0)
            .map(|v| v.vr)
            .collect()
    };
    (pick(Causality::Input), pick(Causality::Output))
}

/// A valid value different from the start value of input `vr`.
fn other_value(vr: u32) -> f64 {
    if vr == real::RPM {
        2500.0
    } else if vr == real::LOAD_TORQUE {
        150.0
    } else {
        0.7
    }
}

#[test]
fn outputs_do_not_change_when_an_input_is_set_without_a_step() {
    let fmu = Fmu::load();
    let (inputs, outputs) = inputs_and_outputs();
    let s = fmu.instantiate("feedthrough");
    s.initialize();
    for k in 0..5 {
        assert_eq!(s.do_step(k as f64 * 1e-3, 1e-3), OK);
    }
    for &input in &inputs {
        let before = s.reals(&outputs);
        // A body-point input in scene 1 is answered with a warning (once): the scene ignores it.
        let status = s.set_real(&[input], &[other_value(input)]);
        assert!(status == OK || status == WARNING, "{status}");
        assert_eq!(s.reals(&outputs), before, "input {input} fed through");
    }
    // and the XML says so: an output declares direct dependencies on the external body's
    // interface inputs only
    let section = MODEL_DESCRIPTION_XML
        .split("<Outputs>")
        .nth(1)
        .and_then(|r| r.split("</Outputs>").next())
        .expect("Outputs section");
    let unknowns: Vec<&str> = section.lines().filter(|l| l.contains("<Unknown")).collect();
    assert!(unknowns.len() >= outputs.len(), "{unknowns:?}");
    let index = real_index();
    let interface: Vec<usize> = real::MOUNT_BODY_R
        .iter()
        .chain(&real::MOUNT_BODY_V)
        .flatten()
        .map(|vr| index[vr])
        .collect();
    for line in unknowns {
        let deps = line
            .split("dependencies=\"")
            .nth(1)
            .and_then(|r| r.split('"').next())
            .unwrap_or("");
        for d in deps.split_whitespace() {
            let d: usize = d.parse().unwrap();
            assert!(
                interface.contains(&d),
                "{line} depends on {d}, not an interface input"
            );
        }
    }
}

/// The value reference of a `<ScalarVariable` line of the XML.
fn value_reference(line: &str) -> u32 {
    line.split("valueReference=\"")
        .nth(1)
        .and_then(|r| r.split('"').next())
        .and_then(|v| v.parse().ok())
        .expect("valueReference")
}

/// Index (1-based, as in `<ModelStructure>`) of each ScalarVariable by value reference, Reals.
fn real_index() -> std::collections::BTreeMap<u32, usize> {
    let mut map = std::collections::BTreeMap::new();
    let mut index = 0;
    for line in MODEL_DESCRIPTION_XML.lines() {
        if line.contains("<ScalarVariable") {
            index += 1;
            map.entry(value_reference(line)).or_insert(index);
        }
    }
    map
}

#[test]
fn initial_unknowns_declare_the_inputs_they_depend_on() {
    let fmu = Fmu::load();
    let (inputs, outputs) = inputs_and_outputs();
    let index = real_index();
    let initial = |changed: Option<u32>| {
        let s = fmu.instantiate("initial");
        if let Some(vr) = changed {
            assert_eq!(s.set_real(&[vr], &[other_value(vr)]), OK);
        }
        assert_eq!(s.setup(0.0, None), OK);
        assert_eq!(s.enter_init(), OK);
        // A body-point input in scene 1 is answered with a warning: the scene ignores it.
        let status = s.exit_init();
        assert!(status == OK || status == WARNING, "{:?}", s.logs());
        s.reals(&outputs)
    };
    let base = initial(None);
    let section = MODEL_DESCRIPTION_XML
        .split("<InitialUnknowns>")
        .nth(1)
        .and_then(|r| r.split("</InitialUnknowns>").next())
        .expect("InitialUnknowns section");
    for &input in &inputs {
        let changed = initial(Some(input));
        for (k, &out) in outputs.iter().enumerate() {
            if changed[k] != base[k] {
                let line = section
                    .lines()
                    .find(|l| l.contains(&format!(r#"index="{}""#, index[&out])))
                    .expect("the output is an initial unknown");
                // no attribute: depends on all knowns; else the input's index must be listed
                if let Some(deps) = line.split("dependencies=\"").nth(1) {
                    let deps: Vec<usize> = deps
                        .split('"')
                        .next()
                        .unwrap_or("")
                        .split_whitespace()
                        .map(|d| d.parse().unwrap())
                        .collect();
                    assert!(
                        deps.contains(&index[&input]),
                        "initial output {out} depends on input {input} but declares {deps:?}"
                    );
                }
            }
        }
    }
}

#[test]
fn value_references_are_unique_across_types() {
    let mut seen = std::collections::BTreeSet::new();
    for line in MODEL_DESCRIPTION_XML
        .lines()
        .filter(|l| l.contains("<ScalarVariable"))
    {
        let vr = value_reference(line);
        assert!(seen.insert(vr), "value reference {vr} used twice");
    }
    assert!(seen.len() > 50, "{} variables", seen.len());
}
