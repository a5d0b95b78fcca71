//! The variable table, generated from `modelDescription/variables.json` by `build.rs`.
//!
//! Value references are indices into the per-type arrays [`REALS`], [`INTEGERS`], [`BOOLEANS`]
//! and [`STRINGS`]; the constants in [`real`], [`integer`], [`boolean`] and [`string`] name them.

/// FMI causality of a variable.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Causality {
    Input,
    Output,
    Parameter,
    CalculatedParameter,
    Local,
}

/// FMI variability of a variable.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Variability {
    Constant,
    Fixed,
    Tunable,
    Discrete,
    Continuous,
}

/// One scalar variable of the model description.
#[derive(Debug, Clone, Copy)]
pub struct Variable<T: 'static> {
    pub name: &'static str,
    pub vr: u32,
    pub causality: Causality,
    pub variability: Variability,
    pub start: T,
    pub min: Option<T>,
    pub max: Option<T>,
}

include!(concat!(env!("OUT_DIR"), "/variables.rs"));

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn value_references_are_indices() {
        for (i, v) in REALS.iter().enumerate() {
            assert_eq!(v.vr as usize, i, "{}", v.name);
        }
        for (i, v) in INTEGERS.iter().enumerate() {
            assert_eq!(v.vr as usize, i, "{}", v.name);
        }
        for (i, v) in BOOLEANS.iter().enumerate() {
            assert_eq!(v.vr as usize, i, "{}", v.name);
        }
        for (i, v) in STRINGS.iter().enumerate() {
            assert_eq!(v.vr as usize, i, "{}", v.name);
        }
    }

    #[test]
    fn xml_and_table_agree() {
        let xml = super::super::MODEL_DESCRIPTION_XML;
        assert!(xml.contains(GUID));
        for v in REALS {
            let needle = format!("name=\"{}\" valueReference=\"{}\"", v.name, v.vr);
            assert!(xml.contains(&needle), "{needle}");
        }
        assert_eq!(REALS[real::MOUNT_F[1][2] as usize].name, "mount[2].F[3]");
        assert_eq!(REALS[real::RPM as usize].name, "rpm");
    }
}
