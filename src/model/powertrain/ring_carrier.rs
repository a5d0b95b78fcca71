//! Ring carrier: linear 6-DOF elastomer bushing between monoblock and housing (paper §4.2).
//!
//! Deflections are measured in housing axes: translation of the monoblock's copy of the bushing
//! point relative to the housing's copy, and the rotation vector of the relative rotation
//! `R_hᵀ R_m` (exact, no small-angle assumption in the kinematics; the elastic moment is the exact
//! gradient of the rotational energy, so the element is conservative). The force acts at the
//! monoblock point and, opposite, at the housing point; the housing also takes the moment of that
//! force pair, so the element conserves linear and angular momentum.

use nalgebra::{Matrix3, Vector3};

use super::assembly::v3;
use super::composite::BodyKinematics;
use super::config::BushingConfig;
use crate::model::kinematics::{left_jacobian_inverse_transpose, rotation_vector};

/// A bushing ready for evaluation.
#[derive(Debug, Clone, PartialEq)]
pub struct RingCarrier {
    /// The ring carrier's name from the configuration.
    pub name: String,
    /// Bushing point relative to the monoblock reference point (body axes).
    pub on_monoblock: Vector3<f64>,
    /// Bushing point relative to the housing reference point (body axes).
    pub on_housing: Vector3<f64>,
    /// Stiffness in housing axes: translations (N/m), rotations (N m/rad).
    pub stiffness: [f64; 6],
    /// Damping in the same order (N s/m, N m s/rad).
    pub damping: [f64; 6],
}

/// Wrenches on both bodies (vehicle frame): force at the body's bushing point and moment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BushingWrench {
    /// Force on the monoblock (N).
    pub monoblock_force: Vector3<f64>,
    /// Where it acts: the monoblock's bushing point (m).
    pub monoblock_point: Vector3<f64>,
    /// Moment on the monoblock (N m).
    pub monoblock_moment: Vector3<f64>,
    /// Force on the housing (N).
    pub housing_force: Vector3<f64>,
    /// Where it acts: the housing's bushing point (m).
    pub housing_point: Vector3<f64>,
    /// Moment on the housing (N m).
    pub housing_moment: Vector3<f64>,
    /// Local deflection `[translation; rotation]` in housing axes.
    pub deflection: [f64; 6],
}

impl RingCarrier {
    /// The bushing of `c` between bodies with these reference points (vehicle frame).
    pub fn from_config(
        c: &BushingConfig,
        monoblock_ref: &Vector3<f64>,
        housing_ref: &Vector3<f64>,
    ) -> Self {
        let p = v3(&c.position);
        Self {
            name: c.name.clone(),
            on_monoblock: p - monoblock_ref,
            on_housing: p - housing_ref,
            stiffness: c.stiffness,
            damping: c.damping,
        }
    }

    /// The bushing's forces and moments on both bodies in their current motion.
    pub fn wrench(&self, mb: &BodyKinematics, h: &BodyKinematics) -> BushingWrench {
        let xm = mb.point(&self.on_monoblock);
        let xh = h.point(&self.on_housing);
        let rt = h.rotation.transpose();
        let d = rt * (xm - xh);
        let dv = rt * (mb.point_velocity(&self.on_monoblock) - h.point_velocity(&self.on_housing));
        let th = rotation_vector(&(rt * mb.rotation));
        let w = rt * (mb.omega - h.omega);
        let k = &self.stiffness;
        let c = &self.damping;
        let f_local = Vector3::new(
            k[0] * d.x + c[0] * dv.x,
            k[1] * d.y + c[1] * dv.y,
            k[2] * d.z + c[2] * dv.z,
        );
        // Elastic moment conjugate to small relative rotations: J_l⁻ᵀ(θ) K θ, the exact gradient
        // of ½ θᵀKθ, so the element stays conservative at finite rotations.
        let elastic = left_jacobian_inverse_transpose(&th)
            * Vector3::new(k[3] * th.x, k[4] * th.y, k[5] * th.z);
        let m_local = elastic + Vector3::new(c[3] * w.x, c[4] * w.y, c[5] * w.z);
        let f = -(h.rotation * f_local);
        let m = -(h.rotation * m_local);
        BushingWrench {
            monoblock_force: f,
            monoblock_point: xm,
            monoblock_moment: m,
            housing_force: -f,
            housing_point: xh,
            housing_moment: -m - (xm - xh).cross(&f),
            deflection: [d.x, d.y, d.z, th.x, th.y, th.z],
        }
    }

    /// Elastic energy for a local deflection.
    pub fn energy(&self, deflection: &[f64; 6]) -> f64 {
        (0..6)
            .map(|i| 0.5 * self.stiffness[i] * deflection[i] * deflection[i])
            .sum()
    }

    /// Translational stiffness matrix in housing axes (used by mode descriptions).
    pub fn translational_stiffness(&self) -> Matrix3<f64> {
        Matrix3::from_diagonal(&Vector3::new(
            self.stiffness[0],
            self.stiffness[1],
            self.stiffness[2],
        ))
    }
}
