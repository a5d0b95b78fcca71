//! FMI 3.0 value references resolved to the runtime's variable table: an array variable
//! (`mount.F`, `mode.frequency`, …) stands for its elements, row-major, each a scalar variable
//! of the table (the 2.0 variables), so both ABIs read and write the same stores.

use crate::fmu::values::{Slot, VarType};
use crate::variables::fmi3::{MODES_SIZE, TIME, VARIABLES};
use crate::variables::ArrayVariable;

/// The 3.0 variable with value reference `vr`, if it has 2.0 elements.
pub fn variable(vr: u32) -> Option<&'static ArrayVariable> {
    VARIABLES.iter().find(|v| v.vr == vr)
}

/// The 3.0 type name of a 2.0 type index.
fn type_name(type_index: usize) -> &'static str {
    ["Float64", "Int32", "Boolean", "String"][type_index]
}

/// The slots of the values behind `vrs` for a get or set of type `T`, `modes_size` elements of
/// the natural-mode arrays; an unknown value reference or one of another type is refused, and
/// so is a value count that does not match the variables' elements.
pub fn resolve<T: VarType>(
    vrs: &[u32],
    modes_size: u64,
    n_values: usize,
) -> Result<Vec<Slot>, String> {
    let mut slots = Vec::with_capacity(n_values);
    for &vr in vrs {
        if vr == TIME && T::TYPE_INDEX == 0 {
            slots.push(Slot::Time);
            continue;
        }
        let Some(v) = variable(vr).filter(|v| v.type_index == T::TYPE_INDEX) else {
            return Err(unknown(vr, type_name(T::TYPE_INDEX)));
        };
        let n = if v.sized_by_modes {
            (modes_size as usize).min(v.indices.len())
        } else {
            v.indices.len()
        };
        slots.extend(v.indices[..n].iter().map(|&i| Slot::Element(i as usize)));
    }
    if slots.len() != n_values {
        return Err(format!(
            "nValues = {n_values}, but the {} value references have {} elements",
            vrs.len(),
            slots.len()
        ));
    }
    Ok(slots)
}

/// The refusal of a value reference that is not a variable of type `ty`.
pub fn unknown(vr: u32, ty: &str) -> String {
    let what = if vr == MODES_SIZE {
        "modes.size is a UInt64".to_owned()
    } else if vr == TIME {
        "time is a Float64".to_owned()
    } else if let Some(v) = variable(vr) {
        format!("{} is a {}", v.name, type_name(v.type_index))
    } else {
        "no variable has it".to_owned()
    };
    format!("value reference {vr} is not a {ty} variable of this FMU ({what})")
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::variables::{fmi3::MODES_SIZE_MAX, real, REALS};

    #[test]
    fn arrays_resolve_row_major_to_the_2_0_elements() {
        let f = variable(real::MOUNT_F[0][0]).expect("mount.F");
        assert_eq!(f.name, "mount.F");
        assert_eq!(f.dims, &[4, 3]);
        let slots = resolve::<f64>(&[f.vr], MODES_SIZE_MAX, 12).unwrap();
        for (k, s) in slots.iter().enumerate() {
            let (i, j) = (k / 3, k % 3);
            assert_eq!(*s, Slot::Element(real::MOUNT_F[i][j] as usize));
            assert_eq!(
                REALS[real::MOUNT_F[i][j] as usize].name,
                format!("mount[{}].F[{}]", i + 1, j + 1)
            );
        }
    }

    #[test]
    fn mode_arrays_follow_modes_size_and_counts_must_match() {
        let vr = real::MODE_FREQUENCY[0];
        assert_eq!(resolve::<f64>(&[vr], 5, 5).unwrap().len(), 5);
        assert!(resolve::<f64>(&[vr], 5, 6).is_err());
        assert!(resolve::<i32>(&[vr], 5, 5).is_err());
        assert_eq!(
            resolve::<f64>(&[TIME, real::RPM], 5, 2).unwrap()[0],
            Slot::Time
        );
        assert!(resolve::<f64>(&[MODES_SIZE], 5, 1)
            .unwrap_err()
            .contains("UInt64"));
    }
}
