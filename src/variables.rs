//! The variable table, generated from `modelDescription/variables.json` by `build.rs`.
//!
//! A leaf: it knows the FMU's variables and nothing of the model. Each variable of type `T` sits at
//! its `index` in the per-type arrays [`REALS`], [`INTEGERS`], [`BOOLEANS`] and [`STRINGS`]; the
//! constants in [`real`], [`integer`], [`boolean`] and [`string`] are these indices. Its value
//! reference `vr` is the index plus its type's [`VR_BASE`] (unique across types).
//!
//! One table serves both FMUs of the library, the engine FMU and the body FMU: a variable's
//! [`Variable::fmus`] says which model descriptions list it; value references are the same in
//! both.

/// Bit of [`Variable::fmus`]: the engine FMU (`EngineMountChassis`) has the variable.
pub const ENGINE_FMU: u8 = 1;
/// Bit of [`Variable::fmus`]: the body FMU (`EngineMountBody`) has the variable.
pub const BODY_FMU: u8 = 2;

/// FMI causality of a variable.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Causality {
    /// Set by the master between steps (`rpm`, `loadTorque`, the mount scales).
    Input,
    /// Computed by the model at each communication point.
    Output,
    /// Set by the master before initialisation ends; the model is built from the parameters.
    Parameter,
    /// Computed from the parameters at initialisation (the natural modes).
    CalculatedParameter,
    /// Internal; not used by this FMU's variables.
    Local,
}

/// FMI variability of a variable.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Variability {
    /// Never changes.
    Constant,
    /// Fixed after initialisation.
    Fixed,
    /// May change between steps (no tunable variable exists in this FMU).
    Tunable,
    /// Changes only at communication points (the solver counters).
    Discrete,
    /// Changes continuously in time (inputs and physical outputs).
    Continuous,
}

/// One scalar variable of the model description.
#[derive(Debug, Clone, Copy)]
pub struct Variable<T: 'static> {
    /// FMI name, e.g. `mount[2].F[3]`.
    pub name: &'static str,
    /// Value reference in `modelDescription.xml`.
    pub vr: u32,
    /// Position among the variables of its type.
    pub index: u32,
    /// The FMUs whose model description has the variable ([`ENGINE_FMU`], [`BODY_FMU`] bits).
    pub fmus: u8,
    /// Who sets the variable and when.
    pub causality: Causality,
    /// When the variable can change.
    pub variability: Variability,
    /// Start value (the value after instantiation and reset).
    pub start: T,
    /// Lower bound of a Real or Integer (values below are refused).
    pub min: Option<T>,
    /// Upper bound of a Real or Integer (values above are refused).
    pub max: Option<T>,
}

include!(concat!(env!("OUT_DIR"), "/variables.rs"));

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn value_references_are_indices_over_their_type_base() {
        fn check<T>(table: &[Variable<T>], base: u32) {
            for (i, v) in table.iter().enumerate() {
                assert_eq!(v.index as usize, i, "{}", v.name);
                assert_eq!(v.vr, base + v.index, "{}", v.name);
            }
        }
        check(REALS, VR_BASE[0]);
        check(INTEGERS, VR_BASE[1]);
        check(BOOLEANS, VR_BASE[2]);
        check(STRINGS, VR_BASE[3]);
    }

    #[test]
    fn log_categories_are_named_by_the_table() {
        assert_eq!(LogCategory::ALL.len(), LOG_CATEGORIES.len());
        for (c, name) in LogCategory::ALL.iter().zip(LOG_CATEGORIES) {
            assert_eq!(c.name(), *name);
        }
    }

    #[test]
    fn parameters_read_their_own_value_references() {
        // Every parameter field changed through its value reference shows up in the structure.
        let defaults = Parameters::default();
        let mut reals: Vec<f64> = REALS.iter().map(|v| v.start).collect();
        reals[real::SOLVER_REL_TOL as usize] = 3e-4;
        let mut integers: Vec<i32> = INTEGERS.iter().map(|v| v.start).collect();
        integers[integer::SCENE as usize] = 2;
        let mut booleans: Vec<bool> = BOOLEANS.iter().map(|v| v.start).collect();
        booleans[boolean::CHASSIS_STIFFENING_BAR as usize] = true;
        let mut strings: Vec<&str> = STRINGS.iter().map(|v| v.start).collect();
        strings[string::CHASSIS_CACHE_DIR as usize] = "/tmp/x";
        let p = Parameters::from_values(&reals, &integers, &booleans, &strings);
        assert_eq!(p.solver_rel_tol, 3e-4);
        assert_eq!(p.scene, 2);
        assert!(p.chassis_stiffening_bar && !defaults.chassis_stiffening_bar);
        assert_eq!(p.chassis_cache_dir, "/tmp/x");
        assert_eq!(
            Parameters {
                solver_rel_tol: 3e-4,
                scene: 2,
                chassis_stiffening_bar: true,
                chassis_cache_dir: "/tmp/x".into(),
                ..defaults
            },
            p
        );
    }
}
