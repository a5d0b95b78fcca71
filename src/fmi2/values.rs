//! FMI 2.0 value references: each type's variables are numbered from its base in
//! [`crate::variables::VR_BASE`], so a value reference is a position among the variables
//! of its type.

use crate::fmu::values::{Slot, VarType};
use crate::variables::VR_BASE;

/// The positions of the variables of type `T` behind the master's value references; one of
/// another type, or of no variable, is refused.
pub fn slots<T: VarType>(vrs: &[u32]) -> Result<Vec<Slot>, String> {
    indices::<T>(vrs).map(|i| i.into_iter().map(Slot::Element).collect())
}

/// The indices among the variables of type `T` behind the master's value references.
pub fn indices<T: VarType>(vrs: &[u32]) -> Result<Vec<usize>, String> {
    let base = VR_BASE[T::TYPE_INDEX];
    vrs.iter()
        .map(|&vr| {
            vr.checked_sub(base)
                .map(|i| i as usize)
                .filter(|i| *i < T::table().len())
                .ok_or_else(|| {
                    format!(
                        "unknown value reference {vr} (not a {} variable of this FMU)",
                        T::NAME
                    )
                })
        })
        .collect()
}

/// The Real knowns of a directional derivative (indices among the Reals) with their seeds, for
/// the FMU with variable bit `fmu`. FMI 2.0 defines the derivative with respect to Real knowns
/// only (§2.1.9: the others are among `v_rest`), yet a host that passes an unknown's whole
/// `dependencies` list (OMSimulator) names this FMU's Integer and String parameters too, each
/// seeded 0. Such a known adds nothing to `Σ ∂unknown/∂known · seed`, so with a zero seed it is
/// left out; with any other seed it is refused. Value references are unique across types here,
/// so a non-Real one is recognised for what it is; one of no variable of this FMU is refused.
pub fn real_knowns(vrs: &[u32], seeds: &[f64], fmu: u8) -> Result<(Vec<usize>, Vec<f64>), String> {
    let mut knowns = Vec::with_capacity(vrs.len());
    let mut kept = Vec::with_capacity(vrs.len());
    for (&vr, &seed) in vrs.iter().zip(seeds) {
        if let Ok(i) = indices::<f64>(&[vr]) {
            knowns.push(i[0]);
            kept.push(seed);
            continue;
        }
        let Some(name) = other_type(vr, fmu) else {
            return Err(format!(
                "unknown value reference {vr} (no variable of this FMU)"
            ));
        };
        if seed != 0.0 {
            return Err(format!(
                "{name} is not a Real: directional derivatives are with respect to Real knowns \
                 (FMI 2.0 section 2.1.9); give it a zero seed or leave it out"
            ));
        }
    }
    Ok((knowns, kept))
}

/// The name of this FMU's Integer, Boolean or String variable behind `vr`, if there is one.
fn other_type(vr: u32, fmu: u8) -> Option<&'static str> {
    fn find<T: VarType>(vr: u32, fmu: u8) -> Option<&'static str> {
        let i = indices::<T>(&[vr]).ok()?[0];
        let v = &T::table()[i];
        (v.fmus & fmu != 0).then_some(v.name)
    }
    find::<i32>(vr, fmu)
        .or_else(|| find::<bool>(vr, fmu))
        .or_else(|| find::<String>(vr, fmu))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::variables::{integer, real, INTEGERS, REALS};

    #[test]
    fn value_references_map_to_their_own_type_only() {
        let rpm = REALS[real::RPM as usize].vr;
        let scene = INTEGERS[integer::SCENE as usize].vr;
        assert_eq!(indices::<f64>(&[rpm]).unwrap(), vec![real::RPM as usize]);
        assert_eq!(
            indices::<i32>(&[scene]).unwrap(),
            vec![integer::SCENE as usize]
        );
        let err = indices::<f64>(&[scene]).unwrap_err();
        assert!(err.contains(&format!("{scene} (not a Real")), "{err}");
        assert!(indices::<bool>(&[scene]).is_err());
        assert!(indices::<String>(&[u32::MAX]).is_err());
    }

    #[test]
    fn a_non_real_known_is_dropped_with_a_zero_seed_and_refused_with_another() {
        use crate::variables::{string, ENGINE_FMU, STRINGS};
        let rpm = REALS[real::RPM as usize].vr;
        let scene = INTEGERS[integer::SCENE as usize].vr;
        let config = STRINGS[string::CONFIG_FILE as usize].vr;
        let (knowns, seeds) =
            real_knowns(&[scene, rpm, config], &[0.0, 2.0, 0.0], ENGINE_FMU).unwrap();
        assert_eq!(knowns, vec![real::RPM as usize]);
        assert_eq!(seeds, vec![2.0]);
        let err = real_knowns(&[scene], &[1.0], ENGINE_FMU).unwrap_err();
        assert!(err.contains("scene is not a Real"), "{err}");
        let err = real_knowns(&[u32::MAX], &[0.0], ENGINE_FMU).unwrap_err();
        assert!(err.contains("no variable of this FMU"), "{err}");
    }
}
