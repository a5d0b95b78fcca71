//! Effect switches: a scene simulates only the effects it calls for (DESIGN §4.5).

use serde::{Deserialize, Serialize};

/// Which physical effects the model includes. A switched-off effect costs nothing: its terms are
/// not evaluated and, for the ring carriers and the body's elastic modes, the states disappear.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Effects {
    /// Piston side-force pairs from the cylinder pressure.
    pub gas_forces: bool,
    /// Inertia forces of the moving crank drive parts (shaking forces, rocking moments, mass torque).
    pub mass_forces: bool,
    /// Balance shaft and the extra crank counterweight pair.
    pub balance_shaft: bool,
    /// Spin of the crank and balance shaft in their angular momentum.
    pub gyroscopic: bool,
    /// Monoblock and housing as two bodies on elastic ring carriers; off: one rigid powertrain.
    pub ring_carrier_elasticity: bool,
    /// Nonlinear mount curves; off: the tangent at the static operating point.
    pub mount_nonlinearity: bool,
    /// Elastic body; off: only the body's rigid-body modes on its suspension (a rigid body).
    pub chassis_flexibility: bool,
}

impl Default for Effects {
    /// The start values of the `effects.*` parameters.
    fn default() -> Self {
        crate::variables::Parameters::default().effects()
    }
}
