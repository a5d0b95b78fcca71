//! The chassis of the hybrid scene: which Craig-Bampton reduction ([`crate::cms`]) the scene's
//! settings ask for, and what each of its modes is (for mode tables and checks against the paper).

use crate::cms::{ModeSelection, Reduction, ReductionSpec};
use crate::fe::chassis_config::ChassisConfig;
use crate::fe::eigen::Modes;
use crate::fe::modal::{describe, ModeDescription};

/// The reduction spec for the default body with the given options: fixed-interface modes below
/// `cutoff_hz`, or exactly the `max_modes` lowest when `max_modes > 0`; all constraint modes
/// (translations of the four mount nodes) are always kept.
pub fn reduction_spec(cutoff_hz: f64, max_modes: usize, stiffening_bar: bool) -> ReductionSpec {
    let mut chassis = ChassisConfig::default();
    chassis.options.stiffening_bar = stiffening_bar;
    ReductionSpec {
        chassis,
        selection: if max_modes > 0 {
            ModeSelection::Count(max_modes)
        } else {
            ModeSelection::CutoffHz(cutoff_hz)
        },
        ..ReductionSpec::default()
    }
}

/// The FE description (torsion, steering wheel, front end, …) of every reduced chassis mode, in
/// the order of [`crate::cms::ReducedChassis::omega`].
pub fn describe_modes(r: &Reduction) -> Result<Vec<ModeDescription>, String> {
    let modes = Modes {
        eigenvalues: r.modes.omega.iter().map(|w| w * w).collect(),
        shapes: r.modes.shapes.clone(),
    };
    describe(&r.chassis.mesh, &r.assembled, &modes).map_err(|e| format!("chassis modes: {e}"))
}
