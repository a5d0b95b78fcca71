//! `<ModelStructure>` says what really depends on what: in scenes 1 and 2 outputs change only in
//! `fmi2DoStep` (the only direct feedthrough is from the external body's motion, scene 3, see
//! `coupling.rs`), every initial unknown's declared dependencies include each input that
//! changes it and only knowns the standard allows, and a host that differentiates the initial
//! unknowns with their whole dependency list gets the derivatives of the initialisation.

use crate::common::*;
use engine_mount_chassis::fmi2::variables::Causality;
use engine_mount_chassis::fmi2::variables::{real, ENGINE_FMU, REALS};
use engine_mount_chassis::fmi2::{BODY_MODEL_DESCRIPTION_XML, MODEL_DESCRIPTION_XML};

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

/// `(causality, value reference)` of each ScalarVariable of `xml`, in index order (the
/// `<ModelStructure>` indices are 1-based positions in this list).
fn scalar_variables(xml: &str) -> Vec<(String, u32)> {
    xml.lines()
        .filter(|l| l.contains("<ScalarVariable"))
        .map(|l| {
            let causality = l
                .split("causality=\"")
                .nth(1)
                .and_then(|r| r.split('"').next())
                .unwrap_or("local")
                .to_owned();
            (causality, value_reference(l))
        })
        .collect()
}

/// The `dependencies` indices of the unknown with index `index` in section `list` of `xml`.
fn dependencies_of(xml: &str, list: &str, index: usize) -> Vec<usize> {
    let section = xml
        .split(&format!("<{list}>"))
        .nth(1)
        .and_then(|r| r.split(&format!("</{list}>")).next())
        .expect("section");
    let line = section
        .lines()
        .find(|l| l.contains(&format!(r#"index="{index}""#)))
        .expect("the unknown is listed");
    line.split("dependencies=\"")
        .nth(1)
        .and_then(|r| r.split('"').next())
        .expect("dependencies are declared")
        .split_whitespace()
        .map(|d| d.parse().unwrap())
        .collect()
}

/// FMI 2.0 §2.2.8: the knowns an `<Outputs>` unknown may depend on at a communication point are
/// the inputs (no continuous states are exposed, time is implicit); those of an
/// `<InitialUnknowns>` unknown, the inputs and the variables with `initial="exact"` — here the
/// parameters (no `initial` attribute: exact by default), of any type, as the standard's own
/// example lists "any type of input" among them.
#[test]
fn dependencies_list_only_the_knowns_the_standard_allows() {
    for xml in [MODEL_DESCRIPTION_XML, BODY_MODEL_DESCRIPTION_XML] {
        let variables = scalar_variables(xml);
        for (list, allowed) in [
            ("Outputs", &["input"][..]),
            ("InitialUnknowns", &["input", "parameter"][..]),
        ] {
            for (index, (causality, _)) in variables.iter().enumerate() {
                let listed = matches!(causality.as_str(), "output")
                    || (list == "InitialUnknowns" && causality == "calculatedParameter");
                if !listed {
                    continue;
                }
                for d in dependencies_of(xml, list, index + 1) {
                    let known = &variables[d - 1].0;
                    assert!(
                        allowed.contains(&known.as_str()),
                        "{list}: unknown {} depends on index {d}, a {known}",
                        index + 1
                    );
                }
            }
        }
    }
}

/// Central difference of `outputs` with respect to input `input` at its current value, by
/// setting the input: in initialisation mode each value re-solves the initialisation.
fn central_difference(s: &Slave, outputs: &[u32], input: u32, h: f64) -> Vec<f64> {
    let x = s.reals(&[input])[0];
    assert_eq!(s.set_real(&[input], &[x + h]), OK);
    let plus = s.reals(outputs);
    assert_eq!(s.set_real(&[input], &[x - h]), OK);
    let minus = s.reals(outputs);
    assert_eq!(s.set_real(&[input], &[x]), OK);
    plus.iter()
        .zip(&minus)
        .map(|(p, m)| (p - m) / (2.0 * h))
        .collect()
}

/// What a host solving the engine–body loop during initialisation asks (OMSimulator does): the
/// derivative of initial unknowns with respect to one interface input, passing an unknown's
/// whole `<InitialUnknowns>` dependency list — Integer, String and Real parameters among it —
/// with the seed on the one input and zero on the others. Answered, and right: against the
/// host's own central difference of the initialisation, and against the static equilibrium,
/// where the mount forces shift between the mounts but keep their sum (the engine's weight and
/// the load), whatever the body does.
#[test]
fn initial_unknowns_have_directional_derivatives_with_the_whole_dependency_list() {
    let fmu = Fmu::load();
    let s = fmu.instantiate("initial-derivatives");
    assert_eq!(s.setup(0.0, None), OK);
    assert_eq!(s.enter_init(), OK);
    let scene = value_references(1, &[integer::SCENE])[0];
    assert_eq!(s.set_integer(&[integer::SCENE], &[3]), OK, "{:?}", s.logs());
    let forces: Vec<u32> = real::MOUNT_F.iter().flatten().copied().collect();
    let variables = scalar_variables(MODEL_DESCRIPTION_XML);
    let f13 = variables
        .iter()
        .position(|(_, vr)| *vr == real::MOUNT_F[0][2])
        .unwrap();
    let knowns: Vec<u32> = dependencies_of(MODEL_DESCRIPTION_XML, "InitialUnknowns", f13 + 1)
        .iter()
        .map(|&d| variables[d - 1].1)
        .collect();
    let config = value_references(3, &[string::CONFIG_FILE])[0];
    assert!(
        knowns.contains(&scene)
            && knowns.contains(&config)
            && knowns.contains(&real::SOLVER_REL_TOL)
    );
    for (input, h) in [
        (real::MOUNT_BODY_R[0][2], 1e-6),
        (real::MOUNT_BODY_R[2][0], 1e-6),
        (real::MOUNT_BODY_V[1][2], 1e-5),
    ] {
        let seeds: Vec<f64> = knowns.iter().map(|&k| f64::from(k == input)).collect();
        let (status, derivative) = s.directional_derivative(&forces, &knowns, &seeds);
        assert_eq!(status, OK, "{:?}", s.logs());
        let difference = central_difference(&s, &forces, input, h);
        let scale = derivative.iter().fold(1.0f64, |m, x| m.max(x.abs()));
        assert!(scale > 10.0, "{derivative:?}");
        for (d, c) in derivative.iter().zip(&difference) {
            assert!(
                (d - c).abs() <= 1e-5 * scale,
                "{d:e} vs central difference {c:e}"
            );
        }
        for axis in 0..3 {
            let sum: f64 = (0..4).map(|i| derivative[3 * i + axis]).sum();
            assert!(
                sum.abs() <= 1e-5 * scale,
                "axis {axis}: forces change their sum by {sum:e}"
            );
        }
    }
    // A seed on a non-Real or a parameter asks for what is not provided: refused, naming it.
    let (status, _) = s.directional_derivative(&forces, &[scene], &[1.0]);
    assert_eq!(status, ERROR);
    assert!(
        s.logs().iter().any(|l| l.contains("scene is not a Real")),
        "{:?}",
        s.logs()
    );
    let (status, _) = s.directional_derivative(&forces, &[real::SOLVER_REL_TOL], &[1.0]);
    assert_eq!(status, ERROR);
    // A value reference of no variable stays refused, whatever its seed.
    let (status, _) = s.directional_derivative(&forces, &[u32::MAX], &[0.0]);
    assert_eq!(status, ERROR);
    // Between steps the whole list is accepted as well; the zero seeds change nothing.
    assert_eq!(s.exit_init(), OK, "{:?}", s.logs());
    assert_eq!(s.do_step(0.0, 1e-3), OK);
    let input = real::MOUNT_BODY_R[0][2];
    let seeds: Vec<f64> = knowns.iter().map(|&k| f64::from(k == input)).collect();
    let (status, listed) = s.directional_derivative(&forces, &knowns, &seeds);
    assert_eq!(status, OK, "{:?}", s.logs());
    let (_, alone) = s.directional_derivative(&forces, &[input], &[1.0]);
    assert_eq!(listed, alone);
}

/// The body FMU's initial mount displacements are its static deflection under the mount forces:
/// the derivatives a host gets in initialisation mode form the body's compliance at the mounts,
/// symmetric as Maxwell–Betti reciprocity requires of a linear elastic body.
#[test]
fn the_body_initial_derivatives_are_a_symmetric_compliance() {
    use engine_mount_chassis::fmi2::variables::BODY_GUID;
    let fmu = Fmu::load();
    let s = fmu
        .instantiate_with("initial-compliance", BODY_GUID, Some(&resources_uri()))
        .expect("the body FMU");
    assert_eq!(s.setup(0.0, None), OK);
    assert_eq!(s.enter_init(), OK);
    let forces: Vec<u32> = real::BODY_MOUNT_F.iter().flatten().copied().collect();
    let weight: Vec<f64> = (0..12)
        .map(|k| if k % 3 == 2 { -400.0 } else { 0.0 })
        .collect();
    assert_eq!(s.set_real(&forces, &weight), OK);
    let displacements: Vec<u32> = real::BODY_MOUNT_R.iter().flatten().copied().collect();
    let compliance: Vec<Vec<f64>> = forces
        .iter()
        .map(|&f| {
            let (status, column) = s.directional_derivative(&displacements, &[f], &[1.0]);
            assert_eq!(status, OK, "{:?}", s.logs());
            column
        })
        .collect();
    let largest = compliance
        .iter()
        .flatten()
        .fold(0.0f64, |m, x| m.max(x.abs()));
    assert!(largest > 1e-7, "{largest:e} m/N");
    for (i, column) in compliance.iter().enumerate() {
        assert!(column[i] > 0.0, "a force moves its own point along it");
        for (j, c) in column.iter().enumerate() {
            let mirror = compliance[j][i];
            assert!(
                (c - mirror).abs() <= 1e-6 * largest,
                "C[{i}][{j}] = {c:e}, C[{j}][{i}] = {mirror:e}"
            );
        }
    }
}
