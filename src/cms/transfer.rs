//! Frequency response of the reduced chassis alone by modal superposition (paper §5.3, Fig. 8):
//! a harmonic unit force or moment at one recovery point, the response at another.

use faer::c64;

use super::error::CmsError;
use super::reduced::{RecoveryPoint, ReducedChassis};

/// One DOF of a recovery point: `dof` 0..6 = ux, uy, uz, rx, ry, rz (vehicle axes).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PointDof<'a> {
    /// Recovery point name, e.g. "mount_front_left" or "steering_wheel".
    pub point: &'a str,
    /// Local DOF 0..6.
    pub dof: usize,
}

/// Which response quantity a transfer function returns per unit excitation.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Response {
    /// Receptance (m/N).
    Displacement,
    /// Mobility (m/s/N).
    Velocity,
    /// Accelerance (m/s²/N).
    Acceleration,
}

impl ReducedChassis {
    fn shape_of(&self, which: &str, at: PointDof<'_>) -> Result<&RecoveryPoint, CmsError> {
        if at.dof >= 6 {
            return Err(CmsError::InvalidInput(format!(
                "{which} dof {} of '{}' must be in 0..6",
                at.dof, at.point
            )));
        }
        let p = self.point(at.point).ok_or_else(|| {
            CmsError::InvalidInput(format!(
                "{which} point '{}' is not a recovery point (have: {})",
                at.point,
                self.points
                    .iter()
                    .map(|p| p.name.as_str())
                    .collect::<Vec<_>>()
                    .join(", ")
            ))
        })?;
        if p.shape.len() != self.n_modes() || self.zeta.len() != self.n_modes() {
            return Err(CmsError::InvalidInput(format!(
                "inconsistent reduced chassis: {} modes, {} damping ratios, '{}' has {} rows",
                self.n_modes(),
                self.zeta.len(),
                p.name,
                p.shape.len()
            )));
        }
        Ok(p)
    }

    /// Complex response at `output` per unit harmonic force (or moment) at `input`, at each of
    /// `frequencies_hz`: `H(ω) = (iω)^p Σ_k φ_out,k φ_in,k / (ω_k² − ω² + 2iζ_k ω_k ω)`,
    /// p = 0, 1, 2 for displacement, velocity, acceleration.
    pub fn transfer_function(
        &self,
        input: PointDof<'_>,
        output: PointDof<'_>,
        response: Response,
        frequencies_hz: &[f64],
    ) -> Result<Vec<c64>, CmsError> {
        let pin = self.shape_of("input", input)?;
        let pout = self.shape_of("output", output)?;
        let gains: Vec<f64> = pin
            .shape
            .iter()
            .zip(&pout.shape)
            .map(|(a, b)| a[input.dof] * b[output.dof])
            .collect();
        frequencies_hz
            .iter()
            .enumerate()
            .map(|(i, &f)| {
                if !(f.is_finite() && f >= 0.0) {
                    return Err(CmsError::InvalidInput(format!(
                        "frequencies_hz[{i}] = {f} must be finite and >= 0"
                    )));
                }
                let w = 2.0 * std::f64::consts::PI * f;
                let mut h = c64::new(0.0, 0.0);
                for (k, g) in gains.iter().enumerate() {
                    let (wk, z) = (self.omega[k], self.zeta[k]);
                    let den = c64::new(wk * wk - w * w, 2.0 * z * wk * w);
                    if den.norm() == 0.0 {
                        return Err(CmsError::InvalidInput(format!(
                            "frequencies_hz[{i}] = {f} is the undamped resonance of mode {k}"
                        )));
                    }
                    h += c64::new(*g, 0.0) / den;
                }
                Ok(match response {
                    Response::Displacement => h,
                    Response::Velocity => h * c64::new(0.0, w),
                    Response::Acceleration => h * (-w * w),
                })
            })
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// One mode: the analytic single-DOF receptance φ²/(ω_n² − ω² + 2iζω_nω).
    fn single_mode() -> ReducedChassis {
        ReducedChassis {
            omega: vec![100.0],
            zeta: vec![0.05],
            points: vec![RecoveryPoint {
                name: "a".into(),
                node: 0,
                position: [0.0; 3],
                shape: vec![[0.0, 0.0, 0.5, 0.0, 0.0, 0.0]],
            }],
            cutoff_hz: None,
            own_damping: None,
        }
    }

    #[test]
    fn single_mode_matches_the_oscillator_and_its_derivatives() {
        let rc = single_mode();
        let at = PointDof { point: "a", dof: 2 };
        let f = 100.0 / (2.0 * std::f64::consts::PI);
        let d = rc
            .transfer_function(at, at, Response::Displacement, &[f])
            .unwrap()[0];
        // At resonance: φ² / (2iζω²) = 0.25 / (i · 1000) = −0.00025 i.
        assert!((d - c64::new(0.0, -2.5e-4)).norm() < 1e-15, "{d}");
        let a = rc
            .transfer_function(at, at, Response::Acceleration, &[f])
            .unwrap()[0];
        assert!((a - d * (-1.0e4)).norm() < 1e-12);
        let v = rc
            .transfer_function(at, at, Response::Velocity, &[f])
            .unwrap()[0];
        assert!((v - d * c64::new(0.0, 100.0)).norm() < 1e-12);
        // Static: φ²/ω_n².
        let s = rc
            .transfer_function(at, at, Response::Displacement, &[0.0])
            .unwrap()[0];
        assert!((s.re - 0.25e-4).abs() < 1e-18 && s.im == 0.0);
    }

    #[test]
    fn bad_queries_are_named() {
        let rc = single_mode();
        let ok = PointDof { point: "a", dof: 2 };
        let e = rc
            .transfer_function(
                PointDof { point: "b", dof: 0 },
                ok,
                Response::Displacement,
                &[1.0],
            )
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("input point 'b'") && e.contains("have: a"),
            "{e}"
        );
        let e = rc
            .transfer_function(
                ok,
                PointDof { point: "a", dof: 6 },
                Response::Displacement,
                &[1.0],
            )
            .unwrap_err()
            .to_string();
        assert!(e.contains("output dof 6"), "{e}");
        let e = rc
            .transfer_function(ok, ok, Response::Displacement, &[1.0, f64::NAN])
            .unwrap_err()
            .to_string();
        assert!(e.contains("frequencies_hz[1]"), "{e}");
    }
}
