//! Builds the bodies of the engine model (parts, reference points) from a configuration.

use nalgebra::{Matrix3, Vector3};

use super::config::{
    CrankDriveConfig, EccentricWeight, EngineConfig, RigidBodyConfig, UNBALANCE_RADIUS,
};
use super::parts::{Part, PartMotion};
use crate::model::effects::Effects;

/// One free rigid body (6 coordinates) with the parts it carries.
#[derive(Debug, Clone, PartialEq)]
pub struct Body {
    /// The body's name (`monoblock`, `housing`, or the rigid powertrain's).
    pub name: String,
    /// Reference point in the vehicle frame (reference configuration).
    pub reference: Vector3<f64>,
    /// The parts it carries (fixed masses, crank-drive parts, balance weights).
    pub parts: Vec<Part>,
}

pub(crate) fn v3(a: &[f64; 3]) -> Vector3<f64> {
    Vector3::new(a[0], a[1], a[2])
}

pub(crate) fn m3(a: &[[f64; 3]; 3]) -> Matrix3<f64> {
    Matrix3::from_fn(|r, c| a[r][c])
}

fn spin_inertia(j: f64) -> Matrix3<f64> {
    Matrix3::new(0.0, 0.0, 0.0, 0.0, j, 0.0, 0.0, 0.0, 0.0)
}

/// A rigid body's own structure as a part of a body with reference point `reference`.
pub fn structure_part(name: &str, body: &RigidBodyConfig, reference: &Vector3<f64>) -> Part {
    Part {
        name: name.to_string(),
        mass: body.mass,
        inertia: m3(&body.inertia),
        motion: PartMotion::Fixed {
            offset: v3(&body.centre_of_mass) - reference,
        },
        spin_ratio: 0.0,
    }
}

/// Crank drive parts (pistons, crank points, crank rotor), relative to `reference`.
pub fn crank_drive_parts(c: &CrankDriveConfig, reference: &Vector3<f64>) -> Vec<Part> {
    let centre = v3(&c.crank_centre) - reference;
    let bore = v3(&c.bore_axis);
    let mut parts = Vec::new();
    for (i, cyl) in c.cylinders.iter().enumerate() {
        let throw = cyl.throw_deg.to_radians();
        parts.push(Part {
            name: format!("piston {}", i + 1),
            mass: c.oscillating_mass,
            inertia: Matrix3::zeros(),
            motion: PartMotion::Piston {
                crank_centre: centre,
                bore,
                y: cyl.y_offset,
                throw,
                radius: c.crank_radius,
                conrod: c.conrod_length,
            },
            spin_ratio: 0.0,
        });
        if c.rotating_mass > 0.0 {
            parts.push(Part {
                name: format!("crank pin {}", i + 1),
                mass: c.rotating_mass,
                inertia: Matrix3::zeros(),
                motion: PartMotion::Orbit {
                    centre,
                    bore,
                    y: cyl.y_offset,
                    radius: c.crank_radius,
                    ratio: 1.0,
                    phase: -throw,
                },
                spin_ratio: 1.0,
            });
        }
        if c.counterweight_mass > 0.0 {
            parts.push(Part {
                name: format!("counterweight {}", i + 1),
                mass: c.counterweight_mass,
                inertia: Matrix3::zeros(),
                motion: PartMotion::Orbit {
                    centre,
                    bore,
                    y: cyl.y_offset,
                    radius: c.counterweight_radius,
                    ratio: 1.0,
                    phase: std::f64::consts::PI - throw,
                },
                spin_ratio: 1.0,
            });
        }
    }
    parts.push(Part {
        name: "crankshaft".into(),
        mass: c.crank_mass,
        inertia: spin_inertia(c.crank_axial_inertia),
        motion: PartMotion::Fixed { offset: centre },
        spin_ratio: 1.0,
    });
    parts
}

/// An eccentric weight turning at `ratio` about an axis through `centre` (relative to the body
/// reference point).
fn eccentric(
    name: String,
    w: &EccentricWeight,
    centre: Vector3<f64>,
    bore: Vector3<f64>,
    ratio: f64,
) -> Part {
    Part {
        name,
        mass: w.mass,
        inertia: Matrix3::zeros(),
        motion: PartMotion::Orbit {
            centre,
            bore,
            y: w.y,
            radius: w.eccentricity,
            ratio,
            phase: w.phase_deg.to_radians(),
        },
        spin_ratio: ratio,
    }
}

/// Residual unbalances ([`super::config::ResidualUnbalance`]) as point masses on the crank and the shafts.
pub fn unbalance_parts(cfg: &EngineConfig, reference: &Vector3<f64>) -> Vec<Part> {
    let c = &cfg.crank_drive;
    let bore = v3(&c.bore_axis);
    let crank = v3(&c.crank_centre) - reference;
    cfg.residual_unbalance
        .iter()
        .filter_map(|u| {
            let (mass, centre, ratio) = if u.part == "crank" {
                (c.crank_mass, crank, 1.0)
            } else {
                let shaft = cfg.balance_shafts.iter().find(|b| b.name == u.part)?;
                let weights: f64 = shaft.weights.iter().map(|w| w.mass).sum();
                (
                    shaft.shaft_mass + weights,
                    v3(&shaft.axis_point) - reference,
                    shaft.ratio,
                )
            };
            let omega = u.service_rpm * std::f64::consts::PI / 30.0 * ratio.abs();
            let unbalance = mass * u.grade_mm_per_s * 1e-3 / omega;
            let weight = EccentricWeight {
                mass: unbalance / UNBALANCE_RADIUS,
                eccentricity: UNBALANCE_RADIUS,
                y: u.y,
                phase_deg: u.phase_deg,
            };
            Some(eccentric(
                format!("{} residual unbalance", u.part),
                &weight,
                centre,
                bore,
                ratio,
            ))
        })
        .collect()
}

/// Balance shafts with their weights and the extra crank counterweights, relative to `reference`.
/// With `balancing` off the weights sit on their axes: the masses stay, the balancing goes.
pub fn balance_parts(cfg: &EngineConfig, reference: &Vector3<f64>, balancing: bool) -> Vec<Part> {
    let c = &cfg.crank_drive;
    let bore = v3(&c.bore_axis);
    let crank = v3(&c.crank_centre) - reference;
    let mut parts = Vec::new();
    for shaft in &cfg.balance_shafts {
        let axis = v3(&shaft.axis_point) - reference;
        parts.push(Part {
            name: shaft.name.clone(),
            mass: shaft.shaft_mass,
            inertia: spin_inertia(shaft.shaft_axial_inertia),
            motion: PartMotion::Fixed { offset: axis },
            spin_ratio: shaft.ratio,
        });
        for (k, w) in shaft.weights.iter().enumerate() {
            let name = format!("{} weight {}", shaft.name, k + 1);
            parts.push(eccentric(
                name,
                &switched(w, balancing),
                axis,
                bore,
                shaft.ratio,
            ));
        }
    }
    for (k, w) in cfg.crank_counterweights.iter().enumerate() {
        let name = format!("extra counterweight {}", k + 1);
        parts.push(eccentric(name, &switched(w, balancing), crank, bore, 1.0));
    }
    parts.extend(unbalance_parts(cfg, reference));
    parts
}

/// A balancing weight as it is with balancing on, or moved onto its axis with balancing off.
fn switched(w: &EccentricWeight, balancing: bool) -> EccentricWeight {
    EccentricWeight {
        eccentricity: if balancing { w.eccentricity } else { 0.0 },
        ..w.clone()
    }
}

/// The free bodies of the model: `[monoblock, housing]` with elastic ring carriers, otherwise one
/// rigid `powertrain`. The monoblock (or powertrain) is always body 0 and carries the crank drive.
pub fn build_bodies(cfg: &EngineConfig, effects: &Effects) -> Vec<Body> {
    let mb_ref = v3(&cfg.monoblock.centre_of_mass);
    let mut mb_parts = vec![structure_part("monoblock", &cfg.monoblock, &mb_ref)];
    mb_parts.extend(crank_drive_parts(&cfg.crank_drive, &mb_ref));
    mb_parts.extend(balance_parts(cfg, &mb_ref, effects.balance_shaft));
    if effects.ring_carrier_elasticity {
        let h_ref = v3(&cfg.housing.centre_of_mass);
        vec![
            Body {
                name: "monoblock".into(),
                reference: mb_ref,
                parts: mb_parts,
            },
            Body {
                name: "housing".into(),
                reference: h_ref,
                parts: vec![structure_part("housing", &cfg.housing, &h_ref)],
            },
        ]
    } else {
        mb_parts.push(structure_part("housing", &cfg.housing, &mb_ref));
        vec![Body {
            name: "powertrain".into(),
            reference: mb_ref,
            parts: mb_parts,
        }]
    }
}
