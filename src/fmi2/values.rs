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
}
