//! Engine mount force law: per local direction a monotone C¹ spring curve, viscous damping and an
//! assembly preload, with stiffness and damping scale factors.
//!
//! The law is a function of the relative displacement and velocity of the housing bracket with
//! respect to the attachment point (a ground point or a body node), so it works in any vehicle;
//! it also returns its derivatives for Jacobians.

use nalgebra::{Matrix3, Vector3};

use super::config::MountConfig;
use super::curve::{CurveTable, MountCurve};
use crate::model::powertrain::assembly::{m3, v3};

/// Mount force and its derivatives, in the vehicle frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MountResponse {
    /// Force the mount exerts on the bracket (N). The force on the ground/chassis side is `−force`.
    pub force: Vector3<f64>,
    /// Deflection in mount axes (m).
    pub deflection: Vector3<f64>,
    /// Tangent stiffness and damping per mount axis; the vehicle-frame matrices are formed only
    /// when a Jacobian asks for them.
    axial_stiffness: Vector3<f64>,
    axial_damping: Vector3<f64>,
    axes: Matrix3<f64>,
}

impl MountResponse {
    /// `∂force/∂(bracket displacement relative to attachment)`.
    pub fn stiffness(&self) -> Matrix3<f64> {
        -(self.axes.transpose() * Matrix3::from_diagonal(&self.axial_stiffness) * self.axes)
    }

    /// `∂force/∂(relative velocity)`.
    pub fn damping(&self) -> Matrix3<f64> {
        -(self.axes.transpose() * Matrix3::from_diagonal(&self.axial_damping) * self.axes)
    }
}

/// A mount ready for evaluation.
#[derive(Debug, Clone, PartialEq)]
pub struct Mount {
    /// The mount's name from the configuration.
    pub name: String,
    /// Bracket point in the vehicle frame, reference configuration.
    pub bracket: Vector3<f64>,
    /// Attachment point in the vehicle frame (reference): the ground point or the body node.
    pub attachment: Vector3<f64>,
    /// Rows: local axes.
    pub axes: Matrix3<f64>,
    /// Force-deflection curve per local axis.
    pub curves: [MountCurve; 3],
    /// The curves prepared for evaluation.
    tables: [CurveTable; 3],
    /// Viscous damping per local axis (N s/m).
    pub damping: Vector3<f64>,
    /// Force on the bracket at zero deflection per local axis (N): the assembly preload.
    pub preload: Vector3<f64>,
    /// Deflection of the static operating point; with the nonlinearity switched off the curves
    /// are replaced by their tangents there.
    pub operating_point: Vector3<f64>,
}

impl Mount {
    /// The mount of `c` attached at `attachment` (vehicle frame, reference configuration).
    pub fn from_config(c: &MountConfig, attachment: Vector3<f64>) -> Self {
        Self {
            name: c.name.clone(),
            bracket: v3(&c.bracket),
            attachment,
            axes: m3(&c.axes),
            curves: c.curves.clone(),
            tables: c.curves.each_ref().map(CurveTable::new),
            damping: v3(&c.damping),
            preload: v3(&c.preload),
            operating_point: Vector3::zeros(),
        }
    }

    /// Local deflection of a bracket at world position `x` against an attachment displaced by
    /// `attachment_displacement`.
    pub fn deflection(
        &self,
        x: &Vector3<f64>,
        attachment_displacement: &Vector3<f64>,
    ) -> Vector3<f64> {
        self.axes * (x - self.attachment - attachment_displacement)
    }

    /// Force law for the relative displacement `rel = x_bracket − x_attachment` (vehicle frame)
    /// and relative velocity `rel_vel`.
    pub fn response(
        &self,
        rel: &Vector3<f64>,
        rel_vel: &Vector3<f64>,
        stiffness_scale: f64,
        damping_scale: f64,
        nonlinear: bool,
    ) -> MountResponse {
        let delta = self.axes * (rel - (self.bracket - self.attachment));
        let rate = self.axes * rel_vel;
        let mut f_local = Vector3::zeros();
        let mut k_local = Vector3::zeros();
        for i in 0..3 {
            let table = &self.tables[i];
            let (g, k) = if nonlinear {
                table.force_and_stiffness(delta[i])
            } else {
                let d0 = self.operating_point[i];
                let (g0, k0) = table.force_and_stiffness(d0);
                (g0 + k0 * (delta[i] - d0), k0)
            };
            f_local[i] =
                self.preload[i] - stiffness_scale * g - damping_scale * self.damping[i] * rate[i];
            k_local[i] = stiffness_scale * k;
        }
        MountResponse {
            force: self.axes.tr_mul(&f_local),
            deflection: delta,
            axial_stiffness: k_local,
            axial_damping: self.damping * damping_scale,
            axes: self.axes,
        }
    }

    /// Elastic energy stored at local deflection `delta` (preload work included), for energy checks.
    pub fn energy(&self, delta: &Vector3<f64>, stiffness_scale: f64, nonlinear: bool) -> f64 {
        (0..3)
            .map(|i| {
                let d = delta[i];
                let curve = &self.curves[i];
                let elastic = if nonlinear {
                    curve.energy(d)
                } else {
                    let d0 = self.operating_point[i];
                    let (g0, k0) = (curve.force(d0), curve.stiffness(d0));
                    g0 * d + 0.5 * k0 * (d - d0) * (d - d0) - 0.5 * k0 * d0 * d0
                };
                stiffness_scale * elastic - self.preload[i] * d
            })
            .sum()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::VehicleConfig;

    #[test]
    fn response_derivatives_match_finite_differences_in_a_rotated_frame() {
        let mut cfg = VehicleConfig::default().mounts[0].clone();
        let rot = nalgebra::Rotation3::from_euler_angles(0.3, -0.2, 0.5).into_inner();
        cfg.axes = [
            [rot[(0, 0)], rot[(0, 1)], rot[(0, 2)]],
            [rot[(1, 0)], rot[(1, 1)], rot[(1, 2)]],
            [rot[(2, 0)], rot[(2, 1)], rot[(2, 2)]],
        ];
        let mount = Mount::from_config(&cfg, v3(&cfg.bracket));
        let rel = Vector3::new(0.004, -0.006, -0.009);
        let vel = Vector3::new(0.01, 0.02, -0.03);
        let r = mount.response(&rel, &vel, 1.3, 0.7, true);
        let h = 1e-8;
        for j in 0..3 {
            let dx = Vector3::ith(j, h);
            let fd = (mount.response(&(rel + dx), &vel, 1.3, 0.7, true).force
                - mount.response(&(rel - dx), &vel, 1.3, 0.7, true).force)
                / (2.0 * h);
            assert!(
                (fd - r.stiffness().column(j)).norm() < 1e-4 * r.stiffness().norm(),
                "stiffness column {j}"
            );
            let fv = (mount.response(&rel, &(vel + dx), 1.3, 0.7, true).force
                - mount.response(&rel, &(vel - dx), 1.3, 0.7, true).force)
                / (2.0 * h);
            assert!(
                (fv - r.damping().column(j)).norm() < 1e-6 * r.damping().norm(),
                "damping column {j}"
            );
        }
        // The force derives from the energy (conservative spring part).
        let e = |x: &Vector3<f64>| mount.energy(&(mount.axes * x), 1.3, true);
        for j in 0..3 {
            let dx = Vector3::ith(j, 1e-7);
            let grad = (e(&(rel + dx)) - e(&(rel - dx))) / 2e-7;
            let f_el = mount
                .response(&rel, &Vector3::zeros(), 1.3, 0.7, true)
                .force[j];
            assert!(
                (grad + f_el).abs() < 1e-3 * (1.0 + f_el.abs()),
                "energy gradient {j}: {grad} vs {f_el}"
            );
        }
    }
}
