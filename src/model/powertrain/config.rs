//! Powertrain configuration (serde): crank drive, balance shafts, gas, the monoblock and housing
//! bodies and the ring carriers between them. Defaults: the paper's Steyr M13 inline-3
//! ([`super::defaults`]).
//!
//! Frame: ISO 8855 vehicle frame, x forward, y left, z up, origin at the front axle centre on the
//! ground. The engine is transverse: the crank axis is +y; the cylinders point along the
//! configurable bore axis (default +z). Angles about the crank axis are measured from the bore
//! axis `b` towards `e_y × b` (for the upright engine: from +z towards +x). All positions are
//! given in the reference configuration (bodies undeflected), SI units.
//!
//! Every struct rejects unknown fields, and no field is silently defaulted: a configuration file
//! is complete, or says `"extends": "default"` to patch the default (see
//! [`crate::model::vehicle::VehicleConfig::from_json`]).

use serde::{Deserialize, Serialize};

use super::gas::GasModel;
use crate::model::validate::{
    err, finite, inertia_tensor, non_negative, positive, unit_vector, ConfigError,
};

/// Mass properties of one rigid body (without the internal moving parts).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RigidBodyConfig {
    /// Mass (kg).
    pub mass: f64,
    /// Centre of mass in the vehicle frame (m); also the body's reference point.
    pub centre_of_mass: [f64; 3],
    /// Inertia tensor about the centre of mass in vehicle axes (kg m²).
    pub inertia: [[f64; 3]; 3],
}

/// One cylinder of the inline engine.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CylinderConfig {
    /// Cylinder axis position along the crank axis relative to the crank centre (m).
    pub y_offset: f64,
    /// Crank throw angle (deg): the cylinder's crank angle after TDC is `φ − throw`.
    pub throw_deg: f64,
    /// Crank angle of this cylinder's firing TDC within the 720° cycle (deg): the firing order.
    pub firing_tdc_deg: f64,
}

/// Crank drive: geometry, reciprocating and rotating masses, cylinders and firing order.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CrankDriveConfig {
    /// Crank centre (middle of the crank axis) in the vehicle frame (m).
    pub crank_centre: [f64; 3],
    /// Cylinder (bore) axis, a unit vector normal to the crank axis y (default +z; an inclined
    /// engine tilts it in the x-z plane).
    pub bore_axis: [f64; 3],
    /// Cylinder bore (m).
    pub bore: f64,
    /// Crank radius, half the stroke (m).
    pub crank_radius: f64,
    /// Conrod length between the pin centres (m).
    pub conrod_length: f64,
    /// Piston + oscillating conrod part per cylinder (kg).
    pub oscillating_mass: f64,
    /// Crank pin + rotating conrod part per cylinder, at the crank radius (kg).
    pub rotating_mass: f64,
    /// Counterweight per throw, opposite the crank pin (kg).
    pub counterweight_mass: f64,
    /// Radius of the counterweights' centre of mass (m).
    pub counterweight_radius: f64,
    /// Crankshaft + flywheel mass on the axis (kg).
    pub crank_mass: f64,
    /// Crankshaft + flywheel spin inertia about the crank axis (kg m²).
    pub crank_axial_inertia: f64,
    /// One entry per cylinder: position along the crank, throw and firing angle.
    pub cylinders: Vec<CylinderConfig>,
}

/// An eccentric mass on a shaft parallel to the crank axis.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EccentricWeight {
    /// Mass (kg).
    pub mass: f64,
    /// Distance of its centre of mass from the shaft axis (m).
    pub eccentricity: f64,
    /// Position along the shaft axis, from the shaft's reference point (m).
    pub y: f64,
    /// Angle at crank angle φ = 0 (deg, from the bore axis towards e_y × bore); it turns at the
    /// shaft's ratio times φ.
    pub phase_deg: f64,
}

/// Residual unbalance of a rotating part after balancing, by its balance grade (ISO 21940-11,
/// which replaced ISO 1940-1): the permissible specific unbalance `e = G / Ω` at the maximum
/// service speed `Ω`, so `U = m G / Ω` for a part of mass `m`. It acts as a point mass `U / r`
/// at radius [`UNBALANCE_RADIUS`] on the part, turning with it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ResidualUnbalance {
    /// `crank`, or the name of a balance shaft.
    pub part: String,
    /// Balance grade G (mm/s), e.g. 16 for G 16.
    pub grade_mm_per_s: f64,
    /// Maximum service speed of the engine (rpm) the grade refers to.
    pub service_rpm: f64,
    /// Axial position (m) from the crank centre plane (y = 0).
    pub y: f64,
    /// Angle of the unbalance (deg) in the part's frame, as for eccentric weights.
    pub phase_deg: f64,
}

/// Radius at which a residual unbalance is placed as a point mass (m).
pub const UNBALANCE_RADIUS: f64 = 0.05;

/// A balance shaft: a shaft parallel to the crank axis turning at `ratio` times the crank's speed
/// relative to the block (−1: the inline-3's counter-rotating first-order shaft; ±2: a pair of
/// Lanchester shafts of an inline-4), carrying eccentric weights.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BalanceShaftConfig {
    /// The shaft's name (a residual unbalance refers to it).
    pub name: String,
    /// A point of the shaft axis in the vehicle frame; the reference of the weights' `y` (m).
    pub axis_point: [f64; 3],
    /// Speed relative to the block as a multiple of the crank's (negative: counter-rotating).
    pub ratio: f64,
    /// Shaft mass on the axis (kg).
    pub shaft_mass: f64,
    /// Shaft spin inertia about its axis (kg m²).
    pub shaft_axial_inertia: f64,
    /// The eccentric weights it carries.
    pub weights: Vec<EccentricWeight>,
}

/// Gas pressure source and load.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GasConfig {
    /// Where the cylinder pressure comes from: the Wiebe combustion model or a measured table.
    pub model: GasModel,
    /// Load between idle (0) and full load (1) for the Wiebe model.
    pub load: f64,
    /// Crankcase pressure acting under the piston (Pa).
    pub crankcase_pressure: f64,
    /// Cylinder-to-cylinder variation: relative deviation of each cylinder's heat release from
    /// the mean (Wiebe model), one per cylinder, or empty for identical cylinders. The pressure
    /// equation is linear in the heat released, so cylinder `i` sees
    /// `p_motored + (1 + δ_i)(p − p_motored)` and its IMEP scales by `1 + δ_i`.
    pub cylinder_heat_spread: Vec<f64>,
}

/// Linear 6-DOF elastomer bushing (ring carrier) between monoblock and housing.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct BushingConfig {
    /// The ring carrier's name (e.g. front, rear).
    pub name: String,
    /// Location in the vehicle frame (m).
    pub position: [f64; 3],
    /// Stiffness in housing axes: translations x, y, z (N/m), rotations x, y, z (N m/rad).
    pub stiffness: [f64; 6],
    /// Damping in the same order (N s/m, N m s/rad).
    pub damping: [f64; 6],
}

/// The powertrain: monoblock with its crank drive, balance shafts and gas forces, the housing
/// (gearbox, aggregates, mount brackets), and the ring carriers between the two.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct EngineConfig {
    /// Crank angle at the start of a simulation (deg, relative to the monoblock).
    pub start_crank_angle_deg: f64,
    /// Excitation fade-in time (s); 0 switches the excitation on at once.
    pub excitation_fade_in: f64,
    /// Crank drive geometry, masses and cylinders.
    pub crank_drive: CrankDriveConfig,
    /// Balance shafts (effect switch `balance_shaft`).
    pub balance_shafts: Vec<BalanceShaftConfig>,
    /// Extra counterweights on the crank that work with the balance shafts (switched with them);
    /// `y` from the crank centre, turning with the crank.
    pub crank_counterweights: Vec<EccentricWeight>,
    /// Residual unbalance of the crank and the balance shafts (present whatever the effect
    /// switches say: balancing never removes it completely).
    pub residual_unbalance: Vec<ResidualUnbalance>,
    /// Gas pressure source, load and cylinder-to-cylinder spread.
    pub gas: GasConfig,
    /// Monoblock structure (cylinders, head, main bearing frame) without the moving parts.
    pub monoblock: RigidBodyConfig,
    /// Housing + gearbox + aggregates (carries the mount brackets).
    pub housing: RigidBodyConfig,
    /// Ring carriers between monoblock and housing (effect switch `ring_carrier_elasticity`).
    pub ring_carriers: Vec<BushingConfig>,
}

impl RigidBodyConfig {
    fn validate(&self, field: &str) -> Result<(), ConfigError> {
        positive(&format!("{field}.mass"), self.mass)?;
        finite(&format!("{field}.centre_of_mass"), &self.centre_of_mass)?;
        inertia_tensor(&format!("{field}.inertia"), &self.inertia)
    }
}

impl EccentricWeight {
    fn validate(&self, field: &str) -> Result<(), ConfigError> {
        non_negative(&format!("{field}.mass"), self.mass)?;
        non_negative(&format!("{field}.eccentricity"), self.eccentricity)?;
        finite(&format!("{field}.y"), &[self.y])?;
        finite(&format!("{field}.phase_deg"), &[self.phase_deg])
    }
}

impl EngineConfig {
    /// Checks every physical parameter; the error names the field (prefixed by `at`) and its
    /// value.
    ///
    /// Long on purpose: a flat list of independent checks, one per field.
    pub fn validate(&self) -> Result<(), ConfigError> {
        finite("start_crank_angle_deg", &[self.start_crank_angle_deg])?;
        non_negative("excitation_fade_in", self.excitation_fade_in)?;
        let c = &self.crank_drive;
        finite("crank_drive.crank_centre", &c.crank_centre)?;
        unit_vector("crank_drive.bore_axis", &c.bore_axis)?;
        if c.bore_axis[1].abs() > 1e-6 {
            return Err(err(
                "crank_drive.bore_axis",
                format!(
                    "crank_drive.bore_axis = {:?} must be normal to the crank axis y",
                    c.bore_axis
                ),
            ));
        }
        positive("crank_drive.bore", c.bore)?;
        positive("crank_drive.crank_radius", c.crank_radius)?;
        positive("crank_drive.conrod_length", c.conrod_length)?;
        let lambda = c.crank_radius / c.conrod_length;
        if lambda >= 1.0 {
            return Err(err(
                "crank_drive.conrod_length",
                format!("lambda = crank_radius / conrod_length = {lambda} must be < 1 (conrod_length = {})", c.conrod_length),
            ));
        }
        positive("crank_drive.oscillating_mass", c.oscillating_mass)?;
        non_negative("crank_drive.rotating_mass", c.rotating_mass)?;
        non_negative("crank_drive.counterweight_mass", c.counterweight_mass)?;
        non_negative("crank_drive.counterweight_radius", c.counterweight_radius)?;
        non_negative("crank_drive.crank_mass", c.crank_mass)?;
        non_negative("crank_drive.crank_axial_inertia", c.crank_axial_inertia)?;
        if c.cylinders.is_empty() {
            return Err(err(
                "crank_drive.cylinders",
                "at least one cylinder is required",
            ));
        }
        for (i, cyl) in c.cylinders.iter().enumerate() {
            let fc = format!("crank_drive.cylinders[{i}]");
            finite(&fc, &[cyl.y_offset, cyl.throw_deg, cyl.firing_tdc_deg])?;
            let diff = (cyl.firing_tdc_deg - cyl.throw_deg).rem_euclid(360.0);
            if diff > 1e-6 && diff < 360.0 - 1e-6 {
                return Err(err(
                    format!("{fc}.firing_tdc_deg"),
                    format!(
                        "{fc}.firing_tdc_deg = {} must be a TDC of the cylinder, i.e. equal to throw_deg = {} modulo 360",
                        cyl.firing_tdc_deg, cyl.throw_deg
                    ),
                ));
            }
        }
        for (i, b) in self.balance_shafts.iter().enumerate() {
            let fb = format!("balance_shafts[{i}]");
            finite(&format!("{fb}.axis_point"), &b.axis_point)?;
            if !(b.ratio.is_finite() && b.ratio != 0.0) {
                return Err(err(
                    format!("{fb}.ratio"),
                    format!("{fb}.ratio = {} must be finite and non-zero", b.ratio),
                ));
            }
            non_negative(&format!("{fb}.shaft_mass"), b.shaft_mass)?;
            non_negative(&format!("{fb}.shaft_axial_inertia"), b.shaft_axial_inertia)?;
            for (k, w) in b.weights.iter().enumerate() {
                w.validate(&format!("{fb}.weights[{k}]"))?;
            }
        }
        for (k, u) in self.residual_unbalance.iter().enumerate() {
            let f = format!("residual_unbalance[{k}]");
            if u.part != "crank" && !self.balance_shafts.iter().any(|b| b.name == u.part) {
                return Err(err(
                    format!("{f}.part"),
                    format!(
                        "{f}.part = {:?} is neither \"crank\" nor a balance shaft's name",
                        u.part
                    ),
                ));
            }
            non_negative(&format!("{f}.grade_mm_per_s"), u.grade_mm_per_s)?;
            positive(&format!("{f}.service_rpm"), u.service_rpm)?;
            finite(&format!("{f}.y"), &[u.y, u.phase_deg])?;
        }
        for (k, w) in self.crank_counterweights.iter().enumerate() {
            w.validate(&format!("crank_counterweights[{k}]"))?;
        }
        self.validate_gas()?;
        self.monoblock.validate("monoblock")?;
        self.housing.validate("housing")?;
        for (i, r) in self.ring_carriers.iter().enumerate() {
            let fr = format!("ring_carriers[{i}]");
            finite(&format!("{fr}.position"), &r.position)?;
            for k in 0..6 {
                non_negative(&format!("{fr}.stiffness[{k}]"), r.stiffness[k])?;
                non_negative(&format!("{fr}.damping[{k}]"), r.damping[k])?;
            }
        }
        Ok(())
    }

    /// Crank radius over conrod length.
    pub fn lambda(&self) -> f64 {
        self.crank_drive.crank_radius / self.crank_drive.conrod_length
    }

    /// Long on purpose: a flat list of independent checks, one per field.
    fn validate_gas(&self) -> Result<(), ConfigError> {
        let g = &self.gas;
        let load = g.load;
        if !(load.is_finite() && (0.0..=1.0).contains(&load)) {
            return Err(err(
                "gas.load",
                format!("gas.load = {load} must lie in [0, 1]"),
            ));
        }
        positive("gas.crankcase_pressure", g.crankcase_pressure)?;
        let n = self.crank_drive.cylinders.len();
        if !(g.cylinder_heat_spread.is_empty() || g.cylinder_heat_spread.len() == n) {
            return Err(err(
                "gas.cylinder_heat_spread",
                format!(
                    "gas.cylinder_heat_spread has {} entries for {n} cylinders (give one per cylinder, or none)",
                    g.cylinder_heat_spread.len()
                ),
            ));
        }
        for (i, d) in g.cylinder_heat_spread.iter().enumerate() {
            if !(d.is_finite() && *d > -1.0) {
                return Err(err(
                    "gas.cylinder_heat_spread",
                    format!("gas.cylinder_heat_spread[{i}] = {d} must be finite and > -1"),
                ));
            }
        }
        if !g.cylinder_heat_spread.is_empty() && matches!(g.model, GasModel::Table(_)) {
            return Err(err(
                "gas.cylinder_heat_spread",
                "a cylinder-to-cylinder spread needs the Wiebe model (a pressure table has no heat release to vary)".to_owned(),
            ));
        }
        match &g.model {
            GasModel::Wiebe(w) => {
                if !(w.compression_ratio.is_finite() && w.compression_ratio > 1.0) {
                    return Err(err(
                        "gas.model.compression_ratio",
                        format!(
                            "gas.model.compression_ratio = {} must be > 1",
                            w.compression_ratio
                        ),
                    ));
                }
                for (name, k) in [
                    ("kappa_compression", w.kappa_compression),
                    ("kappa_expansion", w.kappa_expansion),
                ] {
                    if !(k.is_finite() && k > 1.0 && k < 2.0) {
                        return Err(err(
                            format!("gas.model.{name}"),
                            format!("gas.model.{name} = {k} must lie in (1, 2)"),
                        ));
                    }
                }
                if !(w.ivc_deg.is_finite()
                    && w.evo_deg.is_finite()
                    && -360.0 < w.ivc_deg
                    && w.ivc_deg < 0.0
                    && 0.0 < w.evo_deg
                    && w.evo_deg < 360.0)
                {
                    return Err(err(
                        "gas.model.ivc_deg",
                        format!(
                            "need -360 < ivc_deg = {} < 0 < evo_deg = {} < 360",
                            w.ivc_deg, w.evo_deg
                        ),
                    ));
                }
                positive("gas.model.blowdown_deg", w.blowdown_deg)?;
                for (pname, p) in [("idle", &w.idle), ("full_load", &w.full_load)] {
                    let f = format!("gas.model.{pname}");
                    positive(&format!("{f}.pressure_ivc"), p.pressure_ivc)?;
                    non_negative(&format!("{f}.heat"), p.heat)?;
                    let total: f64 = p.stages.iter().map(|s| s.fraction).sum();
                    if p.heat > 0.0 && (total - 1.0).abs() > 1e-6 {
                        return Err(err(
                            format!("{f}.stages"),
                            format!("{f}.stages fractions sum to {total}, must be 1"),
                        ));
                    }
                    for (i, s) in p.stages.iter().enumerate() {
                        let sf = format!("{f}.stages[{i}]");
                        non_negative(&format!("{sf}.fraction"), s.fraction)?;
                        positive(&format!("{sf}.duration_deg"), s.duration_deg)?;
                        non_negative(&format!("{sf}.shape"), s.shape)?;
                        finite(&format!("{sf}.start_deg"), &[s.start_deg])?;
                    }
                }
            }
            GasModel::Table(t) => {
                if t.angle_deg.len() != t.pressure.len() || t.angle_deg.len() < 4 {
                    return Err(err(
                        "gas.model.pressure",
                        format!("pressure table needs matching angle/pressure lists of at least 4 points, got {} and {}", t.angle_deg.len(), t.pressure.len()),
                    ));
                }
                finite("gas.model.angle_deg", &t.angle_deg)?;
                for (i, p) in t.pressure.iter().enumerate() {
                    positive(&format!("gas.model.pressure[{i}]"), *p)?;
                }
            }
        }
        Ok(())
    }
}
