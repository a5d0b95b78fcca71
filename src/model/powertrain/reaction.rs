//! Reaction of the crank drive on a monoblock held fixed ("engine on rigid ground", facts 1–5 of
//! DESIGN §7): the forces and moments the moving parts (through their inertia, via the
//! composite-body projection) and the gas side-force pairs exert on the block.

use nalgebra::Vector3;

use super::assembly::v3;
use super::composite::{BodyDynamics, BodyKinematics, CrankDriveState};
use super::Powertrain;

/// Force and moment (vehicle frame) on the monoblock.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Wrench {
    /// Force (N).
    pub force: [f64; 3],
    /// About the crank centre.
    pub moment: [f64; 3],
}

impl Powertrain {
    /// Wrench the crank drive exerts on the monoblock held fixed at its reference pose, at crank
    /// angle `phi`, crank spin `speed` and spin acceleration `acceleration`; gravity excluded,
    /// effect switches honoured, no fade-in. Minus this is the reaction on rigid ground.
    pub fn crank_drive_wrench(&self, phi: f64, speed: f64, acceleration: f64) -> Wrench {
        let fx = *self.effects();
        let body = &self.bodies()[0];
        let kin = BodyKinematics::at_rest(body.reference);
        let crank = CrankDriveState {
            angle: phi,
            speed,
            acceleration,
            excitation: if fx.mass_forces { 1.0 } else { 0.0 },
            spin: if fx.gyroscopic { speed } else { 0.0 },
        };
        let mut dynamics = BodyDynamics::zero();
        self.part_moments(0)
            .add(&kin, &crank, &Vector3::zeros(), &mut dynamics);
        self.add_gas_forces(&kin, phi, 1.0, &mut dynamics);
        let f = dynamics.force;
        let force = Vector3::new(f[0], f[1], f[2]);
        let centre = v3(&self.config().crank_drive.crank_centre);
        let moment = Vector3::new(f[3], f[4], f[5]) + (body.reference - centre).cross(&force);
        Wrench {
            force: [force.x, force.y, force.z],
            moment: [moment.x, moment.y, moment.z],
        }
    }
}
