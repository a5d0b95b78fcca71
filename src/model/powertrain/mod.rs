//! The powertrain component: the monoblock with its internal parts (crank drive, balance shafts),
//! the housing, the ring carriers between them, gas forces and gravity.
//!
//! It owns 1 or 2 free rigid bodies (6 coordinates each: one rigid powertrain, or monoblock and
//! housing on elastic ring carriers) and evaluates their composite-body dynamics
//! (`M(q, φ) v' = Q`) for a given crank-drive state; where those coordinates live in the state
//! vector, and what the mounts attach to, is the coupled model's business
//! ([`crate::model::coupled`]).

pub mod assembly;
pub mod composite;
pub mod config;
pub mod defaults;
pub mod gas;
pub mod part_moments;
pub mod parts;
pub mod reaction;
pub mod ring_carrier;

use std::sync::Arc;

use nalgebra::Vector3;

use self::assembly::{build_bodies, v3, Body};
use self::composite::{BodyDynamics, BodyKinematics, CrankDriveState};
use self::config::EngineConfig;
use self::gas::{side_force, CylinderGeometry, GasModel, PressureCurve};
use self::part_moments::PartMoments;
use self::parts::{slider_crank, slider_crank_trig};
use self::ring_carrier::RingCarrier;
use super::effects::Effects;
use super::inputs::InputError;
use super::validate::ConfigError;

/// The Wiebe model's curves at idle and full load, one per distinct cylinder, for changing the
/// load at run time.
#[derive(Debug, Clone, PartialEq)]
struct LoadPoints {
    /// Per cylinder with the heat-release spread; a single curve when the cylinders are alike.
    idle: Vec<PressureCurve>,
    full: Vec<PressureCurve>,
}

impl LoadPoints {
    /// Each cylinder's heat scaled by `1 + δ` of `spread` (empty: identical cylinders) and
    /// integrated on its own: with wall heat loss the pressure is not linear in the heat, so a
    /// blend of motored and fired curves would only be the first-order term.
    fn new(model: &gas::WiebeModel, spread: &[f64], geometry: &CylinderGeometry) -> LoadPoints {
        let per_cylinder = |point: &gas::CombustionPoint| -> Vec<PressureCurve> {
            if spread.iter().all(|d| *d == 0.0) {
                return vec![PressureCurve::wiebe(model, point, geometry)];
            }
            spread
                .iter()
                .map(|d| {
                    let scaled = gas::CombustionPoint {
                        heat: point.heat * (1.0 + d),
                        ..point.clone()
                    };
                    PressureCurve::wiebe(model, &scaled, geometry)
                })
                .collect()
        };
        LoadPoints {
            idle: per_cylinder(&model.idle),
            full: per_cylinder(&model.full_load),
        }
    }

    /// Refuses curves whose peak pressure is not finite or beyond [`MAX_PEAK_PRESSURE`]: a heat
    /// release far beyond any engine's (a mistyped exponent) would otherwise pass the set-up and
    /// fail at the first step.
    fn check_peaks(&self) -> Result<(), ConfigError> {
        for (what, curves) in [("idle", &self.idle), ("full_load", &self.full)] {
            for curve in curves {
                let peak = curve.peak();
                if !(curve.is_finite() && peak <= MAX_PEAK_PRESSURE) {
                    return Err(ConfigError {
                        field: format!("engine.gas.model.{what}.heat"),
                        message: format!(
                            "the {what} heat release gives a peak cylinder pressure of {:.3e} bar, beyond the {:.0} bar any engine withstands",
                            peak / 1e5,
                            MAX_PEAK_PRESSURE / 1e5
                        ),
                    });
                }
            }
        }
        Ok(())
    }

    /// Per-cylinder curves at `load` (shared when the cylinders are identical).
    fn curves(&self, load: f64, cylinders: usize) -> Vec<Arc<PressureCurve>> {
        let blended: Vec<Arc<PressureCurve>> = self
            .idle
            .iter()
            .zip(&self.full)
            .map(|(idle, full)| Arc::new(PressureCurve::blend(idle, full, load)))
            .collect();
        if blended.len() == 1 {
            return (0..cylinders).map(|_| Arc::clone(&blended[0])).collect();
        }
        blended
    }
}

/// Highest peak cylinder pressure accepted, Pa: 500 bar, twice what today's diesel engines are
/// built for.
pub const MAX_PEAK_PRESSURE: f64 = 500e5;

/// Crank speed (rad/s) from which the engine fires fully; below it the gas excitation fades out
/// smoothly to none at standstill (the cylinders do not fire on a standing crank). 300 rpm is
/// below any idle speed and above a starter's cranking speed.
pub const FIRING_SPEED: f64 = 300.0 * std::f64::consts::PI / 30.0;

/// Share of the gas excitation at crank speed `speed`: smoothstep from 0 at rest to 1 at
/// [`FIRING_SPEED`].
pub fn firing_factor(speed: f64) -> f64 {
    let x = (speed.abs() / FIRING_SPEED).min(1.0);
    x * x * (3.0 - 2.0 * x)
}

/// Gas excitation prepared from the configuration.
#[derive(Debug, Clone, PartialEq)]
struct GasExcitation {
    /// Pressure curve of each cylinder (shared when they are alike).
    curves: Vec<Arc<PressureCurve>>,
    load_points: Option<LoadPoints>,
    /// Relative heat-release deviation per cylinder (empty: identical cylinders).
    spread: Vec<f64>,
    /// Mean indicated torque of all cylinders (N m), from the pressure curves' work per cycle.
    mean_torque: f64,
    area: f64,
    crankcase_pressure: f64,
    radius: f64,
    conrod: f64,
    /// (y offset, throw, firing TDC) per cylinder, radians.
    cylinders: Vec<(f64, f64, f64)>,
    /// (sin, cos) of each cylinder's throw.
    throw_trig: Vec<(f64, f64)>,
    /// Crank centre relative to body 0's reference point, and the bore axis (body axes).
    crank_centre: Vector3<f64>,
    bore: Vector3<f64>,
}

impl GasExcitation {
    fn new(config: &EngineConfig, reference: &Vector3<f64>) -> Result<Self, ConfigError> {
        let c = &config.crank_drive;
        let geometry = CylinderGeometry {
            bore: c.bore,
            crank_radius: c.crank_radius,
            conrod: c.conrod_length,
        };
        let n = c.cylinders.len();
        let spread = config.gas.cylinder_heat_spread.clone();
        let (curves, load_points) = match &config.gas.model {
            GasModel::Wiebe(w) => {
                let points = LoadPoints::new(w, &spread, &geometry);
                points.check_peaks()?;
                (points.curves(config.gas.load, n), Some(points))
            }
            GasModel::Table(t) => {
                let curve = PressureCurve::from_table(t).map_err(|message| ConfigError {
                    field: "engine.gas.model".into(),
                    message,
                })?;
                let shared = Arc::new(curve);
                ((0..n).map(|_| Arc::clone(&shared)).collect(), None)
            }
        };
        let mut gas = GasExcitation {
            curves,
            load_points,
            spread,
            mean_torque: 0.0,
            area: geometry.piston_area(),
            crankcase_pressure: config.gas.crankcase_pressure,
            radius: c.crank_radius,
            conrod: c.conrod_length,
            cylinders: c
                .cylinders
                .iter()
                .map(|k| {
                    (
                        k.y_offset,
                        k.throw_deg.to_radians(),
                        k.firing_tdc_deg.to_radians(),
                    )
                })
                .collect(),
            throw_trig: c
                .cylinders
                .iter()
                .map(|k| k.throw_deg.to_radians().sin_cos())
                .collect(),
            crank_centre: v3(&c.crank_centre) - reference,
            bore: v3(&c.bore_axis),
        };
        gas.mean_torque = gas.indicated_torque();
        Ok(gas)
    }

    /// Mean indicated torque `Σ_i ∮ (p_i − p_crankcase) dV / 4π` (N m) of the current curves.
    fn indicated_torque(&self) -> f64 {
        const SAMPLES: usize = 2880;
        let step = 4.0 * std::f64::consts::PI / SAMPLES as f64;
        let volume = |psi: f64| -self.area * slider_crank(psi, self.radius, self.conrod).0;
        let mut work = 0.0;
        for (&(_, throw, firing), curve) in self.cylinders.iter().zip(&self.curves) {
            for k in 0..SAMPLES {
                let (a, b) = (k as f64 * step, (k + 1) as f64 * step);
                let p = 0.5 * (curve.pressure(a - firing) + curve.pressure(b - firing));
                work += (p - self.crankcase_pressure) * (volume(b - throw) - volume(a - throw));
            }
        }
        work / (4.0 * std::f64::consts::PI)
    }
}

/// The powertrain ready for evaluation.
#[derive(Debug, Clone)]
pub struct Powertrain {
    config: EngineConfig,
    effects: Effects,
    bodies: Vec<Body>,
    /// Each body's parts compiled for evaluation.
    moments: Vec<PartMoments>,
    ring_carriers: Vec<RingCarrier>,
    gas: Option<GasExcitation>,
    gravity: Vector3<f64>,
}

impl Powertrain {
    /// Builds the powertrain of `config` with the effects switched as in `effects`, under gravity
    /// `g` (m/s², along −z). The configuration is validated here.
    pub fn new(config: EngineConfig, effects: Effects, g: f64) -> Result<Self, ConfigError> {
        config.validate()?;
        if effects.ring_carrier_elasticity && config.ring_carriers.is_empty() {
            return Err(ConfigError {
                field: "engine.ring_carriers".into(),
                message: "ring carrier elasticity is on but no ring carrier is configured".into(),
            });
        }
        let bodies = build_bodies(&config, &effects);
        let ring_carriers = if bodies.len() == 2 {
            config
                .ring_carriers
                .iter()
                .map(|r| RingCarrier::from_config(r, &bodies[0].reference, &bodies[1].reference))
                .collect()
        } else {
            Vec::new()
        };
        let gas = if effects.gas_forces {
            Some(GasExcitation::new(&config, &bodies[0].reference)?)
        } else {
            None
        };
        Ok(Self {
            config,
            effects,
            moments: bodies.iter().map(|b| PartMoments::new(&b.parts)).collect(),
            bodies,
            ring_carriers,
            gas,
            gravity: Vector3::new(0.0, 0.0, -g),
        })
    }

    /// The engine configuration it was built from.
    pub fn config(&self) -> &EngineConfig {
        &self.config
    }

    /// The effect switches it was built with.
    pub fn effects(&self) -> &Effects {
        &self.effects
    }

    /// The free rigid bodies: monoblock and housing, or one rigid powertrain.
    pub fn bodies(&self) -> &[Body] {
        &self.bodies
    }

    /// Body `b`'s parts compiled for evaluation.
    pub fn part_moments(&self, b: usize) -> &PartMoments {
        &self.moments[b]
    }

    /// The ring carriers between monoblock and housing (none when they are rigid).
    pub fn ring_carriers(&self) -> &[RingCarrier] {
        &self.ring_carriers
    }

    /// Gravitational acceleration (m/s², vehicle frame).
    pub fn gravity(&self) -> &Vector3<f64> {
        &self.gravity
    }

    /// Number of free bodies (2 with elastic ring carriers, else 1).
    pub fn body_count(&self) -> usize {
        self.bodies.len()
    }

    /// Index of the body carrying the mount brackets (housing or the rigid powertrain).
    pub fn housing_index(&self) -> usize {
        self.bodies.len() - 1
    }

    /// Reference point of the housing outputs: the housing's centre of mass in the reference
    /// configuration (also when the powertrain is one rigid body).
    pub fn housing_reference(&self) -> Vector3<f64> {
        v3(&self.config.housing.centre_of_mass)
    }

    /// Total mass of every body and part (kg).
    pub fn mass(&self) -> f64 {
        self.bodies
            .iter()
            .flat_map(|b| b.parts.iter())
            .map(|p| p.mass)
            .sum()
    }

    /// The crank angle after which every excitation repeats (rad): the four-stroke working cycle
    /// of two revolutions, provided every balance shaft's turn fits into it a whole number of
    /// times (ratio a multiple of ½); otherwise an error naming the shaft.
    pub fn cycle_angle(&self) -> Result<f64, String> {
        let cycle = 4.0 * std::f64::consts::PI;
        for shaft in &self.config.balance_shafts {
            let turns = 2.0 * shaft.ratio;
            if (turns - turns.round()).abs() > 1e-9 {
                return Err(format!(
                    "balance shaft {} turns {} times per working cycle: the engine's excitation \
                     has no period of one cycle",
                    shaft.name, turns
                ));
            }
        }
        Ok(cycle)
    }

    /// Crank angle at the start of a simulation (rad, relative to the monoblock).
    pub fn start_angle(&self) -> f64 {
        self.config.start_crank_angle_deg.to_radians()
    }

    /// Engine load between idle (0) and full load (1) of the Wiebe gas model, at run time.
    /// Ignored (Ok) when gas forces are off; an error for a user pressure table.
    pub fn set_gas_load(&mut self, load: f64) -> Result<(), InputError> {
        if !(load.is_finite() && (0.0..=1.0).contains(&load)) {
            return Err(InputError::Other(format!(
                "gas load {load} must lie in [0, 1]"
            )));
        }
        if let Some(gas) = &mut self.gas {
            let Some(points) = &gas.load_points else {
                return Err(InputError::Other(
                    "the gas pressure comes from a user table; its load cannot change".into(),
                ));
            };
            gas.curves = points.curves(load, gas.cylinders.len());
            gas.mean_torque = gas.indicated_torque();
        }
        self.config.gas.load = load;
        Ok(())
    }

    /// Contributions that depend on one body's coordinates only (and on the crank angle): its
    /// parts with gravity (the parts placed as `crank` says), the gas side forces at crank angle
    /// `phi` scaled by `gas_scale` (monoblock), the load torque about the crank axis (housing).
    pub fn local_dynamics(
        &self,
        b: usize,
        kin: &BodyKinematics,
        crank: &CrankDriveState,
        phi: f64,
        gas_scale: f64,
        load_torque: f64,
    ) -> BodyDynamics {
        let mut d = BodyDynamics::zero();
        self.moments[b].add(kin, crank, &self.gravity, &mut d);
        if b == 0 && gas_scale != 0.0 {
            self.add_gas_forces(kin, phi, gas_scale, &mut d);
        }
        if b == self.housing_index() {
            d.add_wrench(
                &Vector3::zeros(),
                &(kin.rotation * Vector3::y() * load_torque),
            );
        }
        d
    }

    /// Ring-carrier forces on monoblock and housing (nothing for a rigid powertrain).
    pub fn add_ring_carriers(&self, kin: &[BodyKinematics], dynamics: &mut [BodyDynamics]) {
        if kin.len() != 2 {
            return;
        }
        for rc in &self.ring_carriers {
            let w = rc.wrench(&kin[0], &kin[1]);
            dynamics[0].add_point_force(&kin[0], &w.monoblock_point, &w.monoblock_force);
            dynamics[0].add_wrench(&Vector3::zeros(), &w.monoblock_moment);
            dynamics[1].add_point_force(&kin[1], &w.housing_point, &w.housing_force);
            dynamics[1].add_wrench(&Vector3::zeros(), &w.housing_moment);
        }
    }

    /// Piston side-force pairs (paper §4.2) on the monoblock `body`: `−F_N` at each piston pin,
    /// `+F_N` at the main bearing on the same cylinder axis, `F_N = p A tan β` along
    /// `e_y × bore`, scaled by `scale`.
    pub fn add_gas_forces(
        &self,
        body: &BodyKinematics,
        phi: f64,
        scale: f64,
        out: &mut BodyDynamics,
    ) {
        let Some(gas) = &self.gas else { return };
        let side = body.rotation * Vector3::y().cross(&gas.bore);
        let (sin, cos) = phi.sin_cos();
        let cylinders = gas.cylinders.iter().zip(&gas.throw_trig).zip(&gas.curves);
        for ((&(yo, _, firing), &(sin_throw, cos_throw)), curve) in cylinders {
            let sn = sin * cos_throw - cos * sin_throw;
            let cs = cos * cos_throw + sin * sin_throw;
            let p = curve.pressure(phi - firing);
            let f_gas = (p - gas.crankcase_pressure) * gas.area * scale;
            let n = side_force(f_gas, sn, gas.radius / gas.conrod);
            let (s, _, _) = slider_crank_trig(sn, cs, gas.radius, gas.conrod);
            let on_axis = gas.crank_centre + Vector3::new(0.0, yo, 0.0);
            let pin = body.point(&(on_axis + gas.bore * s));
            let bearing = body.point(&on_axis);
            out.add_point_force(body, &pin, &(-n * side));
            out.add_point_force(body, &bearing, &(n * side));
        }
        // The mean of the gas torque leaves the crank inside the powertrain, to the engine's
        // friction and into the gearbox; its reaction on the block closes the torque path, so on
        // average the mounts carry only the drivetrain's reaction (the load torque input) and the
        // gas forces excite the alternating part.
        out.add_wrench(
            &Vector3::zeros(),
            &(body.rotation * Vector3::y() * (gas.mean_torque * scale)),
        );
    }

    /// Mean indicated torque of the engine at its current load (N m; 0 without gas forces).
    pub fn mean_indicated_torque(&self) -> f64 {
        self.gas.as_ref().map_or(0.0, |g| g.mean_torque)
    }

    /// Cylinder pressure of cylinder `i` at crank angle `phi` (Pa), if gas forces are on.
    pub fn cylinder_pressure(&self, i: usize, phi: f64) -> Option<f64> {
        let gas = self.gas.as_ref()?;
        let &(_, _, firing) = gas.cylinders.get(i)?;
        Some(gas.curves[i].pressure(phi - firing))
    }
}
