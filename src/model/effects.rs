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

impl Effects {
    /// Every effect on: the full model.
    pub const ALL: Effects = Effects {
        gas_forces: true,
        mass_forces: true,
        balance_shaft: true,
        gyroscopic: true,
        ring_carrier_elasticity: true,
        mount_nonlinearity: true,
        chassis_flexibility: true,
    };

    /// The value of one switch.
    pub fn get(&self, switch: EffectSwitch) -> bool {
        let mut copy = *self;
        *copy.slot(switch)
    }

    /// Sets one switch.
    pub fn set(&mut self, switch: EffectSwitch, on: bool) {
        *self.slot(switch) = on;
    }

    fn slot(&mut self, switch: EffectSwitch) -> &mut bool {
        match switch {
            EffectSwitch::GasForces => &mut self.gas_forces,
            EffectSwitch::MassForces => &mut self.mass_forces,
            EffectSwitch::BalanceShaft => &mut self.balance_shaft,
            EffectSwitch::Gyroscopic => &mut self.gyroscopic,
            EffectSwitch::RingCarrierElasticity => &mut self.ring_carrier_elasticity,
            EffectSwitch::MountNonlinearity => &mut self.mount_nonlinearity,
            EffectSwitch::ChassisFlexibility => &mut self.chassis_flexibility,
        }
    }
}

impl Default for Effects {
    /// The full model ([`Effects::ALL`]).
    fn default() -> Self {
        Effects::ALL
    }
}

/// One of the [`Effects`] switches, to name it without its value.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum EffectSwitch {
    /// [`Effects::gas_forces`].
    GasForces,
    /// [`Effects::mass_forces`].
    MassForces,
    /// [`Effects::balance_shaft`].
    BalanceShaft,
    /// [`Effects::gyroscopic`].
    Gyroscopic,
    /// [`Effects::ring_carrier_elasticity`].
    RingCarrierElasticity,
    /// [`Effects::mount_nonlinearity`].
    MountNonlinearity,
    /// [`Effects::chassis_flexibility`].
    ChassisFlexibility,
}

impl EffectSwitch {
    /// Every switch, in the order of the [`Effects`] fields.
    pub const ALL: [EffectSwitch; 7] = [
        EffectSwitch::GasForces,
        EffectSwitch::MassForces,
        EffectSwitch::BalanceShaft,
        EffectSwitch::Gyroscopic,
        EffectSwitch::RingCarrierElasticity,
        EffectSwitch::MountNonlinearity,
        EffectSwitch::ChassisFlexibility,
    ];
}
