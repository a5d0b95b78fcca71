//! Internal parts of a composite body and their motion relative to the body frame.
//!
//! Every part is a rigid body whose centre of mass moves on a prescribed path `ρ(φ)` in the body
//! frame (φ = crank angle relative to the monoblock) and which may spin about the body's y axis
//! (the crank axis) at `n · φ'`. Pistons carry the oscillating conrod mass (two-mass split), crank
//! points carry the rotating conrod mass, the crank pin and the counterweights; balance shaft
//! weights turn at their shaft's ratio `n` (−1 for the inline-3's shaft, ±2 for Lanchester shafts).
//!
//! Angles in the plane normal to the crank axis are measured from the cylinder (bore) axis `b`
//! towards `s = e_y × b`: for an upright engine `b = z`, `s = x`.

use nalgebra::{Matrix3, Vector3};

/// How a part moves relative to its body.
#[derive(Debug, Clone, PartialEq)]
pub enum PartMotion {
    /// Rigidly attached at `offset` (from the body reference point, body axes).
    Fixed {
        /// Position of the centre of mass from the body reference point (m, body axes).
        offset: Vector3<f64>,
    },
    /// Piston pin on the cylinder through `crank_centre + y·e_y` along the bore axis `bore`; exact
    /// slider-crank `s(ψ) = r cos ψ + √(l² − r² sin² ψ)`, `ψ = φ − throw`.
    Piston {
        /// Crank centre from the body reference point (m, body axes).
        crank_centre: Vector3<f64>,
        /// Unit bore axis (body axes).
        bore: Vector3<f64>,
        /// Cylinder position along the crank axis (m).
        y: f64,
        /// Throw angle of the cylinder's crank pin (rad).
        throw: f64,
        /// Crank radius `r` (m).
        radius: f64,
        /// Conrod length `l` (m).
        conrod: f64,
    },
    /// Point at `radius` from an axis parallel to body y through `centre`, at `y` along it, at the
    /// angle `ψ = ratio · φ + phase` measured from the bore axis `bore` towards `e_y × bore`.
    Orbit {
        /// A point of the axis from the body reference point (m, body axes).
        centre: Vector3<f64>,
        /// Unit bore axis, the zero of the angle (body axes).
        bore: Vector3<f64>,
        /// Position along the axis (m).
        y: f64,
        /// Distance from the axis (m).
        radius: f64,
        /// Turns per crank turn relative to the body (−1: a counter-rotating balance shaft).
        ratio: f64,
        /// Angle at crank angle 0 (rad).
        phase: f64,
    },
}

/// One internal part: mass, inertia, motion and spin.
#[derive(Debug, Clone, PartialEq)]
pub struct Part {
    /// The part's name (e.g. `piston 1`, `crankshaft`).
    pub name: String,
    /// Mass (kg).
    pub mass: f64,
    /// Inertia tensor about the part's centre of mass in body axes. For spinning parts it must be
    /// axisymmetric about body y (only then is it independent of the spin angle).
    pub inertia: Matrix3<f64>,
    /// How its centre of mass moves relative to the body.
    pub motion: PartMotion,
    /// Spin about body y relative to the body, as a multiple of the crank's relative speed.
    pub spin_ratio: f64,
}

/// Position of a part's centre of mass in body axes and its first two derivatives in φ.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PartPath {
    /// Position `ρ` (m).
    pub rho: Vector3<f64>,
    /// `dρ/dφ` (m/rad).
    pub d_rho: Vector3<f64>,
    /// `d²ρ/dφ²` (m/rad²).
    pub dd_rho: Vector3<f64>,
}

/// Piston stroke position `s(ψ)` and its derivatives `(s, s', s'')`.
pub fn slider_crank(psi: f64, r: f64, l: f64) -> (f64, f64, f64) {
    let (sn, cs) = psi.sin_cos();
    slider_crank_trig(sn, cs, r, l)
}

/// [`slider_crank`] from `(sin ψ, cos ψ)`, for callers that share one `sin_cos` among cylinders.
pub fn slider_crank_trig(sn: f64, cs: f64, r: f64, l: f64) -> (f64, f64, f64) {
    let w = (l * l - r * r * sn * sn).max(f64::MIN_POSITIVE).sqrt();
    let w1 = -r * r * sn * cs / w;
    let w2 = -r * r * (cs * cs - sn * sn) / w - r.powi(4) * sn * sn * cs * cs / w.powi(3);
    (r * cs + w, -r * sn + w1, -r * cs + w2)
}

/// A moving part reduced to what its path needs at run time.
#[derive(Debug, Clone, PartialEq)]
pub(super) enum MovingPart {
    /// Piston pin at `base + bore s(ψ)`, `ψ = φ − throw` (cos, sin of the throw kept).
    Piston {
        mass: f64,
        base: Vector3<f64>,
        bore: Vector3<f64>,
        cos_throw: f64,
        sin_throw: f64,
        radius: f64,
        conrod: f64,
    },
    /// Point at `base + radius (side sin ψ + bore cos ψ)`, `ψ = ratio φ + phase`.
    Orbit {
        mass: f64,
        base: Vector3<f64>,
        bore: Vector3<f64>,
        side: Vector3<f64>,
        radius: f64,
        ratio: f64,
        cos_phase: f64,
        sin_phase: f64,
    },
}

/// Sine and cosine of `ratio · φ` from those of `φ`: exact identities for the ratios engines use
/// (±1, ±2), a fresh `sin_cos` otherwise.
#[inline]
pub(super) fn multiple_angle(ratio: f64, phi: f64, sin: f64, cos: f64) -> (f64, f64) {
    if ratio == 1.0 {
        (sin, cos)
    } else if ratio == -1.0 {
        (-sin, cos)
    } else if ratio == 2.0 {
        (2.0 * sin * cos, cos * cos - sin * sin)
    } else if ratio == -2.0 {
        (-2.0 * sin * cos, cos * cos - sin * sin)
    } else if ratio == 0.0 {
        (0.0, 1.0)
    } else {
        (ratio * phi).sin_cos()
    }
}

impl MovingPart {
    /// The run-time form of a part that moves relative to its body, or the offset of a fixed one.
    pub(super) fn of(part: &Part) -> Result<MovingPart, Vector3<f64>> {
        let mass = part.mass;
        match &part.motion {
            PartMotion::Fixed { offset } => Err(*offset),
            PartMotion::Piston {
                crank_centre,
                bore,
                y,
                throw,
                radius,
                conrod,
            } => Ok(MovingPart::Piston {
                mass,
                base: crank_centre + Vector3::new(0.0, *y, 0.0),
                bore: *bore,
                cos_throw: throw.cos(),
                sin_throw: throw.sin(),
                radius: *radius,
                conrod: *conrod,
            }),
            PartMotion::Orbit {
                centre,
                bore,
                y,
                radius,
                ratio,
                phase,
            } => Ok(MovingPart::Orbit {
                mass,
                base: centre + Vector3::new(0.0, *y, 0.0),
                bore: *bore,
                side: Vector3::y().cross(bore),
                radius: *radius,
                ratio: *ratio,
                cos_phase: phase.cos(),
                sin_phase: phase.sin(),
            }),
        }
    }

    /// The part's mass.
    pub(super) fn mass(&self) -> f64 {
        match self {
            MovingPart::Piston { mass, .. } | MovingPart::Orbit { mass, .. } => *mass,
        }
    }

    /// `(ρ, ρ', ρ'')` at crank angle `phi` with `(sin φ, cos φ)` given.
    #[inline]
    pub(super) fn path(&self, phi: f64, sin: f64, cos: f64) -> [Vector3<f64>; 3] {
        match self {
            MovingPart::Piston {
                base,
                bore,
                cos_throw,
                sin_throw,
                radius,
                conrod,
                ..
            } => {
                let sn = sin * cos_throw - cos * sin_throw;
                let cs = cos * cos_throw + sin * sin_throw;
                let (s, s1, s2) = slider_crank_trig(sn, cs, *radius, *conrod);
                [base + bore * s, bore * s1, bore * s2]
            }
            MovingPart::Orbit {
                base,
                bore,
                side,
                radius,
                ratio,
                cos_phase,
                sin_phase,
                ..
            } => {
                let (sr, cr) = multiple_angle(*ratio, phi, sin, cos);
                let sn = sr * cos_phase + cr * sin_phase;
                let cs = cr * cos_phase - sr * sin_phase;
                let radial = side * sn + bore * cs;
                let tangential = side * cs - bore * sn;
                [
                    base + radial * *radius,
                    tangential * (ratio * radius),
                    radial * (-ratio * ratio * radius),
                ]
            }
        }
    }
}

impl Part {
    /// Path of the centre of mass at crank angle `phi`.
    pub fn path(&self, phi: f64) -> PartPath {
        match MovingPart::of(self) {
            Ok(moving) => {
                let (sin, cos) = phi.sin_cos();
                let [rho, d_rho, dd_rho] = moving.path(phi, sin, cos);
                PartPath { rho, d_rho, dd_rho }
            }
            Err(offset) => PartPath {
                rho: offset,
                d_rho: Vector3::zeros(),
                dd_rho: Vector3::zeros(),
            },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn slider_crank_derivatives_match_finite_differences() {
        let (r, l) = (0.047, 0.047 / 0.3);
        let h = 1e-5;
        for i in 0..36 {
            let psi = i as f64 * 0.17 + 0.05;
            let (s, s1, s2) = slider_crank(psi, r, l);
            let (sp, s1p, _) = slider_crank(psi + h, r, l);
            let (sm, s1m, _) = slider_crank(psi - h, r, l);
            assert!(((sp - sm) / (2.0 * h) - s1).abs() < 1e-9);
            assert!(((s1p - s1m) / (2.0 * h) - s2).abs() < 1e-8);
            // Exact geometry: conrod length is preserved between pin and crank pin.
            let pin = Vector3::new(0.0, 0.0, s);
            let crank_pin = Vector3::new(r * psi.sin(), 0.0, r * psi.cos());
            assert!(((pin - crank_pin).norm() - l).abs() < 1e-12);
        }
    }

    #[test]
    fn part_paths_are_consistent_with_their_derivatives_and_geometry() {
        let bore = Vector3::new(0.2, 0.0, 1.0).normalize();
        let parts = [
            PartMotion::Orbit {
                centre: Vector3::new(0.1, 0.0, -0.05),
                bore,
                y: 0.03,
                radius: 0.02,
                ratio: -2.0,
                phase: 0.7,
            },
            PartMotion::Piston {
                crank_centre: Vector3::new(0.0, 0.0, -0.1),
                bore,
                y: -0.1,
                throw: 2.0,
                radius: 0.047,
                conrod: 0.156,
            },
        ];
        for motion in parts {
            let part = Part {
                name: "p".into(),
                mass: 1.0,
                inertia: Matrix3::zeros(),
                motion: motion.clone(),
                spin_ratio: 0.0,
            };
            for k in 0..30 {
                let phi = -3.0 + 0.41 * k as f64;
                let h = 1e-5;
                let (p, pp, pm) = (part.path(phi), part.path(phi + h), part.path(phi - h));
                assert!(((pp.rho - pm.rho) / (2.0 * h) - p.d_rho).norm() < 1e-8);
                assert!(((pp.d_rho - pm.d_rho) / (2.0 * h) - p.dd_rho).norm() < 1e-7);
                if let PartMotion::Orbit { centre, radius, .. } = &motion {
                    // Stays on its circle in the plane normal to the crank axis.
                    let r = p.rho - centre;
                    assert!((Vector3::new(r.x, 0.0, r.z).norm() - radius).abs() < 1e-12);
                    assert!((r.y - 0.03).abs() < 1e-15);
                }
            }
        }
    }
}
