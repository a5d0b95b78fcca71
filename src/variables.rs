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

/// What the parameters mean to the model's components. Where a parameter has a default in the
/// model ([`crate::model::Effects`], [`crate::model::scene::BodyOptions`], the speed follower),
/// that default is read from here, so the variable table is the one place defaults are set.
impl Parameters {
    /// The effect switches.
    pub fn effects(&self) -> crate::model::Effects {
        crate::model::Effects {
            gas_forces: self.effect_gas_forces,
            mass_forces: self.effect_mass_forces,
            balance_shaft: self.effect_balance_shaft,
            gyroscopic: self.effect_gyroscopic,
            ring_carrier_elasticity: self.effect_ring_carrier,
            mount_nonlinearity: self.effect_mount_nonlinearity,
            chassis_flexibility: self.effect_chassis_flexibility,
        }
    }

    /// How the elastic body is reduced (scene 2).
    pub fn body_options(&self) -> Result<crate::model::scene::BodyOptions, String> {
        use crate::cms::CacheSetting;
        Ok(crate::model::scene::BodyOptions {
            mode_cutoff_hz: self.chassis_mode_cutoff,
            modal_damping_scale: self.chassis_modal_damping_scale,
            interface_rotations: self.chassis_interface_rotations,
            max_rpm: self.scene_max_rpm,
            max_engine_order: self.scene_max_engine_order,
            max_modes: usize::try_from(self.chassis_max_modes).map_err(|_| {
                "chassis.maxModes must be >= 0 (0: select by chassis.modeCutoff)".to_string()
            })?,
            stiffening_bar: self.chassis_stiffening_bar,
            stiff_front_plate: self.chassis_stiff_front_plate,
            cache: if !self.chassis_cache_enabled {
                CacheSetting::Disabled
            } else {
                match self.chassis_cache_dir.trim() {
                    "" => CacheSetting::Default,
                    dir => CacheSetting::Dir(std::path::PathBuf::from(dir)),
                }
            },
        })
    }
}

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
        let xml = crate::fmi2::MODEL_DESCRIPTION_XML;
        assert!(xml.contains(GUID));
        for v in REALS {
            let needle = format!("name=\"{}\" valueReference=\"{}\"", v.name, v.vr);
            assert!(xml.contains(&needle), "{needle}");
        }
        assert_eq!(REALS[real::MOUNT_F[1][2] as usize].name, "mount[2].F[3]");
        assert_eq!(REALS[real::RPM as usize].name, "rpm");
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

    #[test]
    fn parameters_by_fmi_name_refuse_unknown_names() {
        let p: Parameters =
            serde_json::from_str(r#"{"scene": 2, "effects.gasForces": false}"#).unwrap();
        assert_eq!(p.scene, 2);
        assert!(!p.effect_gas_forces);
        assert_eq!(p.solver_rel_tol, Parameters::default().solver_rel_tol);
        let err = serde_json::from_str::<Parameters>(r#"{"solver.relTols": 1e-6}"#)
            .unwrap_err()
            .to_string();
        assert!(err.contains("solver.relTols"), "{err}");
        // The model's own defaults are the table's.
        assert_eq!(
            Parameters::default().effects(),
            crate::model::Effects::default()
        );
        assert_eq!(
            Parameters::default().body_options().unwrap(),
            crate::model::scene::BodyOptions::default()
        );
    }
}
