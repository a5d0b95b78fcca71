//! The composite-body dynamics of [`super::composite`] evaluated through the parts' mass moments.
//!
//! Projecting each part's Newton–Euler equations one by one costs a handful of 3×3 products per
//! part and per evaluation. But every term of the projection is linear in a few mass moments of
//! the parts' paths in body axes — `Σ m ρ`, `Σ m ρ'`, `Σ m ρ''`, `Σ m ρ ρᵀ`, `Σ m ρ' ρᵀ`,
//! `Σ m ρ'·ρ`, `Σ m |ρ'|²`, `Σ m ρ'·ρ''`, `Σ m ρ' × ρ`, `Σ m ρ × ρ''` — which depend on the crank
//! angle alone. So the parts are summed once per evaluation in body axes (one `sin_cos` of the
//! crank angle shared by all of them), the body's motion enters through these sums, and the
//! result is rotated into the vehicle frame once. Fixed parts fold into constants at build time,
//! spinning inertias into one constant tensor per spin ratio.
//!
//! With `A = −[r]× − d eᵀ` (the angular partial velocity block of a part, `r = R ρ`,
//! `d = R ρ'`, `e = R e_y`) the sums give, in body axes (`w` the body's angular velocity, `s` the
//! relative crank speed, `α` its rate):
//! - `Σ m A = −[S₀]× − S₁ eᵀ`, `Σ m AᵀA = tr(Q) I − Q + h eᵀ + e hᵀ + β e eᵀ`;
//! - `Σ m a_bias = w×(w×S₀) + 2s w×S₁ + s² S₂ + α S₁`;
//! - `Σ m Aᵀ a_bias = (Q w)×w + 2s(γ w − N w) + s² k − α h − e(wᵀN w − |w|² γ + s² δ + α β)`,
//!
//! where `S₀ = Σ mρ`, `S₁ = Σ mρ'`, `S₂ = Σ mρ''`, `Q = Σ m ρρᵀ`, `N = Σ m ρ'ρᵀ`,
//! `γ = Σ m ρ'·ρ`, `β = Σ m|ρ'|²`, `δ = Σ m ρ'·ρ''`, `h = Σ m ρ'×ρ`, `k = Σ m ρ×ρ''`.
//! The per-part projection stays in the tests as the independent reference.

use nalgebra::{Matrix3, Vector3};

use super::composite::{BodyDynamics, BodyKinematics, CrankDriveState};
use super::parts::{MovingPart, Part};

/// The parts of one body, compiled for evaluation through their mass moments.
#[derive(Debug, Clone, PartialEq)]
pub struct PartMoments {
    total_mass: f64,
    /// `Σ m ρ` and `Σ m ρρᵀ` of the fixed parts.
    fixed_first: Vector3<f64>,
    fixed_second: Matrix3<f64>,
    moving: Vec<MovingPart>,
    /// Summed inertia tensor (body axes) per spin ratio.
    spin_groups: Vec<(f64, Matrix3<f64>)>,
    /// `Σ (I − n e eᵀ) J (I − n e eᵀ)` over the spin groups: their constant share of the mass
    /// matrix in body axes.
    spin_mass: Matrix3<f64>,
}

impl PartMoments {
    /// Compiles a body's parts: fixed parts and spinning inertias fold into constants here.
    pub fn new(parts: &[Part]) -> Self {
        let mut fixed_first = Vector3::zeros();
        let mut fixed_second = Matrix3::zeros();
        let mut moving = Vec::new();
        let mut spin_groups: Vec<(f64, Matrix3<f64>)> = Vec::new();
        for part in parts {
            match MovingPart::of(part) {
                Ok(moving_part) => moving.push(moving_part),
                Err(offset) => {
                    fixed_first += offset * part.mass;
                    fixed_second += offset * offset.transpose() * part.mass;
                }
            }
            if part.inertia != Matrix3::zeros() {
                match spin_groups.iter_mut().find(|(n, _)| *n == part.spin_ratio) {
                    Some((_, j)) => *j += part.inertia,
                    None => spin_groups.push((part.spin_ratio, part.inertia)),
                }
            }
        }
        let e_outer = Vector3::y() * Vector3::y().transpose();
        let spin_mass = spin_groups
            .iter()
            .map(|(n, j)| {
                let p = Matrix3::identity() - e_outer * *n;
                p.transpose() * j * p
            })
            .sum();
        Self {
            total_mass: parts.iter().map(|p| p.mass).sum(),
            fixed_first,
            fixed_second,
            moving,
            spin_groups,
            spin_mass,
        }
    }

    /// Adds the parts' contributions (gravity `g` included) to `out`: the same projection as
    /// summing every part's Newton–Euler equations with its partial velocities.
    pub fn add(
        &self,
        body: &BodyKinematics,
        crank: &CrankDriveState,
        gravity: &Vector3<f64>,
        out: &mut BodyDynamics,
    ) {
        let rot = &body.rotation;
        let w = rot.tr_mul(&body.omega);
        let g = rot.tr_mul(gravity);
        let e = Vector3::y();
        let e_dot_w = w.y;
        let s = crank.excitation * crank.speed - e_dot_w;
        let alpha = crank.excitation * crank.acceleration;
        let sigma = crank.spin - e_dot_w;

        let mut s0 = self.fixed_first;
        let mut q = self.fixed_second;
        let (mut s1, mut s2) = (Vector3::zeros(), Vector3::zeros());
        let mut n_mat = Matrix3::zeros();
        let (mut gamma, mut beta, mut delta) = (0.0, 0.0, 0.0);
        let (mut h, mut k) = (Vector3::zeros(), Vector3::zeros());
        if !self.moving.is_empty() {
            let phi = crank.angle;
            let (sin, cos) = phi.sin_cos();
            for part in &self.moving {
                let m = part.mass();
                let [a, b, c] = part.path(phi, sin, cos);
                let (ma, mb) = (a * m, b * m);
                s0 += ma;
                s1 += mb;
                s2 += c * m;
                q += ma * a.transpose();
                n_mat += mb * a.transpose();
                gamma += mb.dot(&a);
                beta += mb.dot(&b);
                delta += mb.dot(&c);
                h += mb.cross(&a);
                k += ma.cross(&c);
            }
        }

        let force_lin = g * self.total_mass
            - w.cross(&w.cross(&s0))
            - w.cross(&s1) * (2.0 * s)
            - s2 * (s * s)
            - s1 * alpha;
        let mut force_ang = s0.cross(&g) - e * s1.dot(&g) - (q * w).cross(&w)
            + (n_mat * w - w * gamma) * (2.0 * s)
            - k * (s * s)
            + h * alpha
            + e * (w.dot(&(n_mat * w)) - w.norm_squared() * gamma + delta * (s * s) + beta * alpha);
        for (n, j) in &self.spin_groups {
            let omega_part = w + e * (n * sigma);
            let alpha_bias = e * (n * alpha) + w.cross(&e) * (n * sigma);
            let moment = -(j * alpha_bias + omega_part.cross(&(j * omega_part)));
            force_ang += moment - e * (n * e.dot(&moment));
        }
        let coupling = -s0.cross_matrix() - s1 * e.transpose();
        let rotational = Matrix3::identity() * q.trace() - q
            + h * e.transpose()
            + e * h.transpose()
            + e * e.transpose() * beta
            + self.spin_mass;

        let force_lin = rot * force_lin;
        let force_ang = rot * force_ang;
        let coupling = rot * coupling * rot.transpose();
        let rotational = rot * rotational * rot.transpose();
        for i in 0..3 {
            out.mass[(i, i)] += self.total_mass;
            out.force[i] += force_lin[i];
            out.force[3 + i] += force_ang[i];
            for j in 0..3 {
                out.mass[(i, 3 + j)] += coupling[(i, j)];
                out.mass[(3 + j, i)] += coupling[(i, j)];
                out.mass[(3 + i, 3 + j)] += rotational[(i, j)];
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use nalgebra::Rotation3;

    use super::*;
    use crate::model::effects::Effects;
    use crate::model::powertrain::assembly::build_bodies;
    use crate::model::powertrain::composite::add_parts;
    use crate::model::powertrain::parts::{multiple_angle, slider_crank, PartMotion};
    use crate::model::EngineConfig;

    /// Bodies with every kind of part: crank drive, balance shaft (ratio −1), residual
    /// unbalance, and a Lanchester-like pair at ±2 and an odd ratio added by hand.
    fn bodies() -> Vec<Vec<Part>> {
        let cfg = EngineConfig::default();
        let mut out: Vec<Vec<Part>> = build_bodies(&cfg, &Effects::default())
            .into_iter()
            .map(|b| b.parts)
            .collect();
        let rigid = Effects {
            ring_carrier_elasticity: false,
            ..Effects::default()
        };
        let mut parts = build_bodies(&cfg, &rigid).remove(0).parts;
        for (ratio, phase) in [(2.0, 0.4), (-2.0, 1.1), (1.5, -0.3)] {
            parts.push(Part {
                name: format!("shaft {ratio}"),
                mass: 0.8,
                inertia: Matrix3::from_diagonal(&Vector3::new(0.0, 2e-3, 0.0)),
                motion: PartMotion::Orbit {
                    centre: Vector3::new(0.05, -0.02, -0.1),
                    bore: Vector3::new(0.3, 0.0, 1.0).normalize(),
                    y: 0.03,
                    radius: 0.02,
                    ratio,
                    phase,
                },
                spin_ratio: ratio,
            });
        }
        out.push(parts);
        out
    }

    #[test]
    fn moments_give_the_per_part_projection_in_any_motion() {
        let gravity = Vector3::new(0.0, 0.0, -9.81);
        for (i, parts) in bodies().iter().enumerate() {
            let moments = PartMoments::new(parts);
            for k in 0..40 {
                let x = k as f64;
                let body = BodyKinematics {
                    position: Vector3::new(0.1, -0.2, 0.3),
                    rotation: Rotation3::from_euler_angles(
                        0.03 * (0.7 * x).sin(),
                        -0.02 * (1.3 * x).cos(),
                        0.05 * (0.4 * x).sin(),
                    )
                    .into_inner(),
                    velocity: Vector3::new(0.2, -0.1, 0.05 * x.cos()),
                    omega: Vector3::new(3.0 * x.sin(), -2.0 + 0.1 * x, 1.5 * (2.0 * x).cos()),
                };
                let crank = CrankDriveState {
                    angle: 0.37 * x - 4.0,
                    speed: 100.0 + 10.0 * x,
                    acceleration: 50.0 * (0.9 * x).sin(),
                    excitation: if k % 5 == 0 { 0.4 } else { 1.0 },
                    spin: if k % 7 == 0 { 0.0 } else { 95.0 + 10.0 * x },
                };
                let (mut want, mut got) = (BodyDynamics::zero(), BodyDynamics::zero());
                add_parts(parts, &body, &crank, &gravity, &mut want);
                moments.add(&body, &crank, &gravity, &mut got);
                let mass_scale = want.mass.abs().max();
                let force_scale = want.force.abs().max();
                assert!(
                    (got.mass - want.mass).abs().max() < 1e-12 * mass_scale,
                    "body {i}, case {k}: mass\n{}\nvs\n{}",
                    got.mass,
                    want.mass
                );
                assert!(
                    (got.force - want.force).abs().max() < 1e-11 * force_scale,
                    "body {i}, case {k}: force {} vs {}",
                    got.force,
                    want.force
                );
            }
        }
    }

    #[test]
    fn shared_trigonometry_matches_the_direct_paths() {
        let r = 0.047;
        let l = r / 0.3;
        for k in 0..50 {
            let phi = -7.0 + 0.29 * k as f64;
            for ratio in [1.0, -1.0, 2.0, -2.0, 0.7] {
                let (s, c) = multiple_angle(ratio, phi, phi.sin(), phi.cos());
                let psi = ratio * phi;
                assert!((s - psi.sin()).abs() < 1e-14 && (c - psi.cos()).abs() < 1e-14);
            }
            // The stroke's second derivative uses cos 2ψ = cos²ψ − sin²ψ: against differences.
            let (_, s1p, _) = slider_crank(phi + 1e-5, r, l);
            let (_, s1m, _) = slider_crank(phi - 1e-5, r, l);
            let (_, _, s2) = slider_crank(phi, r, l);
            assert!(((s1p - s1m) / 2e-5 - s2).abs() < 1e-8);
        }
    }
}
